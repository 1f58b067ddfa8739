// "Same bits for any thread count" (docs/method.md, "Long recordings"): the Allan sweep, the
// phase integration in runs, the mean filter's shares and analyzeAxis's steps side by side give
// the same bits with 1, 2, 3 and 5 threads. The thread count is fixed through
// shareThreadOverride, so the test means the same on a 2-core CI machine and a 64-core one.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "fixed_threads.hpp"
#include "processing/allan/allan.hpp"
#include "processing/base/parallel_share.hpp"
#include "processing/paper/axis_analysis.hpp"

using namespace gyrod::processing;

namespace {

std::uint64_t shareBitsOf(double v) {
  std::uint64_t b = 0;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// A still gyro's rate: a bias, white noise and a slow random walk, from a seed. Long enough
// for many 4096-index sweep blocks, several 8192-sample integration runs and octave m past
// 4096 (where the sweep may read the phase's double part only).
std::vector<double> stillGyroRate(std::size_t n, std::uint32_t seed) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> white(0.0, 0.05);
  std::normal_distribution<double> walk(0.0, 2e-5);
  std::vector<double> x(n);
  double drift = 0.0;
  for (double& v : x) {
    drift += walk(gen);
    v = 0.8 + drift + white(gen);
  }
  return x;
}

constexpr std::size_t kThreadCounts[] = {1, 2, 3, 5};

}  // namespace

TEST(ParallelShares, OverlappingAllanVariancesAreTheSameBitsForAnyThreadCount) {
  const std::vector<double> x = stillGyroRate(300'000, 11);
  const std::vector<std::size_t> ms = octaveClusterSizes(x.size());
  ASSERT_GT(ms.back(), 4096u);
  std::vector<double> reference;
  {
    const FixedThreads one(1);
    reference = overlappingAllanVariances(x, ms);
  }
  for (std::size_t threads : kThreadCounts) {
    const FixedThreads fixed(threads);
    const std::vector<double> v = overlappingAllanVariances(x, ms);
    ASSERT_EQ(v.size(), reference.size());
    for (std::size_t k = 0; k < v.size(); ++k)
      EXPECT_EQ(shareBitsOf(v[k]), shareBitsOf(reference[k])) << threads << " threads, m = " << ms[k];
  }
}

TEST(ParallelShares, TheWholeAxisAnalysisIsTheSameBitsForAnyThreadCount) {
  const std::vector<double> x = stillGyroRate(120'000, 12);
  AnalysisOptions options;
  options.rate_hz = 50.0;
  AxisAnalysis reference;
  {
    const FixedThreads one(1);
    reference = analyzeAxis(x, options);
  }
  for (std::size_t threads : kThreadCounts) {
    const FixedThreads fixed(threads);
    const AxisAnalysis a = analyzeAxis(x, options);
    ASSERT_EQ(a.allan.size(), reference.allan.size());
    for (std::size_t k = 0; k < a.allan.size(); ++k) {
      EXPECT_EQ(shareBitsOf(a.allan[k].oadev), shareBitsOf(reference.allan[k].oadev))
          << threads << " threads, k = " << k;
      EXPECT_EQ(shareBitsOf(a.allan[k].adev), shareBitsOf(reference.allan[k].adev)) << threads << " threads, k = " << k;
      EXPECT_EQ(a.allan[k].noise_alpha, reference.allan[k].noise_alpha) << threads << " threads, k = " << k;
    }
    ASSERT_EQ(a.allan_after_kalman.size(), reference.allan_after_kalman.size());
    for (std::size_t k = 0; k < a.allan_after_kalman.size(); ++k)
      EXPECT_EQ(shareBitsOf(a.allan_after_kalman[k].oadev), shareBitsOf(reference.allan_after_kalman[k].oadev))
          << threads << " threads, k = " << k;
    EXPECT_EQ(shareBitsOf(a.noise.value.arw_deg_per_sqrt_h), shareBitsOf(reference.noise.value.arw_deg_per_sqrt_h));
    EXPECT_EQ(shareBitsOf(a.noise_after_kalman.value.arw_deg_per_sqrt_h),
              shareBitsOf(reference.noise_after_kalman.value.arw_deg_per_sqrt_h));
    EXPECT_EQ(shareBitsOf(a.variance.kalman), shareBitsOf(reference.variance.kalman)) << threads << " threads";
  }
}

TEST(ParallelShares, EveryTaskRunsOnceAndTheFirstFailureInTaskOrderIsRethrown) {
  for (std::size_t threads : kThreadCounts) {
    const FixedThreads fixed(threads);
    std::vector<std::atomic<int>> runs(9);
    std::vector<std::function<void()>> tasks;
    for (std::size_t t = 0; t < runs.size(); ++t)
      tasks.emplace_back([&runs, t] {
        runs[t].fetch_add(1);
        if (t == 4 || t == 7) throw std::runtime_error("task " + std::to_string(t));
      });
    try {
      runTasksOnBothCores(std::span(tasks));
      ADD_FAILURE() << "no exception with " << threads << " threads";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "task 4") << threads << " threads";
    }
    for (std::size_t t = 0; t < runs.size(); ++t) EXPECT_EQ(runs[t].load(), 1) << "task " << t << ", " << threads;
  }
}

// The in-place table's `alongside` work sees the samples before they become the phase, once.
TEST(ParallelShares, TheInPlaceTablesAlongsideWorkReadsTheSamplesBeforeTheyBecomeThePhase) {
  const std::vector<double> x = stillGyroRate(50'000, 5);
  const std::vector<std::size_t> ms = octaveClusterSizes(x.size());
  const std::vector<AllanPoint> reference = allanDeviationTable(x, 0.02, ms);
  for (std::size_t threads : kThreadCounts) {
    const FixedThreads fixed(threads);
    AllanWorkspace workspace(x.size());
    std::copy(x.begin(), x.end(), workspace.rateSlots().begin());
    int calls = 0;
    double sum_seen = 0.0;
    const auto table = allanDeviationTableInPlace(workspace, x.size(), 0.02, ms, {}, [&] {
      ++calls;
      for (std::size_t i = 0; i < x.size(); ++i) sum_seen += workspace.rateSlots()[i];
    });
    double sum = 0.0;
    for (double v : x) sum += v;
    EXPECT_EQ(calls, 1) << threads << " threads";
    EXPECT_EQ(shareBitsOf(sum_seen), shareBitsOf(sum)) << threads << " threads";
    ASSERT_EQ(table.size(), reference.size());
    for (std::size_t k = 0; k < table.size(); ++k)
      EXPECT_EQ(shareBitsOf(table[k].oadev), shareBitsOf(reference[k].oadev));
  }
}
