// Zero-mean, reverse-arrangements and χ² normality tests against hand counts, the
// textbook's worked example and tabulated acceptance region, and seeded simulations.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include "processing/paper/statistics_tests.hpp"

using namespace gyrod::processing;

namespace {

std::vector<double> normalSamples(std::size_t n, double mean, double sd, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> d(mean, sd);
  std::vector<double> x(n);
  for (double& v : x) v = d(rng);
  return x;
}

// The permutation of 0..N−1 with exactly `a` inversions built from its Lehmer code:
// position i is given the value with c_i smaller values still unused to its right,
// c_i = min(remaining, N−1−i). Plain and independent of the code under test.
std::vector<double> sequenceWithInversions(std::size_t n, std::size_t a) {
  std::vector<double> unused(n);
  for (std::size_t i = 0; i < n; ++i) unused[i] = static_cast<double>(i);
  std::vector<double> v;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t c = std::min(a, n - 1 - i);
    a -= c;
    v.push_back(unused[c]);
    unused.erase(unused.begin() + static_cast<std::ptrdiff_t>(c));
  }
  return v;
}

}  // namespace

// ---------------------------------------------------------------- zero mean

TEST(ZeroMeanTest, HandComputedStatistic) {
  // mean 3, s² = (4+1+0+1+4)/4 = 2.5, z = 3/(√2.5/√5) = 3√2.
  const std::vector<double> x{1, 2, 3, 4, 5};
  const ZeroMeanTest t = zeroMeanTest(x);
  EXPECT_DOUBLE_EQ(t.mean, 3.0);
  EXPECT_NEAR(t.standard_deviation, std::sqrt(2.5), 1e-15);
  EXPECT_NEAR(t.z, 3.0 * std::sqrt(2.0), 1e-12);
  EXPECT_FALSE(t.zero_mean);
}

TEST(ZeroMeanTest, SymmetricDataHasZeroMean) {
  const ZeroMeanTest t = zeroMeanTest(std::vector<double>{-2, -1, 0, 1, 2});
  EXPECT_EQ(t.z, 0.0);
  EXPECT_TRUE(t.zero_mean);
}

TEST(ZeroMeanTest, SeededNormalDataAcceptedUnlessOffset) {
  // 10 seeds of N(0,1), n = 2000: rejection probability 5 % each; an offset of 0.2 gives
  // E[z] ≈ 8.9, far beyond 1.96.
  int accepted = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    accepted += zeroMeanTest(normalSamples(2000, 0.0, 1.0, seed)).zero_mean ? 1 : 0;
    EXPECT_FALSE(zeroMeanTest(normalSamples(2000, 0.2, 1.0, seed + 100)).zero_mean);
  }
  EXPECT_GE(accepted, 8);
}

TEST(ZeroMeanTest, RejectsBadInput) {
  EXPECT_THROW(zeroMeanTest(std::vector<double>{1.0}), std::invalid_argument);
  EXPECT_THROW(zeroMeanTest(std::vector<double>{1.0, NAN, 2.0}), std::invalid_argument);
}

// ---------------------------------------------------------------- reverse arrangements

TEST(ReverseArrangements, BendatPiersolWorkedExampleOfEightObservations) {
  // Bendat & Piersol, Random Data §4.5.2: x = 5, 3, 8, 9, 4, 1, 7, 5 has
  // A1..A7 = 3, 1, 4, 4, 1, 0, 1 and A = 14.
  EXPECT_EQ(countReverseArrangements(std::vector<double>{5, 3, 8, 9, 4, 1, 7, 5}), 14u);
}

TEST(ReverseArrangements, MonotoneSequencesAndTies) {
  std::vector<double> up(30), down(30);
  for (std::size_t i = 0; i < 30; ++i) {
    up[i] = static_cast<double>(i);
    down[i] = -static_cast<double>(i);
  }
  EXPECT_EQ(countReverseArrangements(up), 0u);
  EXPECT_EQ(countReverseArrangements(down), 30u * 29u / 2u);
  EXPECT_EQ(countReverseArrangements(std::vector<double>(12, 1.0)), 0u);  // ties are not reversals

  const ReverseArrangementsTest t = reverseArrangementsTestOfSequence(up);
  EXPECT_EQ(t.arrangements, 0.0);
  EXPECT_DOUBLE_EQ(t.mean_arrangements, 30.0 * 29.0 / 4.0);
  EXPECT_DOUBLE_EQ(t.sd_arrangements, std::sqrt(30.0 * 65.0 * 29.0 / 72.0));
  EXPECT_FALSE(t.stationary);
}

TEST(ReverseArrangements, LehmerConstructionHasTheRequestedCount) {
  // Guards the helper the next test relies on.
  for (std::size_t a : {0u, 1u, 64u, 95u, 126u, 190u})
    EXPECT_EQ(countReverseArrangements(sequenceWithInversions(20, a)), a);
}

TEST(ReverseArrangements, NormalApproximationReproducesTabulatedRegionForN20) {
  // Bendat & Piersol, Appendix A table of the reverse-arrangement distribution: for N = 20
  // at α = 0.05 the hypothesis is accepted for 64 < A ≤ 125. Here μ_A = 95 and σ_A² = 237.5, so |u| < 1.96 accepts exactly 65..125.
  const ReverseArrangementsTest lo_out = reverseArrangementsTestOfSequence(sequenceWithInversions(20, 64));
  const ReverseArrangementsTest lo_in = reverseArrangementsTestOfSequence(sequenceWithInversions(20, 65));
  const ReverseArrangementsTest hi_in = reverseArrangementsTestOfSequence(sequenceWithInversions(20, 125));
  const ReverseArrangementsTest hi_out = reverseArrangementsTestOfSequence(sequenceWithInversions(20, 126));
  EXPECT_DOUBLE_EQ(lo_in.mean_arrangements, 95.0);
  EXPECT_NEAR(lo_in.sd_arrangements, std::sqrt(237.5), 1e-12);
  EXPECT_NEAR(lo_in.u, -30.0 / std::sqrt(237.5), 1e-12);
  EXPECT_FALSE(lo_out.stationary);
  EXPECT_TRUE(lo_in.stationary);
  EXPECT_TRUE(hi_in.stationary);
  EXPECT_FALSE(hi_out.stationary);
}

TEST(ReverseArrangements, SegmentMeanSquaresAboutOverallMean) {
  // 10 segments of 4 samples ±s_k around an overall mean of 7, remainder of 3 unused:
  // each segment's mean square about 7 is s_k². s = 1,3,2,5,4,6,8,7,10,9 has reversals
  // (3,2), (5,4), (8,7), (10,9) → A = 4.
  const std::vector<double> s{1, 3, 2, 5, 4, 6, 8, 7, 10, 9};
  std::vector<double> x;
  for (double sk : s)
    for (double sign : {1.0, -1.0, -1.0, 1.0}) x.push_back(7.0 + sign * sk);
  for (int i = 0; i < 3; ++i) x.push_back(1000.0);  // would dominate if it were used
  // The remainder shifts no overall mean: it is excluded from it too.
  const ReverseArrangementsTest t = reverseArrangementsTest(x, 10);
  EXPECT_EQ(t.segments, 10u);
  EXPECT_EQ(t.arrangements, 4.0);
}

TEST(ReverseArrangements, WhiteNoiseIsStationaryOnMostSeeds) {
  // 100 segment values of iid data are iid: each seed rejects with probability ≈ 5 %.
  int stationary = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed)
    stationary += reverseArrangementsTest(normalSamples(20000, 1.367, 0.26, seed)).stationary ? 1 : 0;
  EXPECT_GE(stationary, 16);
}

TEST(ReverseArrangements, TrendInVarianceIsNonStationary) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> d(0.0, 1.0);
  std::vector<double> x(20000);
  for (std::size_t i = 0; i < x.size(); ++i)
    x[i] = 1.367 + (1.0 + 2.0 * static_cast<double>(i) / static_cast<double>(x.size())) * d(rng);
  const ReverseArrangementsTest t = reverseArrangementsTest(x);
  EXPECT_FALSE(t.stationary);
  EXPECT_LT(t.u, -5.0);  // mean squares rise along the record: few reversals
}

TEST(ReverseArrangements, TrendInMeanIsSeenBySegmentMeans) {
  std::vector<double> x = normalSamples(20000, 0.0, 1.0, 11);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] -= 0.5 * static_cast<double>(i) / static_cast<double>(x.size());
  const ReverseArrangementsTest t = reverseArrangementsTest(x, 100, SegmentStatistic::Mean);
  EXPECT_FALSE(t.stationary);
  EXPECT_GT(t.u, 5.0);  // falling means: many reversals
}

TEST(ReverseArrangements, RejectsBadInput) {
  const std::vector<double> x = normalSamples(100, 0.0, 1.0, 3);
  EXPECT_THROW(reverseArrangementsTest(x, 9), std::invalid_argument);
  EXPECT_THROW(reverseArrangementsTest(std::span<const double>(x).first(50), 51), std::invalid_argument);
  EXPECT_THROW(reverseArrangementsTestOfSequence(std::span<const double>(x).first(9)), std::invalid_argument);
  std::vector<double> bad = x;
  bad[17] = INFINITY;
  EXPECT_THROW(reverseArrangementsTest(bad, 10), std::invalid_argument);
  EXPECT_NO_THROW(reverseArrangementsTest(std::span<const double>(x).first(10), 10));
}

// ---------------------------------------------------------------- χ² normality

TEST(ChiSquareNormality, HandComputedFiveBinExample) {
  // 25 samples: 6 at −2, 5 at −0.5, 3 at 0, 5 at +0.5, 6 at +2. Mean 0, ML sd =
  // √((12·4 + 10·0.25)/25) = √2.02 ≈ 1.421; the 5 equiprobable classes split at
  // ±0.2533·sd ≈ ±0.36 and ±0.8416·sd ≈ ±1.20, so the counts are 6,5,3,5,6 against 5 each:
  // χ² = (1 + 0 + 4 + 0 + 1)/5 = 1.2 with 2 dof; χ²₀.₉₅(2) = −2 ln 0.05; p = e^(−0.6).
  std::vector<double> x;
  for (auto [value, count] : {std::pair{-2.0, 6}, {-0.5, 5}, {0.0, 3}, {0.5, 5}, {2.0, 6}})
    for (int i = 0; i < count; ++i) x.push_back(value);
  const ChiSquareNormalityTest t = chiSquareNormalityTest(x, 5);
  EXPECT_EQ(t.bins, 5u);
  EXPECT_NEAR(t.chi2, 1.2, 1e-12);
  EXPECT_EQ(t.dof, 2u);
  EXPECT_NEAR(t.critical, -2.0 * std::log(0.05), 1e-9);
  EXPECT_NEAR(t.p_value, std::exp(-0.6), 1e-9);
  EXPECT_TRUE(t.normal);
  // 25 samples choose 5 classes by default too (Moore: 2·25^0.4 ≈ 7.2, capped at n/5).
  EXPECT_EQ(chiSquareNormalityTest(x).bins, 5u);
}

TEST(ChiSquareNormality, DefaultBinCount) {
  // round(2·n^0.4): n = 1000 → 31.70 → 32; n = 100 → 12.62 → 13; n = 30 → 7.80 → 8, capped
  // at 30/5 = 6; n = 10⁶ → 502 → 100.
  EXPECT_EQ(chiSquareNormalityTest(normalSamples(1000, 0, 1, 1)).bins, 32u);
  EXPECT_EQ(chiSquareNormalityTest(normalSamples(100, 0, 1, 1)).bins, 13u);
  EXPECT_EQ(chiSquareNormalityTest(normalSamples(30, 0, 1, 1)).bins, 6u);
  const ChiSquareNormalityTest big = chiSquareNormalityTest(normalSamples(1000000, 0, 1, 1));
  EXPECT_EQ(big.bins, 100u);
  EXPECT_EQ(big.dof, 97u);
}

TEST(ChiSquareNormality, SeededNormalDataAccepted) {
  int accepted = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed)
    accepted += chiSquareNormalityTest(normalSamples(5000, 1.367, 0.26, seed)).normal ? 1 : 0;
  EXPECT_GE(accepted, 8);  // ≈ 5–8 % rejection each
}

TEST(ChiSquareNormality, UniformAndExponentialDataRejected) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::exponential_distribution<double> e(1.0);
    std::vector<double> xu(3000), xe(3000);
    for (double& v : xu) v = u(rng);
    for (double& v : xe) v = e(rng);
    const ChiSquareNormalityTest tu = chiSquareNormalityTest(xu);
    const ChiSquareNormalityTest te = chiSquareNormalityTest(xe);
    EXPECT_FALSE(tu.normal);
    EXPECT_FALSE(te.normal);
    EXPECT_LT(tu.p_value, 1e-6);
    EXPECT_LT(te.p_value, 1e-6);
  }
}

TEST(ChiSquareNormality, FalseRejectionRateNearFivePercent) {
  // With mean and sd estimated from the ungrouped data the statistic lies asymptotically
  // between χ²(k−3) and χ²(k−1) (Chernoff–Lehmann): a rate of 5 % to ≈ 8 % here (k = 24);
  // 2000 other seeds gave 4.7 %. Over 200 samples the rate's sd is ≤ 2 %, so [1 %, 14 %]
  // leaves > 2 sd below 5 % and > 3 sd above 8 %.
  int rejected = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const ChiSquareNormalityTest t = chiSquareNormalityTest(normalSamples(500, -3.0, 2.0, 1000 + seed));
    ASSERT_EQ(t.bins, 24u);
    rejected += t.normal ? 0 : 1;
  }
  EXPECT_GE(rejected, 2);
  EXPECT_LE(rejected, 28);
}

TEST(ChiSquareNormality, RejectsBadInput) {
  const std::vector<double> x = normalSamples(100, 0.0, 1.0, 2);
  EXPECT_THROW(chiSquareNormalityTest(std::span<const double>(x).first(24)), std::invalid_argument);
  EXPECT_THROW(chiSquareNormalityTest(x, 3), std::invalid_argument);   // dof would be 0
  EXPECT_THROW(chiSquareNormalityTest(x, 21), std::invalid_argument);  // expected count < 5
  EXPECT_NO_THROW(chiSquareNormalityTest(x, 20));
  EXPECT_THROW(chiSquareNormalityTest(std::vector<double>(50, 2.0)), std::invalid_argument);
  std::vector<double> bad = x;
  bad[0] = NAN;
  EXPECT_THROW(chiSquareNormalityTest(bad), std::invalid_argument);
}
