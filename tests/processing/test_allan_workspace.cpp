// AllanWorkspace: a table whose phase lies in a workspace, or whose rate lies in it and
// becomes the phase, is the same table, bit for bit, as allanDeviationTable's own; a
// workspace serves tables in turn (gyroctl analyze's two tables of one axis share one).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/base/parallel_share.hpp"
#include "processing/paper/axis_analysis.hpp"

using namespace gyrod::processing;

namespace {

std::uint64_t bitsOf(double v) {
  std::uint64_t b = 0;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// White noise on a bias plus `walk_sd` of random walk, from a seed: walk_sd 0 gives white
// noise (no difference taken by the noise identification), a large one a strongly
// correlated series like a Kalman output (differenced twice).
std::vector<double> rateSeries(std::size_t n, double walk_sd, std::uint32_t seed) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> white(0.0, 0.05);
  std::normal_distribution<double> walk(0.0, 1.0);
  std::vector<double> x(n);
  double drift = 0.0;
  for (double& v : x) {
    drift += walk_sd * walk(gen);
    v = 0.8 + drift + white(gen);
  }
  return x;
}

void expectSameTable(const std::vector<AllanPoint>& got, const std::vector<AllanPoint>& want, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t j = 0; j < got.size(); ++j) {
    SCOPED_TRACE(what + ", m = " + std::to_string(want[j].m));
    EXPECT_EQ(got[j].m, want[j].m);
    EXPECT_EQ(bitsOf(got[j].tau_s), bitsOf(want[j].tau_s));
    EXPECT_EQ(bitsOf(got[j].adev), bitsOf(want[j].adev));
    EXPECT_EQ(bitsOf(got[j].oadev), bitsOf(want[j].oadev));
    EXPECT_EQ(got[j].adev_terms, want[j].adev_terms);
    EXPECT_EQ(got[j].oadev_terms, want[j].oadev_terms);
    EXPECT_EQ(got[j].noise_alpha, want[j].noise_alpha);
    EXPECT_EQ(bitsOf(got[j].edf), bitsOf(want[j].edf));
    EXPECT_EQ(bitsOf(got[j].oadev_lo), bitsOf(want[j].oadev_lo));
    EXPECT_EQ(bitsOf(got[j].oadev_hi), bitsOf(want[j].oadev_hi));
  }
}

}  // namespace

TEST(AllanWorkspace, TablesInAWorkspaceAreTheSameBitsAsTheirOwn) {
  struct Case {
    const char* name;
    std::vector<double> rate;
  };
  // 300 000 samples: many sweep blocks and integration runs, octave m past 4096 (hi-only
  // blocks); the short ones take the noise identification's fallbacks (< 30 averages at
  // long m; < 30 samples: the slope of the phase's variances).
  const std::vector<Case> cases = {{"white, 300000", rateSeries(300'000, 0.0, 21)},
                                   {"random walk, 300000", rateSeries(300'000, 0.02, 22)},
                                   {"white, 1000", rateSeries(1000, 0.0, 23)},
                                   {"random walk, 20", rateSeries(20, 0.02, 24)}};
  AllanWorkspace workspace(300'000);  // one workspace for every table below, in turn
  for (const Case& c : cases) {
    for (const std::vector<std::size_t>& ms :
         {octaveClusterSizes(c.rate.size()), denseClusterSizes(c.rate.size(), 8)}) {
      const std::vector<AllanPoint> own = allanDeviationTable(c.rate, 0.02, ms);
      expectSameTable(allanDeviationTable(c.rate, 0.02, ms, {}, workspace), own, std::string(c.name) + ", workspace");
      std::copy(c.rate.begin(), c.rate.end(), workspace.rateSlots().begin());
      expectSameTable(allanDeviationTableInPlace(workspace, c.rate.size(), 0.02, ms), own,
                      std::string(c.name) + ", in place");
    }
  }
}

// A workspace on a column the caller is done with (gyroctl analyze's time column) puts the
// phase in that column's memory when it is long enough, else in its own; same tables.
TEST(AllanWorkspace, AReusedColumnHoldsThePhaseWhenLongEnough) {
  const std::vector<double> rate = rateSeries(100'000, 0.02, 27);
  const std::vector<std::size_t> ms = octaveClusterSizes(rate.size());
  const std::vector<AllanPoint> own = allanDeviationTable(rate, 0.02, ms);
  std::vector<double> time_column(rate.size(), 1.5);  // as long as the rate: one more slot fits
  time_column.reserve(rate.size() + 1);
  const double* column_memory = time_column.data();
  AllanWorkspace on_column(rate.size(), std::move(time_column));
  EXPECT_EQ(on_column.phaseHi(), column_memory);
  expectSameTable(allanDeviationTable(rate, 0.02, ms, {}, on_column), own, "on a reused column");
  std::copy(rate.begin(), rate.end(), on_column.rateSlots().begin());
  expectSameTable(allanDeviationTableInPlace(on_column, rate.size(), 0.02, ms), own, "on a reused column, in place");

  // A column too short is dropped for storage of the workspace's own. Its address proves
  // nothing here: the allocator may hand the freed block's memory straight back (it did, in a
  // full run of this suite); a phase written into the short column would overrun it (ASan)
  // or give other tables.
  std::vector<double> short_column(rate.size() / 2, 1.5);
  short_column.shrink_to_fit();
  AllanWorkspace own_storage(rate.size(), std::move(short_column));
  expectSameTable(allanDeviationTable(rate, 0.02, ms, {}, own_storage), own, "a column too short");
}

TEST(AllanWorkspace, InPlaceTablesAreTheSameBitsForAnyThreadCount) {
  const std::vector<double> rate = rateSeries(200'000, 0.02, 25);
  const std::vector<std::size_t> ms = octaveClusterSizes(rate.size());
  AllanWorkspace workspace(rate.size());
  std::vector<AllanPoint> reference;
  for (std::size_t threads : {1u, 2u, 3u, 5u}) {
    shareThreadOverride().store(threads);
    std::copy(rate.begin(), rate.end(), workspace.rateSlots().begin());
    const std::vector<AllanPoint> table = allanDeviationTableInPlace(workspace, rate.size(), 0.02, ms);
    shareThreadOverride().store(0);
    if (reference.empty())
      reference = table;
    else
      expectSameTable(table, reference, std::to_string(threads) + " threads");
  }
}

TEST(AllanWorkspace, ASeriesLongerThanTheWorkspaceIsRefusedByName) {
  const std::vector<double> rate = rateSeries(101, 0.0, 26);
  AllanWorkspace workspace(100);
  const std::vector<std::size_t> ms = {1, 2, 4};
  try {
    allanDeviationTable(rate, 0.02, ms, {}, workspace);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("101 samples"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("holds 100"), std::string::npos) << e.what();
  }
  EXPECT_THROW(allanDeviationTableInPlace(workspace, 101, 0.02, ms), std::invalid_argument);
  std::copy(rate.begin(), rate.begin() + 100, workspace.rateSlots().begin());
  EXPECT_NO_THROW(allanDeviationTableInPlace(workspace, 100, 0.02, ms));
}

// Axes analysed in turn in one workspace (gyroctl analyze's three axes) come out as each
// analysed in its own: the first longer than the second, so the second finds the first's
// phase and filter output in the workspace.
TEST(AllanWorkspace, AxesAnalysedInTurnInOneWorkspaceAreTheSameBitsAsAlone) {
  const std::vector<std::vector<double>> axes = {rateSeries(150'000, 0.001, 27), rateSeries(90'000, 0.0, 28)};
  AnalysisOptions options;
  options.rate_hz = 100.0;
  AllanWorkspace workspace(150'000);
  for (std::size_t k = 0; k < axes.size(); ++k) {
    SCOPED_TRACE("axis " + std::to_string(k));
    const AxisAnalysis alone = analyzeAxis(axes[k], options);
    const AxisAnalysis shared = analyzeAxis(std::vector<double>(axes[k]), options, workspace);
    expectSameTable(shared.allan, alone.allan, "table 2");
    expectSameTable(shared.allan_after_kalman, alone.allan_after_kalman, "table 4");
    EXPECT_EQ(bitsOf(shared.variance.raw), bitsOf(alone.variance.raw));
    EXPECT_EQ(bitsOf(shared.variance.mean), bitsOf(alone.variance.mean));
    EXPECT_EQ(bitsOf(shared.variance.kalman), bitsOf(alone.variance.kalman));
    EXPECT_EQ(bitsOf(shared.peak_ratio), bitsOf(alone.peak_ratio));
    EXPECT_EQ(bitsOf(shared.filter.kalman.a), bitsOf(alone.filter.kalman.a));
    EXPECT_EQ(bitsOf(shared.filter.kalman.r), bitsOf(alone.filter.kalman.r));
    ASSERT_EQ(shared.ar.size(), alone.ar.size());
    EXPECT_EQ(shared.ar_order_aic, alone.ar_order_aic);
    EXPECT_EQ(bitsOf(shared.noise_after_kalman.value.arw_deg_per_sqrt_h),
              bitsOf(alone.noise_after_kalman.value.arw_deg_per_sqrt_h));
  }
  AllanWorkspace small(1000);
  EXPECT_THROW(analyzeAxis(std::vector<double>(axes[1]), options, small), std::invalid_argument);
}

TEST(AllanWorkspace, OverlappingVariancesInAWorkspaceAreTheSameBits) {
  const std::vector<double> rate = rateSeries(300'000, 0.001, 29);
  const std::vector<std::size_t> ms = octaveClusterSizes(rate.size());
  AllanWorkspace workspace(rate.size());
  const std::vector<double> own = overlappingAllanVariances(rate, ms);
  for (int call = 0; call < 2; ++call) {  // the second finds the first's phase there
    const std::vector<double> kept = overlappingAllanVariances(rate, ms, workspace);
    ASSERT_EQ(kept.size(), own.size());
    for (std::size_t j = 0; j < own.size(); ++j) EXPECT_EQ(bitsOf(kept[j]), bitsOf(own[j])) << "m = " << ms[j];
  }
  AllanWorkspace small(10);
  EXPECT_THROW(overlappingAllanVariances(rate, ms, small), std::invalid_argument);
}
