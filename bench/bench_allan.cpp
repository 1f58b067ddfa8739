// Cost of the overlapping Allan deviation at every octave τ on 10⁷ samples, against one
// streaming pass (a sum) over the same array — the floor any O(M)-per-τ method is measured
// against. The ratio is printed at the end (and a run at 23 τ cannot be below ~23 passes).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include "processing/allan.hpp"

namespace {

constexpr std::size_t kSamples = 10'000'000;

const std::vector<double>& samples() {
  static const std::vector<double> y = [] {
    std::mt19937_64 gen(20240601);
    std::normal_distribution<double> normal(0.0, 0.05);
    std::vector<double> v(kSamples);
    for (double& x : v) x = 1.367 + normal(gen);  // a bias and white rate noise, °/s
    return v;
  }();
  return y;
}

void BM_StreamingSum(benchmark::State& state) {
  const auto& y = samples();
  for (auto _ : state) {
    double s = std::accumulate(y.begin(), y.end(), 0.0);
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(y.size()));
}

void BM_OverlappingAdevOctaves(benchmark::State& state) {
  const auto& y = samples();
  const auto ms = gyrod::processing::octaveClusterSizes(y.size());
  for (auto _ : state) {
    auto v = gyrod::processing::overlappingAllanVariances(y, ms);
    benchmark::DoNotOptimize(v.data());
  }
  state.counters["taus"] = static_cast<double>(ms.size());
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(y.size()));
}

void BM_AllanTableOctaves(benchmark::State& state) {  // + ADEV, noise id, edf, χ² bounds
  const auto& y = samples();
  const auto ms = gyrod::processing::octaveClusterSizes(y.size());
  for (auto _ : state) {
    auto t = gyrod::processing::allanDeviationTable(y, 0.02, ms);
    benchmark::DoNotOptimize(t.data());
  }
}

// Median of a few plain wall-clock runs, for the printed ratio.
template <typename F>
double medianNs(F&& f, int runs) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto a = std::chrono::steady_clock::now();
    f();
    const auto b = std::chrono::steady_clock::now();
    t.push_back(std::chrono::duration<double, std::nano>(b - a).count());
  }
  std::nth_element(t.begin(), t.begin() + runs / 2, t.end());
  return t[static_cast<std::size_t>(runs / 2)];
}

}  // namespace

BENCHMARK(BM_StreamingSum)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OverlappingAdevOctaves)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AllanTableOctaves)->Unit(benchmark::kMillisecond)->Iterations(2);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();

  const auto& y = samples();
  const auto ms = gyrod::processing::octaveClusterSizes(y.size());
  const double g_stream_ns = medianNs(
      [&] {
        double s = std::accumulate(y.begin(), y.end(), 0.0);
        benchmark::DoNotOptimize(s);
      },
      15);
  const double g_allan_ns = medianNs(
      [&] {
        auto v = gyrod::processing::overlappingAllanVariances(y, ms);
        benchmark::DoNotOptimize(v.data());
      },
      5);
  std::printf("overlapping ADEV at %zu octave taus on %zu samples: %.1f ms; one streaming sum: %.2f ms; ratio %.1f\n",
              ms.size(), y.size(), g_allan_ns / 1e6, g_stream_ns / 1e6, g_allan_ns / g_stream_ns);
  return 0;
}
