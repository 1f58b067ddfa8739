// The gross-error mean filter against a brute-force version written plainly here: the
// window vector is rebuilt at every step, straight from paper eq. 4 as the header states it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "processing/paper/mean_filter.hpp"

using namespace gyrod::processing;

namespace {

struct BruteForceResult {
  double value;
  std::size_t rejected;
};

BruteForceResult bruteForceWindow(const std::vector<double>& window, double r) {
  double sum = 0.0;
  for (double v : window) sum += v;
  const double m = sum / static_cast<double>(window.size());
  std::vector<double> kept;
  for (double v : window)
    if (!(std::abs(v - m) > r)) kept.push_back(v);
  if (kept.empty()) return {m, window.size()};
  double ks = 0.0;
  for (double v : kept) ks += v;
  return {ks / static_cast<double>(kept.size()), window.size() - kept.size()};
}

// Output k uses samples max(0, k−L+1)..k.
std::vector<BruteForceResult> bruteForceSliding(const std::vector<double>& x, std::size_t L, double r) {
  std::vector<BruteForceResult> out;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const std::size_t first = k + 1 >= L ? k + 1 - L : 0;
    const std::vector<double> window(x.begin() + static_cast<std::ptrdiff_t>(first),
                                     x.begin() + static_cast<std::ptrdiff_t>(k + 1));
    out.push_back(bruteForceWindow(window, r));
  }
  return out;
}

// Gyro-like noise (sd 0.26 °/s) with about 2 % spikes of ±1..3 °/s.
std::vector<double> noisyWithSpikes(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.26);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> x(n);
  for (double& v : x) {
    v = noise(rng);
    if (u(rng) < 0.02) v += (u(rng) < 0.5 ? -1.0 : 1.0) * (1.0 + 2.0 * u(rng));
  }
  return x;
}

void expectMatchesBruteForce(const std::vector<double>& x, std::size_t L, double r) {
  GrossErrorMeanFilter f(L, r);
  const std::vector<BruteForceResult> expected = bruteForceSliding(x, L, r);
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double y = f.update(x[k]);
    ASSERT_NEAR(y, expected[k].value, 1e-12) << "L=" << L << " r=" << r << " k=" << k;
    ASSERT_EQ(f.lastRejected(), expected[k].rejected) << "L=" << L << " r=" << r << " k=" << k;
  }
}

}  // namespace

TEST(GrossErrorMeanFilter, MatchesBruteForceWithSpikesIncludingWarmUp) {
  std::size_t total_rejected = 0;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const std::vector<double> x = noisyWithSpikes(3000, seed);
    for (std::size_t L : {2u, 5u, 20u, 64u}) {
      for (double r : {0.3, 0.8}) expectMatchesBruteForce(x, L, r);
    }
    for (const BruteForceResult& b : bruteForceSliding(x, 20, 0.3)) total_rejected += b.rejected;
  }
  EXPECT_GT(total_rejected, 0u);  // the data do exercise the rejection
}

TEST(GrossErrorMeanFilter, WarmUpUsesWhatHasArrived) {
  // L = 20 but only 3 samples: 1, 2, 30 → m = 11; |30 − 11| = 19 > r = 10 is dropped,
  // |1 − 11|, |2 − 11| ≤ 10 are kept → (1 + 2)/2 = 1.5.
  GrossErrorMeanFilter f(20, 10.0);
  EXPECT_DOUBLE_EQ(f.update(1.0), 1.0);
  EXPECT_DOUBLE_EQ(f.update(2.0), 1.5);
  EXPECT_DOUBLE_EQ(f.update(30.0), 1.5);
  EXPECT_EQ(f.lastRejected(), 1u);
}

TEST(GrossErrorMeanFilter, AllRejectedWindowGivesTheWindowMean) {
  // Window {−1, +1}: m = 0 and both samples are 1 > r = 0.5 away → output m = 0.
  GrossErrorMeanFilter f(2, 0.5);
  f.update(-1.0);
  EXPECT_DOUBLE_EQ(f.update(1.0), 0.0);
  EXPECT_EQ(f.lastRejected(), 2u);
  // And on random data with a tiny r nearly every window is all-rejected.
  expectMatchesBruteForce(noisyWithSpikes(500, 9), 4, 1e-3);
}

TEST(GrossErrorMeanFilter, LengthOneIsIdentity) {
  GrossErrorMeanFilter f(1, 0.3);
  for (double v : noisyWithSpikes(200, 4)) {
    EXPECT_EQ(f.update(v), v);
    EXPECT_EQ(f.lastRejected(), 0u);
  }
}

TEST(GrossErrorMeanFilter, ResetStartsANewWarmUp) {
  const std::vector<double> x = noisyWithSpikes(100, 5);
  GrossErrorMeanFilter f(20, 0.3);
  for (double v : x) f.update(v);
  f.reset();
  const std::vector<BruteForceResult> expected = bruteForceSliding(x, 20, 0.3);
  for (std::size_t k = 0; k < x.size(); ++k) ASSERT_NEAR(f.update(x[k]), expected[k].value, 1e-12);
}

TEST(GrossErrorMeanFilter, RejectsInvalidParametersAndSamples) {
  EXPECT_THROW(GrossErrorMeanFilter(0, 0.3), std::invalid_argument);
  EXPECT_THROW(GrossErrorMeanFilter(20, 0.0), std::invalid_argument);
  EXPECT_THROW(GrossErrorMeanFilter(20, -0.3), std::invalid_argument);
  EXPECT_THROW(GrossErrorMeanFilter(20, NAN), std::invalid_argument);
  EXPECT_THROW(GrossErrorMeanFilter(20, INFINITY), std::invalid_argument);
  GrossErrorMeanFilter f(3, 0.3);
  f.update(1.0);
  EXPECT_THROW(f.update(NAN), std::invalid_argument);
  EXPECT_DOUBLE_EQ(f.update(1.2), 1.1);  // the NaN did not enter the window
  EXPECT_EQ(f.windowLength(), 3u);
  EXPECT_EQ(f.threshold(), 0.3);
}

TEST(BlockMeanFilter, MatchesBruteForceBlocks) {
  const std::vector<double> x = noisyWithSpikes(1013, 6);
  for (std::size_t L : {1u, 7u, 20u}) {
    for (double r : {1e-3, 0.3, 0.8}) {
      const std::vector<double> y = blockMeanFilter(x, L, r);
      ASSERT_EQ(y.size(), x.size() / L);  // the trailing partial block is dropped
      for (std::size_t b = 0; b < y.size(); ++b) {
        const std::vector<double> block(x.begin() + static_cast<std::ptrdiff_t>(b * L),
                                        x.begin() + static_cast<std::ptrdiff_t>((b + 1) * L));
        ASSERT_NEAR(y[b], bruteForceWindow(block, r).value, 1e-12) << "L=" << L << " r=" << r << " b=" << b;
      }
    }
  }
}

TEST(BlockMeanFilter, ShortInputAndInvalidParameters) {
  EXPECT_TRUE(blockMeanFilter(std::vector<double>{1.0, 2.0}, 3, 0.3).empty());
  EXPECT_THROW(blockMeanFilter(std::vector<double>{1.0}, 0, 0.3), std::invalid_argument);
  EXPECT_THROW(blockMeanFilter(std::vector<double>{1.0}, 1, 0.0), std::invalid_argument);
  EXPECT_THROW(blockMeanFilter(std::vector<double>{1.0, NAN}, 1, 0.3), std::invalid_argument);
}
