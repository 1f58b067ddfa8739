// Allan variance estimators, cluster sizes, noise identification, edf and confidence
// intervals. Truth: the NBS14 reference values published in NIST SP 1065 (Table 31 area,
// "1000-point" and "10-point" sets), closed forms (white noise, a pure ramp) and plain
// brute-force re-implementations of the textbook definitions written in this file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "processing/allan/allan.hpp"

using namespace gyrod::processing;

namespace {

// NBS14 1000-point set (NIST SP 1065 §12.2): n₀ = 1234567890, n_{i+1} = 16807·n_i mod
// 2147483647, y_i = n_i / 2147483647, n₀ included.
std::vector<double> nbs14ThousandPoints() {
  std::vector<double> y;
  std::uint64_t n = 1234567890;
  for (int i = 0; i < 1000; ++i) {
    y.push_back(static_cast<double>(n) / 2147483647.0);
    n = (16807 * n) % 2147483647;
  }
  return y;
}

const std::vector<double> kNbs14TenPoints = {892, 809, 823, 798, 671, 644, 883, 903, 677};

// The published values carry 7 significant digits: the computed value must round to
// exactly the published one (|x − p| ≤ half a unit in the 7th digit) ...
void expectRoundsToPublished(double computed, double published, const std::string& what) {
  const double unit = std::pow(10.0, std::floor(std::log10(std::abs(published))) - 6.0);
  EXPECT_LE(std::abs(computed - published), 0.5 * unit * (1.0 + 1e-9)) << what << " computed " << computed;
  // ... and, the brief's bar, agree to 1e-6 relative.
  EXPECT_NEAR(computed / published, 1.0, 1e-6) << what;
}

std::vector<double> whiteNoise(std::size_t count, double sigma, std::uint64_t seed, double offset = 0.0) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> normal(0.0, sigma);
  std::vector<double> y(count);
  for (double& v : y) v = offset + normal(gen);
  return y;
}

// Plain definitions, written for clarity, not speed.
double bruteForceAllanVariance(const std::vector<double>& y, std::size_t m) {
  const std::size_t k = y.size() / m;
  std::vector<long double> means(k);
  for (std::size_t c = 0; c < k; ++c) {
    long double s = 0;
    for (std::size_t i = 0; i < m; ++i) s += y[c * m + i];
    means[c] = s / m;
  }
  long double acc = 0;
  for (std::size_t c = 0; c + 1 < k; ++c) acc += (means[c + 1] - means[c]) * (means[c + 1] - means[c]);
  return static_cast<double>(acc / (2.0L * (k - 1)));
}

// NIST SP 1065 eq. 10 (frequency form): 1/(2m²(M−2m+1)) Σ_j [Σ_{i=j}^{j+m−1} (y_{i+m} − y_i)]².
double bruteForceOverlappingAllanVariance(const std::vector<double>& y, std::size_t m) {
  const std::size_t terms = y.size() - 2 * m + 1;
  long double acc = 0;
  for (std::size_t j = 0; j < terms; ++j) {
    long double inner = 0;
    for (std::size_t i = j; i < j + m; ++i) inner += static_cast<long double>(y[i + m]) - y[i];
    acc += inner * inner;
  }
  return static_cast<double>(acc / (2.0L * m * m * terms));
}

}  // namespace

// ---- NBS14 reference values ------------------------------------------------------------

TEST(AllanNbs14, ThousandPointSetMatchesPublishedValues) {
  const auto y = nbs14ThousandPoints();
  ASSERT_NEAR(y[0], 1234567890.0 / 2147483647.0, 1e-15);
  struct Row {
    std::size_t m;
    double adev, oadev;
  };
  for (const Row& r : {Row{1, 2.922319e-01, 2.922319e-01}, Row{10, 9.965736e-02, 9.159953e-02},
                       Row{100, 3.897804e-02, 3.241343e-02}}) {
    expectRoundsToPublished(std::sqrt(allanVariance(y, r.m)), r.adev, "ADEV m=" + std::to_string(r.m));
    expectRoundsToPublished(std::sqrt(overlappingAllanVariance(y, r.m)), r.oadev, "OADEV m=" + std::to_string(r.m));
  }
}

TEST(AllanNbs14, TenPointSetMatchesPublishedValues) {
  expectRoundsToPublished(std::sqrt(allanVariance(kNbs14TenPoints, 1)), 91.22945, "ADEV m=1");
  expectRoundsToPublished(std::sqrt(overlappingAllanVariance(kNbs14TenPoints, 1)), 91.22945, "OADEV m=1");
  expectRoundsToPublished(std::sqrt(allanVariance(kNbs14TenPoints, 2)), 115.8082, "ADEV m=2");
  expectRoundsToPublished(std::sqrt(overlappingAllanVariance(kNbs14TenPoints, 2)), 85.95287, "OADEV m=2");
}

TEST(AllanNbs14, TableAgreesWithSingleEstimatorsAndCountsTerms) {
  const auto y = nbs14ThousandPoints();
  const std::vector<std::size_t> ms = {1, 10, 100, 500};
  const auto table = allanDeviationTable(y, 1.0, ms);
  ASSERT_EQ(table.size(), ms.size());
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const std::size_t m = ms[i];
    EXPECT_EQ(table[i].m, m);
    EXPECT_DOUBLE_EQ(table[i].tau_s, static_cast<double>(m));
    EXPECT_EQ(table[i].adev_terms, 1000 / m - 1);
    EXPECT_EQ(table[i].oadev_terms, 1000 - 2 * m + 1);
    EXPECT_NEAR(table[i].adev, std::sqrt(allanVariance(y, m)), 1e-15);
    EXPECT_NEAR(table[i].oadev, std::sqrt(overlappingAllanVariance(y, m)), 1e-15);
  }
}

// ---- estimators against brute force, invariances, robustness ----------------------------

TEST(AllanEstimators, AgreeWithBruteForceDefinitions) {
  const auto y = whiteNoise(1001, 0.7, 11);  // odd length: clusters do not tile the series
  for (std::size_t m : {1u, 2u, 3u, 7u, 50u, 333u, 500u}) {
    EXPECT_NEAR(allanVariance(y, m) / bruteForceAllanVariance(y, m), 1.0, 1e-12) << "m=" << m;
    EXPECT_NEAR(overlappingAllanVariance(y, m) / bruteForceOverlappingAllanVariance(y, m), 1.0, 1e-12) << "m=" << m;
  }
  std::vector<std::size_t> ms = {1, 3, 50, 500, 501};
  const auto many = overlappingAllanVariances(y, ms);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(many[i] / bruteForceOverlappingAllanVariance(y, ms[i]), 1.0, 1e-12);
  EXPECT_TRUE(std::isnan(many[4]));
}

TEST(AllanEstimators, TooLongAveragingGivesNaN) {
  const auto y = whiteNoise(100, 1.0, 3);
  EXPECT_FALSE(std::isnan(allanVariance(y, 50)));             // 2 clusters, 1 difference
  EXPECT_TRUE(std::isnan(allanVariance(y, 51)));              // 1 cluster
  EXPECT_FALSE(std::isnan(overlappingAllanVariance(y, 50)));  // M − 2m + 1 = 1
  EXPECT_TRUE(std::isnan(overlappingAllanVariance(y, 51)));
  const std::vector<std::size_t> ms = {50, 51, 1000};
  const auto table = allanDeviationTable(y, 0.02, ms);
  EXPECT_EQ(table[0].oadev_terms, 1u);
  EXPECT_TRUE(std::isfinite(table[0].edf));
  for (std::size_t i = 1; i < 3; ++i) {
    EXPECT_TRUE(std::isnan(table[i].adev));
    EXPECT_TRUE(std::isnan(table[i].oadev));
    EXPECT_TRUE(std::isnan(table[i].edf));
    EXPECT_TRUE(std::isnan(table[i].oadev_lo));
    EXPECT_TRUE(std::isnan(table[i].oadev_hi));
    EXPECT_EQ(table[i].oadev_terms, 0u);
  }
  EXPECT_EQ(table[2].adev_terms, 0u);
}

TEST(AllanEstimators, BadInputThrows) {
  const auto y = whiteNoise(100, 1.0, 3);
  EXPECT_THROW(allanVariance(y, 0), std::invalid_argument);
  EXPECT_THROW(overlappingAllanVariance(y, 0), std::invalid_argument);
  EXPECT_THROW(identifyPowerLawNoise(y, 0), std::invalid_argument);
  const std::vector<std::size_t> ms = {1, 2};
  EXPECT_THROW(allanDeviationTable(y, 0.0, ms), std::invalid_argument);
  EXPECT_THROW(allanDeviationTable(y, 0.02, ms, AllanOptions{1.0}), std::invalid_argument);
  const std::vector<std::size_t> zero = {0};
  EXPECT_THROW(allanDeviationTable(y, 0.02, zero), std::invalid_argument);
  const std::vector<double> two = {1.0, 2.0};
  EXPECT_THROW(allanDeviationTable(two, 0.02, ms), std::invalid_argument);
  auto with_nan = y;
  with_nan[17] = std::nan("");
  try {
    overlappingAllanVariance(with_nan, 1);
    FAIL() << "a NaN sample must be rejected";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rate sample 17"), std::string::npos) << e.what();
  }
}

TEST(AllanEstimators, ConstantOffsetDoesNotChangeTheResult) {
  const auto y = whiteNoise(4096, 0.3, 5);
  const auto shifted = whiteNoise(4096, 0.3, 5, 3.7);
  for (std::size_t m : octaveClusterSizes(y.size())) {
    EXPECT_NEAR(overlappingAllanVariance(shifted, m) / overlappingAllanVariance(y, m), 1.0, 1e-12) << m;
    EXPECT_NEAR(allanVariance(shifted, m) / allanVariance(y, m), 1.0, 1e-12) << m;
  }
}

TEST(AllanEstimators, LargeBiasOnSmallNoiseKeepsFullAccuracy) {
  // Bias 1000 on noise of σ = 1e-3: adding the bias rounds each sample by ≤ 5.7e-14, i.e.
  // 6e-11 of σ, so 1e-9 relative is reachable; integrating the raw (un-centred) rate in
  // double would lose ~1e-5 here.
  const std::size_t count = 1 << 17;
  const auto noise = whiteNoise(count, 1e-3, 7);
  const auto biased = whiteNoise(count, 1e-3, 7, 1000.0);
  for (std::size_t m : octaveClusterSizes(count)) {
    EXPECT_NEAR(overlappingAllanVariance(biased, m) / overlappingAllanVariance(noise, m), 1.0, 1e-9) << m;
    EXPECT_NEAR(allanVariance(biased, m) / allanVariance(noise, m), 1.0, 1e-9) << m;
  }
}

TEST(AllanEstimators, PureRampGivesClosedForm) {
  // y_i = R·i·τ0: every cluster-mean difference is R·τ exactly, so σ²(τ) = R²τ²/2 for both
  // estimators (IEEE 952 rate ramp). The phase grows as i², the hard case for integration:
  // a plain double running sum of 2·10⁶ samples is off by ~1e-7 at m = 1.
  const std::size_t count = 2000000;
  const double tau0 = 0.02, ramp = 3e-4;
  std::vector<double> y(count);
  for (std::size_t i = 0; i < count; ++i) y[i] = 5.0 + ramp * static_cast<double>(i) * tau0;
  for (std::size_t m : {1u, 2u, 16u, 1000u, 1000000u}) {
    const double tau = static_cast<double>(m) * tau0;
    const double expected = ramp * ramp * tau * tau / 2.0;
    EXPECT_NEAR(overlappingAllanVariance(y, m) / expected, 1.0, 1e-9) << m;
    EXPECT_NEAR(allanVariance(y, m) / expected, 1.0, 1e-9) << m;
  }
}

// ---- white noise: value and confidence-interval coverage -------------------------------

TEST(AllanWhiteNoise, ConfidenceIntervalsCoverTheTrueDeviationAtNominalRate) {
  // White rate noise of σ has Allan variance σ²/m at every m, for both estimators. The
  // 68.3 % intervals should contain σ/√m in about 68 % of (seed, τ) cases. With 40 seeds ×
  // 12 τ (points of one series are correlated), 50–85 % is a loose but failing-capable bar.
  const double sigma = 0.05;
  const std::size_t count = 8192;
  const auto ms = octaveClusterSizes(count);
  int inside = 0, total = 0;
  for (std::uint64_t seed = 100; seed < 140; ++seed) {
    const auto y = whiteNoise(count, sigma, seed);
    const auto table = allanDeviationTable(y, 0.02, ms);
    for (const AllanPoint& p : table) {
      const double truth = sigma / std::sqrt(static_cast<double>(p.m));
      ASSERT_LT(p.oadev_lo, p.oadev);
      ASSERT_GT(p.oadev_hi, p.oadev);
      if (p.oadev_lo <= truth && truth <= p.oadev_hi) ++inside;
      ++total;
      if (p.m <= 64) {  // ≥ 128 clusters: the non-overlapping value within 5 of its standard errors
        const double se = truth * std::sqrt(1.0 / (2.0 * static_cast<double>(p.adev_terms)));
        EXPECT_NEAR(p.adev, truth, 5.0 * se) << "seed " << seed << " m " << p.m;
      }
    }
  }
  const double coverage = static_cast<double>(inside) / total;
  EXPECT_GT(coverage, 0.50);
  EXPECT_LT(coverage, 0.85);
  RecordProperty("coverage", std::to_string(coverage));
}

TEST(AllanConfidence, IntervalWidthFollowsEdfAndConfidence) {
  const auto y = whiteNoise(50000, 1.0, 9);
  const std::vector<std::size_t> ms = {1, 100};
  const auto narrow = allanDeviationTable(y, 1.0, ms, AllanOptions{0.5});
  const auto wide = allanDeviationTable(y, 1.0, ms, AllanOptions{0.95});
  for (std::size_t i = 0; i < ms.size(); ++i) {
    EXPECT_LT(wide[i].oadev_lo, narrow[i].oadev_lo);
    EXPECT_GT(wide[i].oadev_hi, narrow[i].oadev_hi);
    // Large edf: σ̂²/σ² ≈ N(1, 2/edf), so the 95 % half-width of σ is ≈ 1.96/√(2·edf).
    const double half = (wide[i].oadev_hi - wide[i].oadev_lo) / 2.0 / wide[i].oadev;
    EXPECT_NEAR(half, 1.959964 / std::sqrt(2.0 * wide[i].edf), 0.05 * half) << ms[i];
  }
  EXPECT_GT(narrow[0].edf, narrow[1].edf);
}

// ---- cluster sizes ---------------------------------------------------------------------

TEST(AllanClusterSizes, OctaveDoublesUpToHalfTheSeries) {
  for (std::size_t count : {2u, 3u, 100u, 1024u, 1025u, 180000u}) {
    const auto ms = octaveClusterSizes(count);
    ASSERT_FALSE(ms.empty()) << count;
    EXPECT_EQ(ms.front(), 1u);
    for (std::size_t i = 1; i < ms.size(); ++i) EXPECT_EQ(ms[i], 2 * ms[i - 1]);
    EXPECT_LE(2 * ms.back(), count);
    EXPECT_GT(4 * ms.back(), count);  // the next octave would not fit
  }
  EXPECT_TRUE(octaveClusterSizes(1).empty());
  EXPECT_TRUE(octaveClusterSizes(0).empty());
}

TEST(AllanClusterSizes, DenseIsLogSpacedUniqueAndBounded) {
  const std::size_t count = 180000;
  const auto ms = denseClusterSizes(count, 10);
  ASSERT_FALSE(ms.empty());
  EXPECT_EQ(ms.front(), 1u);
  for (std::size_t i = 1; i < ms.size(); ++i) {
    EXPECT_GT(ms[i], ms[i - 1]);
    if (ms[i - 1] >= 100) {  // away from integer crowding, the step is 10^(1/10) ≈ 1.259
      EXPECT_NEAR(static_cast<double>(ms[i]) / static_cast<double>(ms[i - 1]), std::pow(10.0, 0.1), 0.01);
    }
  }
  EXPECT_LE(2 * ms.back(), count);
  EXPECT_GT(2.0 * std::pow(10.0, 0.1) * static_cast<double>(ms.back()), 0.99 * count);
  // One per decade step: exactly 10 values in [100, 1000).
  int in_decade = 0;
  for (std::size_t m : ms) in_decade += (m >= 100 && m < 1000) ? 1 : 0;
  EXPECT_EQ(in_decade, 10);
  EXPECT_THROW(denseClusterSizes(count, 0), std::invalid_argument);
  EXPECT_EQ(denseClusterSizes(3, 10), std::vector<std::size_t>{1});
}

TEST(AllanClusterSizes, ExplicitTauListMapsToWholeSamples) {
  const std::vector<double> taus = {0.02, 0.3, 1.0, 100.0};
  const auto ms = clusterSizesForTaus(taus, 0.02, 180000);
  EXPECT_EQ(ms, (std::vector<std::size_t>{1, 15, 50, 5000}));
  const std::vector<double> tenth = {0.3};  // 0.3/0.1 = 2.9999999999999996 in double
  EXPECT_EQ(clusterSizesForTaus(tenth, 0.1, 100), std::vector<std::size_t>{3});
}

TEST(AllanClusterSizes, ExplicitTauListErrorsNameTheTau) {
  auto message = [](std::vector<double> taus, double tau0, std::size_t count) -> std::string {
    try {
      clusterSizesForTaus(taus, tau0, count);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no exception";
  };
  const std::string fractional = message({0.02, 0.015}, 0.01, 1000);
  EXPECT_NE(fractional.find("0.015"), std::string::npos) << fractional;
  EXPECT_NE(fractional.find("whole number"), std::string::npos) << fractional;
  const std::string too_long = message({1.0, 12.5}, 0.02, 1000);  // m = 625 > 1000/2
  EXPECT_NE(too_long.find("12.5"), std::string::npos) << too_long;
  EXPECT_NE(too_long.find("too long"), std::string::npos) << too_long;
  EXPECT_EQ(message({10.0}, 0.02, 1000), "no exception");                    // m = 500 = M/2 is the last valid one
  EXPECT_NE(message({0.005}, 0.01, 1000).find("0.005"), std::string::npos);  // half a sample
  EXPECT_NE(message({-1.0}, 0.01, 1000).find("-1"), std::string::npos);
  EXPECT_NE(message({1.0}, 0.0, 1000).find("tau0"), std::string::npos);
}

// ---- noise identification and edf ------------------------------------------------------

TEST(AllanNoiseId, WhiteRandomWalkAndWhitePhaseAreRecognised) {
  // r1 of n white averages has standard deviation ≈ 1/√n; with n ≥ 1024 the class
  // boundaries (|ρ| = 0.25) are ≥ 8 standard errors away, for every seed.
  const std::size_t count = 65536;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const auto white = whiteNoise(count + 1, 1.0, seed);
    std::vector<double> walk(count), white_phase(count), white_rate(white.begin(), white.begin() + count);
    double s = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
      s += white[i];
      walk[i] = s;                               // rate random walk: α = −2
      white_phase[i] = white[i + 1] - white[i];  // rate = difference of white phase: α = +2
    }
    for (std::size_t m : {1u, 4u, 16u, 64u}) {
      EXPECT_EQ(identifyPowerLawNoise(white_rate, m), 0) << "seed " << seed << " m " << m;
      EXPECT_EQ(identifyPowerLawNoise(walk, m), -2) << "seed " << seed << " m " << m;
      EXPECT_EQ(identifyPowerLawNoise(white_phase, m), 2) << "seed " << seed << " m " << m;
    }
  }
}

TEST(AllanNoiseId, ShortSeriesFallBackWithoutThrowing) {
  // m beyond M/30 reuses the longest m with 30 averages; below 30 samples the slope is used.
  const auto walk_steps = whiteNoise(3000, 1.0, 4);
  std::vector<double> walk(walk_steps.size());
  std::partial_sum(walk_steps.begin(), walk_steps.end(), walk.begin());
  EXPECT_EQ(identifyPowerLawNoise(walk, 1000), -2);
  // Pure ramp: the first difference is numerically constant → ramp class (α = −2).
  std::vector<double> ramp(600);
  for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = 0.1 * static_cast<double>(i);
  EXPECT_EQ(identifyPowerLawNoise(ramp, 4), -2);
  // NBS14 10-point set: 9 samples, slope fallback; any answer must be a valid class.
  for (std::size_t m : {1u, 2u, 4u, 10u}) {
    const int alpha = identifyPowerLawNoise(kNbs14TenPoints, m);
    EXPECT_GE(alpha, -2);
    EXPECT_LE(alpha, 2);
  }
  EXPECT_THROW(identifyPowerLawNoise(std::vector<double>{1.0, 2.0}, 1), std::invalid_argument);
}

TEST(AllanEdf, SimpleApproximationsOfSp1065) {
  // Values of the NIST SP 1065 Table 5 expressions worked by hand for N = 1001, m = 10:
  //   white PM  (N+1)(N−2m)/(2(N−m)) = 1002·981/1982                      = 495.9445005
  //   white FM  [3(N−1)/(2m) − 2(N−2)/N]·4m²/(4m²+5) = (150 − 1.996004)·400/405 = 146.1767
  //   flicker FM 5N²/(4m(N+3m)) = 5·1002001/(40·1031)                      = 121.4841
  //   RW FM (N−2)/m·((N−1)² − 3m(N−1) + 4m²)/(N−3)² = 99.9·(10⁶−30000+400)/996004 = 97.3319
  EXPECT_NEAR(overlappingAllanEdf(2, 1001, 10), 495.9445005, 1e-6);
  EXPECT_NEAR(overlappingAllanEdf(0, 1001, 10), 146.176786, 1e-5);
  EXPECT_NEAR(overlappingAllanEdf(-1, 1001, 10), 121.484117, 1e-5);
  EXPECT_NEAR(overlappingAllanEdf(-2, 1001, 10), 97.331898, 1e-5);
  //   flicker PM exp(√(ln((N−1)/(2m))·ln((2m+1)(N−1)/4))) = exp(√(ln 50 · ln 5250))
  EXPECT_NEAR(overlappingAllanEdf(1, 1001, 10), std::exp(std::sqrt(std::log(50.0) * std::log(5250.0))), 1e-9);
  //   flicker FM at m = 1: 2(N−2)/(2.3N − 4.9) = 1998/2297.4
  EXPECT_NEAR(overlappingAllanEdf(-1, 1001, 1), 1998.0 / 2297.4, 1e-12);
  EXPECT_THROW(overlappingAllanEdf(3, 1001, 10), std::invalid_argument);
  EXPECT_THROW(overlappingAllanEdf(0, 20, 10), std::invalid_argument);  // N < 2m + 1
  EXPECT_THROW(overlappingAllanEdf(0, 20, 0), std::invalid_argument);
  for (int alpha = -2; alpha <= 2; ++alpha) EXPECT_GT(overlappingAllanEdf(alpha, 3, 1), 0.0) << alpha;
}
