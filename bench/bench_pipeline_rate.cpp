// gyrod's added cost of the `rate` stream: the whole per-sample SamplePipeline (bias removal →
// mean filter → Kalman → rolling Allan of three streams on three axes, 1 h window at 50 Hz) with
// a sensor model (RateEstimator: model bias, still detector, residual Kalman) against the same
// pipeline without one (rate = raw − bias), in the same run. The difference of the two is what
// filter.model costs gyrod per sample (issue 11: ≤ 0.5 µs). The input alternates 20 s at rest
// with 20 s of a 1 Hz rotation while warming up, so both of the detector's outcomes are timed.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "daemon/sample_pipeline.hpp"
#include "processing/motion/rate_estimator.hpp"

namespace {

constexpr std::size_t kSamples = 200000;
constexpr double kRateHz = 50.0;

struct Input {
  gyrod::daemon::Vec3 rate;
  double temperature;
};

const std::vector<Input>& samples() {
  static const std::vector<Input> data = [] {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> n(0.0, 0.11);
    std::vector<Input> v(kSamples);
    for (std::size_t i = 0; i < kSamples; ++i) {
      const double t = static_cast<double>(i) / kRateHz;
      const bool moving = static_cast<std::size_t>(t / 20.0) % 2 == 1;
      const double w = moving ? 20.0 * std::sin(2.0 * std::numbers::pi * t) : 0.0;
      v[i] = {{1.367 + n(rng) + w, -0.4 + n(rng), 0.25 + n(rng)}, 25.0 + 10.0 * (1.0 - std::exp(-t / 600.0))};
    }
    return v;
  }();
  return data;
}

gyrod::processing::RateEstimatorParameters rateModel() {
  gyrod::processing::RateEstimatorParameters p;
  p.rate_hz = kRateHz;
  const double bias[3] = {1.367, -0.4, 0.25};
  for (std::size_t a = 0; a < 3; ++a) {
    auto& m = p.axes[a];
    m.bias_dps = bias[a];
    m.temperature_coefficient_dps_per_c = 0.02;
    m.temperature_coefficient_std_dps_per_c = 0.002;
    m.warm_up_amplitude_dps = 0.05;  // the warm-up shape on: its exp() is timed too
    m.warm_up_time_constant_s = 300.0;
    m.bias_std_dps = 0.01;
    m.terms = {0.1663, 0.95164, 0.60565, 0.07759, 0.43223};
  }
  return p;
}

gyrod::daemon::PipelineSettings settings(bool with_model, std::size_t allan_window_s) {
  gyrod::daemon::PipelineSettings p;
  p.rate_hz = kRateHz;
  p.bias_origin = gyrod::daemon::BiasOrigin::Config;
  p.bias_dps = {1.367, -0.4, 0.25};
  p.kalman = {0.95, 3e-5, 5e-3};
  p.allan_window_samples = static_cast<std::size_t>(allan_window_s * kRateHz);
  if (with_model) p.rate_model = rateModel();
  return p;
}

void BM_PipelineRate(benchmark::State& state) {
  const bool with_model = state.range(0) != 0;
  const auto& data = samples();
  const auto window_s = static_cast<std::size_t>(state.range(1));
  gyrod::daemon::SamplePipeline pipeline(settings(with_model, window_s));
  std::uint64_t seq = 0;
  for (auto _ : state) {
    const Input& s = data[seq % kSamples];
    benchmark::DoNotOptimize(pipeline.process(seq, static_cast<double>(seq) / kRateHz, s.rate, s.temperature));
    ++seq;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.SetLabel(std::string(with_model ? "model (RateEstimator)" : "no model (raw - bias)") + ", Allan window " +
                 std::to_string(window_s) + " s");
}
// Argument 1: the Allan window, gyrod's default 1 h (its rolling sums dominate the pipeline's
// cost) and 60 s (where the rate stream's share shows better). Run with
// --benchmark_repetitions=N --benchmark_report_aggregates_only=true on a shared machine.
BENCHMARK(BM_PipelineRate)->Args({0, 3600})->Args({1, 3600})->Args({0, 60})->Args({1, 60});

}  // namespace

BENCHMARK_MAIN();
