// Cost of the overlapping Allan deviation at every octave τ on 10⁷ samples, against one
// streaming pass (a sum) over the same array — the floor any O(M)-per-τ method is measured
// against. The ratio is printed at the end (and a run at 23 τ cannot be below ~23 passes).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "processing/allan/allan.hpp"

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

// The same in a workspace kept from call to call, as gyroctl analyze keeps one for an
// axis's two tables: the phase's pages are not cleared again for each call.
void BM_OverlappingAdevOctavesInWorkspace(benchmark::State& state) {
  const auto& y = samples();
  const auto ms = gyrod::processing::octaveClusterSizes(y.size());
  gyrod::processing::AllanWorkspace workspace(y.size());
  for (auto _ : state) {
    auto v = gyrod::processing::overlappingAllanVariances(y, ms, workspace);
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

double processCpuNs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
}

// Medians of a few plain runs, for the printed ratios: wall time, and the CPU time of the
// process (all threads), which a machine loaded by other work inflates much less.
struct Timing {
  double wall_ns = 0.0;
  double cpu_ns = 0.0;
};
template <typename F>
Timing medianNs(F&& f, int runs) {
  std::vector<double> wall, cpu;
  for (int i = 0; i < runs; ++i) {
    const auto a = std::chrono::steady_clock::now();
    const double c = processCpuNs();
    f();
    cpu.push_back(processCpuNs() - c);
    const auto b = std::chrono::steady_clock::now();
    wall.push_back(std::chrono::duration<double, std::nano>(b - a).count());
  }
  const auto median = [runs](std::vector<double>& t) {
    std::nth_element(t.begin(), t.begin() + runs / 2, t.end());
    return t[static_cast<std::size_t>(runs / 2)];
  };
  return {median(wall), median(cpu)};
}

std::string loadAverage() {
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  if (f == nullptr) return "unknown";
  char buf[64] = {};
  const bool read = std::fgets(buf, sizeof buf, f) != nullptr;
  std::fclose(f);
  if (!read) return "unknown";
  std::string s(buf);
  // The 1, 5 and 15 minute averages: the first three fields.
  std::size_t end = 0;
  for (int field = 0; field < 3 && end != std::string::npos; ++field) end = s.find(' ', end + (field > 0 ? 1 : 0));
  return s.substr(0, end);
}

}  // namespace

BENCHMARK(BM_StreamingSum)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OverlappingAdevOctaves)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OverlappingAdevOctavesInWorkspace)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AllanTableOctaves)->Unit(benchmark::kMillisecond)->Iterations(2);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();

  const auto& y = samples();
  const auto ms = gyrod::processing::octaveClusterSizes(y.size());
  const Timing stream = medianNs(
      [&] {
        double s = std::accumulate(y.begin(), y.end(), 0.0);
        benchmark::DoNotOptimize(s);
      },
      15);
  const Timing allan = medianNs(
      [&] {
        auto v = gyrod::processing::overlappingAllanVariances(y, ms);
        benchmark::DoNotOptimize(v.data());
      },
      5);
  gyrod::processing::AllanWorkspace workspace(y.size());
  const Timing kept = medianNs(
      [&] {
        auto v = gyrod::processing::overlappingAllanVariances(y, ms, workspace);
        benchmark::DoNotOptimize(v.data());
      },
      5);
  std::printf(
      "overlapping ADEV at %zu octave taus on %zu samples: %.1f ms wall, %.1f ms CPU; one streaming sum: %.2f ms wall, "
      "%.2f ms CPU; ratio %.1f wall, %.1f CPU (load %s)\n",
      ms.size(), y.size(), allan.wall_ns / 1e6, allan.cpu_ns / 1e6, stream.wall_ns / 1e6, stream.cpu_ns / 1e6,
      allan.wall_ns / stream.wall_ns, allan.cpu_ns / stream.cpu_ns, loadAverage().c_str());
  std::printf(
      "the same in a workspace kept between calls (as gyroctl analyze): %.1f ms wall, %.1f ms CPU; ratio %.1f wall, "
      "%.1f CPU\n",
      kept.wall_ns / 1e6, kept.cpu_ns / 1e6, kept.wall_ns / stream.wall_ns, kept.cpu_ns / stream.cpu_ns);
  return 0;
}
