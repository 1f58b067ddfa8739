// analyzeAxis runs the mean filter once and the Kalman on its output in place of the chain,
// and consumes its series: the figures must be those of the filter chain itself and of the
// copying overload.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "processing/paper/axis_analysis.hpp"
#include "processing/paper/filter_chain.hpp"

using namespace gyrod::processing;

namespace {

std::vector<double> stillAxis(std::size_t count, std::uint64_t seed) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> white(0.0, 0.05);
  std::normal_distribution<double> step(0.0, 2e-4);
  std::vector<double> y(count);
  double drift = 0.0;
  for (double& v : y) {
    drift = 0.999 * drift + step(gen);
    v = 0.4 + drift + white(gen) + (gen() % 5000 == 0 ? 2.0 : 0.0);  // rare gross errors
  }
  return y;
}

TEST(AxisAnalysis, FilterFiguresAreThoseOfTheFilterChain) {
  const std::vector<double> raw = stillAxis(20'000, 7);
  AnalysisOptions options;
  const AxisAnalysis a = analyzeAxis(std::span<const double>(raw), options);

  std::vector<double> x = raw;
  removeLinearTrend(x, 1.0 / options.rate_hz);
  const FilterChainParameters p = identifyFilterChain(x, options.mean_window, options.mean_threshold_dps);
  EXPECT_EQ(a.filter.kalman.a, p.kalman.a);
  EXPECT_EQ(a.filter.kalman.q, p.kalman.q);
  EXPECT_EQ(a.filter.kalman.r, p.kalman.r);
  AxisFilterChain chain(p);
  std::vector<double> mean(x.size()), kalman(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const FilteredRate f = chain.update(x[i]);
    mean[i] = f.mean_dps;
    kalman[i] = f.kalman_dps;
  }
  EXPECT_EQ(a.variance.raw, varianceAboutMean(x));
  EXPECT_EQ(a.variance.mean, varianceAboutMean(mean));
  EXPECT_EQ(a.variance.kalman, varianceAboutMean(kalman));
  EXPECT_EQ(a.peak_ratio, peakDeviationFromMean(kalman) / peakDeviationFromMean(x));
  const std::vector<AllanPoint> after =
      allanDeviationTable(kalman, 1.0 / options.rate_hz, octaveClusterSizes(x.size()));
  ASSERT_EQ(a.allan_after_kalman.size(), after.size());
  for (std::size_t j = 0; j < after.size(); ++j) EXPECT_EQ(a.allan_after_kalman[j].oadev, after[j].oadev);

  const AxisAnalysis consumed = analyzeAxis(std::vector<double>(raw), options);
  EXPECT_EQ(consumed.variance.kalman, a.variance.kalman);
  EXPECT_EQ(consumed.allan.back().oadev, a.allan.back().oadev);
}

}  // namespace

// The mean filter of analyzeAxis (four windows at a time, in shares on the cores) gives the
// bits of GrossErrorMeanFilter run sample by sample, for windows short and long, lengths
// that are not a multiple of four, and gross errors that the rejection drops.
TEST(AxisAnalysis, MeanFilterOutputIsTheFiltersBitForBit) {
  const std::vector<double> raw = stillAxis(150'003, 11);
  for (const std::size_t window : {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{20}, std::size_t{57}})
    for (const double threshold : {0.3, 0.02}) {
      GrossErrorMeanFilter filter(window, threshold);
      const std::vector<double> out = grossErrorMeanFiltered(raw, window, threshold);
      ASSERT_EQ(out.size(), raw.size());
      std::size_t rejected_somewhere = 0;
      for (std::size_t i = 0; i < raw.size(); ++i) {
        const double expected = filter.update(raw[i]);
        rejected_somewhere += filter.lastRejected() > 0 ? 1 : 0;
        ASSERT_EQ(std::bit_cast<std::uint64_t>(out[i]), std::bit_cast<std::uint64_t>(expected))
            << "window " << window << ", threshold " << threshold << ", sample " << i;
      }
      if (window > 1) {  // the rejection was exercised
        EXPECT_GT(rejected_somewhere, 0u) << "window " << window;
      }
    }
  // Shorter than a window: only the filling outputs.
  const std::vector<double> few(raw.begin(), raw.begin() + 7);
  GrossErrorMeanFilter filter(20, 0.3);
  const std::vector<double> out = grossErrorMeanFiltered(few, 20, 0.3);
  for (std::size_t i = 0; i < few.size(); ++i) EXPECT_EQ(out[i], filter.update(few[i]));
}

TEST(AxisAnalysis, MeanFilterRefusesANonFiniteSampleAsTheFilterDoes) {
  std::vector<double> raw = stillAxis(1000, 12);
  raw[700] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(grossErrorMeanFiltered(raw, 20, 0.3), std::invalid_argument);
}
