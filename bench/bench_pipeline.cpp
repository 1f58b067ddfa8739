// Throughput of gyrod's whole per-sample pipeline (bias removal → mean filter → Kalman →
// rolling Allan of the raw, mean and Kalman streams on three axes, 1 h window at 50 Hz),
// beside a plain pass that only copies the samples, in the same run.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "daemon/sample_pipeline.hpp"

namespace {

constexpr std::size_t kSamples = 200000;

const std::vector<gyrod::daemon::Vec3>& samples() {
  static const std::vector<gyrod::daemon::Vec3> data = [] {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> n(0.0, 0.1);
    std::vector<gyrod::daemon::Vec3> v(kSamples);
    for (auto& s : v) s = {-3.3 + n(rng), 1.1 + n(rng), -0.5 + n(rng)};
    return v;
  }();
  return data;
}

gyrod::daemon::PipelineSettings settings() {
  gyrod::daemon::PipelineSettings p;
  p.rate_hz = 50.0;
  p.bias_origin = gyrod::daemon::BiasOrigin::Config;
  p.bias_dps = {-3.3, 1.1, -0.5};
  p.kalman = {0.95, 3e-5, 5e-3};
  p.allan_window_samples = 180000;  // 1 h at 50 Hz
  return p;
}

void BM_Pipeline(benchmark::State& state) {
  const auto& data = samples();
  gyrod::daemon::SamplePipeline pipeline(settings());
  std::uint64_t seq = 0;
  for (auto _ : state) {
    const auto& s = data[seq % kSamples];
    benchmark::DoNotOptimize(pipeline.process(seq, static_cast<double>(seq) * 0.02, s, 30.0));
    ++seq;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_Pipeline);

void BM_CopyOnly(benchmark::State& state) {
  const auto& data = samples();
  std::uint64_t seq = 0;
  gyrod::daemon::Vec3 sink{};
  for (auto _ : state) {
    sink = data[seq % kSamples];
    benchmark::DoNotOptimize(sink);
    ++seq;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_CopyOnly);

}  // namespace

BENCHMARK_MAIN();
