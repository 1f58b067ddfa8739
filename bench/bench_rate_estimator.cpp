// Per-sample cost of the `rate` stream (RateEstimator: model bias, still detector, residual
// Kalman on three axes, with and without its low-pass) beside the paper's chain step that gyrod
// runs today (AxisFilterChain: mean filter + scalar Kalman, once per axis), in the same run.
// Issue 11 asks for ≤ 0.5 µs added per sample. The input alternates 20 s at rest with 20 s
// of a 1 Hz rotation, so both of the detector's outcomes are timed.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "processing/motion/rate_estimator.hpp"
#include "processing/paper/filter_chain.hpp"

namespace {

constexpr std::size_t kSamples = 200000;
constexpr double kRateHz = 50.0;

struct Input {
  double t;
  gyrod::processing::AngularRate rate;
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
      v[i] = {t, {1.367 + n(rng) + w, -0.4 + n(rng), 0.25 + n(rng)}, 25.0 + 10.0 * (1.0 - std::exp(-t / 600.0))};
    }
    return v;
  }();
  return data;
}

gyrod::processing::RateEstimatorParameters rateParameters(bool low_pass) {
  gyrod::processing::RateEstimatorParameters p;
  p.rate_hz = kRateHz;
  const std::array<double, 3> bias = {1.367, -0.4, 0.25};
  for (std::size_t a = 0; a < 3; ++a) {
    auto& m = p.axes[a];
    m.bias_dps = bias[a];
    m.temperature_coefficient_dps_per_c = 0.0;  // the model's terms cost the same at any value
    m.temperature_coefficient_std_dps_per_c = 0.003;
    m.warm_up_amplitude_dps = 0.05;  // the warm-up shape on: its exp() is timed too
    m.warm_up_time_constant_s = 300.0;
    m.bias_std_dps = 0.01;
    m.terms = {0.1663, 0.95164, 0.60565, 0.07759, 0.43223};
  }
  if (low_pass) p.low_pass_hz = 5.0;
  return p;
}

void BM_RateEstimator(benchmark::State& state) {
  const auto& data = samples();
  gyrod::processing::RateEstimator estimator(rateParameters(state.range(0) != 0));
  std::size_t i = 0;
  for (auto _ : state) {
    const Input& s = data[i];
    benchmark::DoNotOptimize(estimator.update(s.t, s.rate, s.temperature));
    if (++i == kSamples) i = 0;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.SetLabel(state.range(0) != 0 ? "3 axes, low-pass 5 Hz" : "3 axes, no low-pass");
}
BENCHMARK(BM_RateEstimator)->Arg(0)->Arg(1);

void BM_PaperChain(benchmark::State& state) {
  const auto& data = samples();
  gyrod::processing::FilterChainParameters p;
  p.kalman = {0.95, 3e-5, 5e-3, 0.0, {}};
  std::array<gyrod::processing::AxisFilterChain, 3> chains = {gyrod::processing::AxisFilterChain(p),
                                                              gyrod::processing::AxisFilterChain(p),
                                                              gyrod::processing::AxisFilterChain(p)};
  std::size_t i = 0;
  for (auto _ : state) {
    const Input& s = data[i];
    for (std::size_t a = 0; a < 3; ++a) benchmark::DoNotOptimize(chains[a].update(s.rate[a] - 1.0));
    if (++i == kSamples) i = 0;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.SetLabel("3 axes, mean filter L=20 + Kalman");
}
BENCHMARK(BM_PaperChain);

}  // namespace

BENCHMARK_MAIN();
