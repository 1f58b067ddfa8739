// What an `allan` request and a noise refit cost gyrod at 1 kHz with a 1 h window
// (issue 16): the ALLAN reply as it was built before (a full snapshot: noise identification
// over the whole window at every τ, on the event loop) against the reply from the rolling
// sums; the refit of one axis (now on the worker thread) against the copy of one raw stream
// that the loop makes for it. The argument is the number of samples in the window.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <random>

#include "daemon/sample_pipeline.hpp"

namespace {

using gyrod::daemon::SamplePipeline;

constexpr double kRateHz = 1000.0;
constexpr std::size_t kWindow = 3'600'000;  // 1 h at 1 kHz

// One pipeline per fill, built once (filling 3.6 M samples takes seconds).
SamplePipeline& filledPipeline(std::size_t samples) {
  static std::map<std::size_t, std::unique_ptr<SamplePipeline>> pipelines;
  auto& p = pipelines[samples];
  if (!p) {
    gyrod::daemon::PipelineSettings s;
    s.rate_hz = kRateHz;
    s.bias_origin = gyrod::daemon::BiasOrigin::Config;
    s.bias_dps = {-3.3, 1.1, -0.5};
    s.kalman = {0.95, 3e-5, 5e-3};
    s.allan_window_samples = kWindow;
    p = std::make_unique<SamplePipeline>(s);
    std::mt19937_64 rng(7);
    std::normal_distribution<double> n(0.0, 0.1);
    for (std::size_t k = 0; k < samples; ++k)
      p->process(k, static_cast<double>(k) / kRateHz, {-3.3 + n(rng), 1.1 + n(rng), -0.5 + n(rng)}, 25.0);
  }
  return *p;
}

void BM_AllanReplyFromSnapshot(benchmark::State& state) {  // the reply before issue 16
  const SamplePipeline& p = filledPipeline(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(p.allanSnapshot());
}

void BM_AllanReplyFromRollingSums(benchmark::State& state) {
  const SamplePipeline& p = filledPipeline(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(p.allanWindowDeviations());
}

void BM_RefitOneAxis(benchmark::State& state) {  // on the worker thread
  const SamplePipeline& p = filledPipeline(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(gyrod::daemon::refitNoiseTerms(p.rawAllan(0), 1.0 / kRateHz));
}

void BM_CopyOneRawStream(benchmark::State& state) {  // on the loop, per axis and refit
  const SamplePipeline& p = filledPipeline(static_cast<std::size_t>(state.range(0)));
  gyrod::processing::RollingOverlappingAllan copy = p.rawAllan(0);  // allocated once, as the worker does
  for (auto _ : state) {
    copy = p.rawAllan(1);
    benchmark::DoNotOptimize(copy);
  }
}

}  // namespace

BENCHMARK(BM_AllanReplyFromSnapshot)->Arg(30'000)->Arg(200'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AllanReplyFromRollingSums)->Arg(30'000)->Arg(200'000)->Arg(3'600'000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RefitOneAxis)->Arg(30'000)->Arg(3'600'000)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_CopyOneRawStream)->Arg(3'600'000)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
