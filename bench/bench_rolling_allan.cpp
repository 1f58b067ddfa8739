// Cost of the streaming overlapping Allan variance as the daemon runs it: a 1 h window at
// 50 Hz (W = 180 000 samples, octave m = 1 … 65 536, 17 factors), window already full.
//  - BM_RollingPush: one push() (ns per sample; the daemon pushes 50/s per stream).
//  - BM_RollingSnapshot: snapshot() of the full window (noise id, edf, χ² bounds).
//  - BM_BatchTableOnWindow: allanDeviationTable on the same 180 000 samples, for scale.
// The state size in bytes is reported as a counter.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/allan/rolling_allan.hpp"

namespace {

constexpr std::size_t kWindow = 180'000;  // 1 h at 50 Hz
constexpr double kTau0 = 0.02;

const std::vector<double>& samples() {
  static const std::vector<double> y = [] {
    std::mt19937_64 gen(20240601);
    std::normal_distribution<double> normal(0.0, 0.05);
    std::vector<double> v(2 * kWindow);
    for (double& x : v) x = 1.367 + normal(gen);  // a bias and white rate noise, °/s
    return v;
  }();
  return y;
}

gyrod::processing::RollingOverlappingAllan fullWindow() {
  gyrod::processing::RollingOverlappingAllan rolling(kWindow);
  const auto& y = samples();
  for (std::size_t k = 0; k < kWindow; ++k) rolling.push(y[k]);
  return rolling;
}

void BM_RollingPush(benchmark::State& state) {
  auto rolling = fullWindow();
  const auto& y = samples();
  std::size_t k = 0;
  for (auto _ : state) {
    rolling.push(y[k]);
    if (++k == y.size()) k = 0;
  }
  benchmark::DoNotOptimize(rolling.windowVariance(0));
  state.counters["taus"] = static_cast<double>(rolling.clusterSizes().size());
  state.counters["state_bytes"] = static_cast<double>(rolling.stateBytes());
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

void BM_RollingSnapshot(benchmark::State& state) {
  const auto rolling = fullWindow();
  for (auto _ : state) {
    auto snap = rolling.snapshot(kTau0);
    benchmark::DoNotOptimize(snap.window.data());
  }
}

void BM_BatchTableOnWindow(benchmark::State& state) {
  const auto& y = samples();
  const std::vector<double> window(y.begin(), y.begin() + kWindow);
  const auto ms = gyrod::processing::octaveClusterSizes(kWindow);
  for (auto _ : state) {
    auto t = gyrod::processing::allanDeviationTable(window, kTau0, ms);
    benchmark::DoNotOptimize(t.data());
  }
}

}  // namespace

BENCHMARK(BM_RollingPush);
BENCHMARK(BM_RollingSnapshot)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BatchTableOnWindow)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
