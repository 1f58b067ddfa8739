// Streaming overlapping Allan variance (window and since start). Truth: the batch estimator
// overlappingAllanVariances / allanDeviationTable (allan.hpp, itself checked against the
// NBS14 reference values) on the same samples, kept by the test in plain vectors; closed
// forms for the χ² interval helper and the exact accumulator.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/allan/rolling_allan.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kRelTol = 1e-9;

// Rate-series models, fixed seeds.
enum class Model { kWhite, kRandomWalk, kBiasOnSmallNoise, kBiasAwayFromFirstSample };

std::string modelName(Model model) {
  switch (model) {
    case Model::kWhite: return "white";
    case Model::kRandomWalk: return "random_walk";
    case Model::kBiasOnSmallNoise: return "bias_1000";
    case Model::kBiasAwayFromFirstSample: return "bias_1000_first_sample_0";
  }
  return "?";
}

std::vector<double> generate(Model model, std::size_t count, std::uint64_t seed) {
  std::mt19937_64 gen(seed);
  std::vector<double> y(count);
  switch (model) {
    case Model::kWhite: {
      std::normal_distribution<double> n(0.0, 0.05);
      for (double& v : y) v = n(gen);
      break;
    }
    case Model::kRandomWalk: {  // rate random walk: y_k = y_{k−1} + w_k
      std::normal_distribution<double> n(0.0, 0.01);
      double level = 0.0;
      for (double& v : y) v = (level += n(gen));
      break;
    }
    case Model::kBiasOnSmallNoise: {  // 1000 °/s bias, 1e-3 °/s white noise
      std::normal_distribution<double> n(0.0, 1e-3);
      for (double& v : y) v = 1000.0 + n(gen);
      break;
    }
    case Model::kBiasAwayFromFirstSample: {           // the reference (first sample) does not remove the bias:
      std::normal_distribution<double> n(0.0, 1e-3);  // the phase grows by 1000 per sample
      for (double& v : y) v = 1000.0 + n(gen);
      if (!y.empty()) y[0] = 0.0;
      break;
    }
  }
  return y;
}

void expectRelNear(double actual, double expected, double tol, const std::string& what) {
  if (std::isnan(expected)) {
    EXPECT_TRUE(std::isnan(actual)) << what << ": expected NaN, got " << actual;
    return;
  }
  EXPECT_NEAR(actual, expected, tol * std::abs(expected)) << what;
}

// The window (last min(count, W) samples) and the whole history against the batch estimator.
void expectMatchesBatch(const RollingOverlappingAllan& rolling, std::span<const double> history,
                        const std::string& what, bool check_since_start = true) {
  const std::size_t n = std::min(history.size(), rolling.windowCapacity());
  ASSERT_EQ(rolling.windowCount(), n) << what;
  ASSERT_EQ(rolling.totalCount(), history.size()) << what;
  const auto window = history.last(n);
  const auto ms = rolling.clusterSizes();
  const std::vector<double> batch_window = overlappingAllanVariances(window, ms);
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const std::string at = what + " window m=" + std::to_string(ms[i]);
    expectRelNear(rolling.windowVariance(i), batch_window[i], kRelTol, at);
    EXPECT_EQ(rolling.windowTerms(i), 2 * ms[i] <= n ? n - 2 * ms[i] + 1 : 0) << at;
  }
  if (!check_since_start) return;
  const std::vector<double> batch_all = overlappingAllanVariances(history, ms);
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const std::string at = what + " since start m=" + std::to_string(ms[i]);
    expectRelNear(rolling.sinceStartVariance(i), batch_all[i], kRelTol, at);
    const std::uint64_t total = history.size();
    EXPECT_EQ(rolling.sinceStartTerms(i), 2 * ms[i] <= total ? total - 2 * ms[i] + 1 : 0) << at;
  }
}

}  // namespace

// ---- the exact accumulator ------------------------------------------------------------

TEST(ExactNonNegativeSum, RemovesALargeValueWithoutLeavingRoundingBehind) {
  ExactNonNegativeSum s;
  s.add(1e16);
  s.add(1.0);
  s.add(1.0);
  s.subtract(1e16);
  EXPECT_EQ(s.value(), 2.0);  // a double sum gives 0 (1e16 + 1 == 1e16)

  ExactNonNegativeSum wide;  // the whole double range, subnormals included
  wide.add(1e300);
  wide.add(0.375);
  wide.add(std::numeric_limits<double>::denorm_min());
  wide.subtract(1e300);
  EXPECT_EQ(wide.value(), 0.375);
  wide.subtract(0.375);
  EXPECT_EQ(wide.value(), std::numeric_limits<double>::denorm_min());
  wide.subtract(std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(wide.value(), 0.0);
}

TEST(ExactNonNegativeSum, ManyAddsAndSubtractsLeaveExactlyTheRemainingValues) {
  // 200 000 values over 40 decades go in; all but three come out again in another order.
  std::mt19937_64 gen(7);
  std::uniform_real_distribution<double> mantissa(1.0, 2.0);
  std::uniform_int_distribution<int> exponent(-70, 70);
  std::vector<double> v(200000);
  for (double& x : v) x = std::ldexp(mantissa(gen), exponent(gen));
  v[10] = 0.5;  // the survivors: their sum 0.5 + 0.25 + 0.125 is exact in double
  v[20] = 0.25;
  v[30] = 0.125;
  ExactNonNegativeSum s;
  for (double x : v) s.add(x);
  std::vector<std::size_t> order(v.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), gen);
  for (std::size_t i : order) {
    if (i != 10 && i != 20 && i != 30) s.subtract(v[i]);
  }
  EXPECT_EQ(s.value(), 0.875);
}

TEST(ExactNonNegativeSum, ValueIsTheCorrectlyScaledSum) {
  ExactNonNegativeSum s;
  s.add(3.0);
  s.add(0x1p-40);
  EXPECT_EQ(s.value(), 3.0 + 0x1p-40);  // exactly representable
  s.add(0x1p900);
  EXPECT_EQ(s.value(), 0x1p900);  // the rest is below half an ulp
  s.clear();
  EXPECT_EQ(s.value(), 0.0);
}

// ---- the χ² interval helper in allan.hpp ------------------------------------------------

TEST(AllanDeviationConfidenceInterval, MatchesChiSquareClosedFormAtTwoDegreesOfFreedom) {
  // χ²(2) is exponential with mean 2: its p-quantile is −2·ln(1 − p).
  const double sigma = 0.37;
  const double c = 0.9;
  const DeviationInterval ci = allanDeviationConfidenceInterval(sigma, 2.0, c);
  const double q_upper = -2.0 * std::log(1.0 - 0.5 * (1.0 + c));
  const double q_lower = -2.0 * std::log(1.0 - 0.5 * (1.0 - c));
  EXPECT_NEAR(ci.lo, sigma * std::sqrt(2.0 / q_upper), 1e-12);
  EXPECT_NEAR(ci.hi, sigma * std::sqrt(2.0 / q_lower), 1e-12);

  const DeviationInterval nan = allanDeviationConfidenceInterval(std::nan(""), 5.0, 0.683);
  EXPECT_TRUE(std::isnan(nan.lo));
  EXPECT_TRUE(std::isnan(nan.hi));
  EXPECT_THROW(allanDeviationConfidenceInterval(1.0, 5.0, 0.0), std::invalid_argument);
  EXPECT_THROW(allanDeviationConfidenceInterval(1.0, 5.0, 1.0), std::invalid_argument);
  EXPECT_THROW(allanDeviationConfidenceInterval(1.0, 0.0, 0.683), std::invalid_argument);
  EXPECT_THROW(allanDeviationConfidenceInterval(1.0, std::nan(""), 0.683), std::invalid_argument);
}

// ---- construction ----------------------------------------------------------------------

TEST(RollingOverlappingAllan, DefaultFactorsAreOctavesUpToHalfTheWindow) {
  auto expect_octaves = [](std::size_t window, std::size_t largest) {
    const RollingOverlappingAllan r(window);
    std::vector<std::size_t> expected;
    for (std::size_t m = 1; m <= largest; m *= 2) expected.push_back(m);
    EXPECT_EQ(std::vector<std::size_t>(r.clusterSizes().begin(), r.clusterSizes().end()), expected)
        << "window " << window;
  };
  expect_octaves(2, 1);
  expect_octaves(5, 2);
  expect_octaves(4096, 2048);
  expect_octaves(4095, 1024);
  expect_octaves(180000, 65536);  // 1 h at 50 Hz: 17 factors
}

TEST(RollingOverlappingAllan, InvalidConstructionThrows) {
  EXPECT_THROW(RollingOverlappingAllan(0), std::invalid_argument);
  EXPECT_THROW(RollingOverlappingAllan(1), std::invalid_argument);
  const std::vector<std::size_t> empty;
  EXPECT_THROW(RollingOverlappingAllan(100, empty), std::invalid_argument);
  EXPECT_THROW(RollingOverlappingAllan(100, std::vector<std::size_t>{0, 1}), std::invalid_argument);
  EXPECT_THROW(RollingOverlappingAllan(10, std::vector<std::size_t>{1, 6}), std::invalid_argument);
  EXPECT_THROW(RollingOverlappingAllan(100, std::vector<std::size_t>{1, 4, 4}), std::invalid_argument);
  EXPECT_THROW(RollingOverlappingAllan(100, std::vector<std::size_t>{4, 2}), std::invalid_argument);
  EXPECT_NO_THROW(RollingOverlappingAllan(10, std::vector<std::size_t>{1, 5}));
  try {
    RollingOverlappingAllan(10, std::vector<std::size_t>{1, 6});
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("6"), std::string::npos) << e.what();
  }
  const RollingOverlappingAllan r(10);
  EXPECT_THROW(static_cast<void>(r.windowVariance(r.clusterSizes().size())), std::out_of_range);
}

// ---- exactness against the batch estimator -------------------------------------------

class RollingWindowVsBatch : public ::testing::TestWithParam<Model> {};

// Window 4096, 50 000 samples: compared at the boundaries (first samples, window just
// filling, just full, first slides) and every 1009 samples, at every octave m up to 2048.
TEST_P(RollingWindowVsBatch, EqualsBatchAtEveryCheckedTimeAndFactor) {
  constexpr std::size_t kWindow = 4096;
  constexpr std::size_t kSamples = 50000;
  const std::vector<double> y = generate(GetParam(), kSamples, 1234);
  RollingOverlappingAllan rolling(kWindow);
  ASSERT_EQ(rolling.clusterSizes().back(), 2048u);
  const std::vector<std::size_t> checkpoints = {1, 2, 3, 4, 100, 4095, 4096, 4097, 4098, 8192, 8193, 12289, kSamples};
  for (std::size_t k = 0; k < kSamples; ++k) {
    rolling.push(y[k]);
    const std::size_t count = k + 1;
    const bool boundary = std::find(checkpoints.begin(), checkpoints.end(), count) != checkpoints.end();
    if (boundary || count % 1009 == 0) {
      // since start on the whole history is the costlier check: at boundaries and every 10th
      expectMatchesBatch(rolling, std::span<const double>(y).first(count),
                         modelName(GetParam()) + " after " + std::to_string(count), boundary || count % 10090 == 0);
      if (HasFailure()) return;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Models, RollingWindowVsBatch,
                         ::testing::Values(Model::kWhite, Model::kRandomWalk, Model::kBiasOnSmallNoise,
                                           Model::kBiasAwayFromFirstSample),
                         [](const auto& info) { return modelName(info.param); });

TEST(RollingOverlappingAllan, ExplicitFactorsEqualBatch) {
  const std::vector<std::size_t> ms = {1, 3, 10, 100, 1500};
  std::vector<double> y = generate(Model::kWhite, 10000, 99);
  const std::vector<double> walk = generate(Model::kRandomWalk, 10000, 100);
  for (std::size_t i = 0; i < y.size(); ++i) y[i] += 7.5 + walk[i];
  RollingOverlappingAllan rolling(3000, ms);
  for (std::size_t k = 0; k < y.size(); ++k) {
    rolling.push(y[k]);
    const std::size_t count = k + 1;
    if (count == 2999 || count == 3000 || count == 3001 || count % 2500 == 0) {
      expectMatchesBatch(rolling, std::span<const double>(y).first(count), "after " + std::to_string(count));
    }
  }
}

// Fewer samples than the window: the window is what has arrived; m without a term is NaN
// with 0 terms, and since start is the same series.
TEST(RollingOverlappingAllan, WindowNotYetFullEqualsBatchOnWhatArrived) {
  const std::vector<double> y = generate(Model::kBiasOnSmallNoise, 1000, 5);
  RollingOverlappingAllan rolling(1000);  // m = 1 … 512
  for (std::size_t i = 0; i < rolling.clusterSizes().size(); ++i) {
    EXPECT_TRUE(std::isnan(rolling.windowVariance(i)));
    EXPECT_TRUE(std::isnan(rolling.sinceStartVariance(i)));
    EXPECT_EQ(rolling.windowTerms(i), 0u);
  }
  const std::vector<std::size_t> checkpoints = {1, 2, 3, 4, 5, 7, 8, 16, 17, 100, 511, 999, 1000};
  for (std::size_t k = 0; k < y.size(); ++k) {
    rolling.push(y[k]);
    const std::size_t count = k + 1;
    if (std::find(checkpoints.begin(), checkpoints.end(), count) == checkpoints.end()) continue;
    expectMatchesBatch(rolling, std::span<const double>(y).first(count), "after " + std::to_string(count));
    for (std::size_t i = 0; i < rolling.clusterSizes().size(); ++i) {
      const std::size_t m = rolling.clusterSizes()[i];
      if (2 * m > count) {
        EXPECT_TRUE(std::isnan(rolling.windowVariance(i))) << "m=" << m << " count=" << count;
        EXPECT_EQ(rolling.windowTerms(i), 0u) << "m=" << m << " count=" << count;
        EXPECT_EQ(rolling.sinceStartTerms(i), 0u) << "m=" << m << " count=" << count;
      } else {
        EXPECT_EQ(rolling.windowVariance(i), rolling.sinceStartVariance(i)) << "m=" << m << " count=" << count;
      }
    }
  }
  // Two samples, m = 1: one term, σ² = (y₁ − y₀)²/2 (NIST SP 1065 eq. 11 with M = 2).
  RollingOverlappingAllan two(10);
  two.push(3.0);
  two.push(3.5);
  EXPECT_DOUBLE_EQ(two.windowVariance(0), 0.125);
}

// A window of 64 over 30 000 samples: since start must be the whole history, not the window.
TEST(RollingOverlappingAllan, SinceStartEqualsBatchOnTheWholeHistory) {
  std::vector<double> y = generate(Model::kRandomWalk, 30000, 11);
  const std::vector<double> white = generate(Model::kWhite, 30000, 12);
  for (std::size_t i = 0; i < y.size(); ++i) y[i] += 3.0 + white[i];
  RollingOverlappingAllan rolling(64);  // m = 1 … 32
  for (std::size_t k = 0; k < y.size(); ++k) {
    rolling.push(y[k]);
    const std::size_t count = k + 1;
    if (count == 63 || count == 64 || count == 65 || count % 7500 == 0) {
      expectMatchesBatch(rolling, std::span<const double>(y).first(count), "after " + std::to_string(count));
    }
  }
  // The two really differ here (a random walk: the last 64 samples are not the history).
  const std::size_t last = rolling.clusterSizes().size() - 1;
  EXPECT_GT(std::abs(rolling.sinceStartVariance(last) / rolling.windowVariance(last) - 1.0), 0.01);
}

// 10⁷ updates on data built to break running sums: a burst of σ ≈ 6000 first (squares of
// ~10⁸ that leave rounding residue of ~10⁻⁶ in a double sum), then a 1000 °/s bias on
// ±0.01 noise (window sums of ~10⁻³) with the first sample 0, so the reference does not
// remove the bias and the phase grows to 10¹⁰. The window (32 samples; m = 1 and the
// largest, 16 — two factors keep the test fast under the sanitizers) must still equal
// batch to 1e-9 at every 10⁶ samples and at the end.
TEST(RollingOverlappingAllan, TenMillionUpdatesStillEqualBatch) {
  constexpr std::size_t kWindow = 32;
  constexpr std::size_t kRing = kWindow + 1;  // the test keeps the last W + 1 samples
  constexpr std::size_t kBurst = 1000;
  constexpr std::size_t kSamples = 10'000'000;
  const std::vector<std::size_t> ms = {1, 16};
  RollingOverlappingAllan rolling(kWindow, ms);
  std::mt19937_64 gen(2024);
  std::uniform_real_distribution<double> burst(-1e4, 1e4);
  std::uniform_real_distribution<double> small(-0.01, 0.01);
  std::vector<double> last(kRing);  // last[k % kRing] = y_k
  // Control: the plain double running sum of squared first differences (m = 1).
  double naive_sum = 0.0;
  std::size_t checks = 0;
  std::size_t slot = 0;  // k % kRing
  for (std::size_t k = 0; k < kSamples; ++k, slot = slot + 1 == kRing ? 0 : slot + 1) {
    const double v = k == 0 ? 0.0 : (k <= kBurst ? burst(gen) : 1000.0 + small(gen));
    const double previous = last[slot == 0 ? kRing - 1 : slot - 1];       // y_{k−1}
    const double oldest = last[slot];                                     // y_{k−W−1}, about to be overwritten
    const double second_oldest = last[slot + 1 == kRing ? 0 : slot + 1];  // y_{k−W}
    if (k >= 1) naive_sum += (v - previous) * (v - previous);
    if (k >= kRing) naive_sum -= (second_oldest - oldest) * (second_oldest - oldest);
    last[slot] = v;
    rolling.push(v);
    const std::size_t count = k + 1;
    if (count % 1'000'000 == 0) {
      std::vector<double> window(kWindow);
      for (std::size_t i = 0; i < kWindow; ++i) window[i] = last[(count - kWindow + i) % kRing];
      const std::vector<double> batch = overlappingAllanVariances(window, ms);
      for (std::size_t i = 0; i < batch.size(); ++i) {
        ASSERT_NEAR(rolling.windowVariance(i), batch[i], kRelTol * batch[i])
            << "after " << count << " samples, m=" << ms[i];
      }
      ++checks;
      if (count == kSamples) {
        // The data do break a plain running sum (so the test can tell the difference).
        const double naive_variance = naive_sum / (2.0 * static_cast<double>(kWindow - 1));
        EXPECT_GT(std::abs(naive_variance / batch[0] - 1.0), 1e-6) << "naive " << naive_variance;
      }
    }
  }
  EXPECT_EQ(checks, 10u);
}

// ---- memory, reset, bad samples --------------------------------------------------------

TEST(RollingOverlappingAllan, StateSizeIsFixedByTheWindowNotByRunTime) {
  const std::vector<std::size_t> ms = {1, 2, 500};
  RollingOverlappingAllan small(1000, ms);
  const RollingOverlappingAllan large(2000, ms);
  const std::size_t bytes = small.stateBytes();
  // Documented: 16 bytes per window sample (+1 phase point) and a fixed cost per m.
  EXPECT_EQ(large.stateBytes() - bytes, 1000 * RollingOverlappingAllan::kBytesPerWindowSample);
  EXPECT_EQ(bytes, sizeof(RollingOverlappingAllan) + 1001 * RollingOverlappingAllan::kBytesPerWindowSample +
                       ms.size() * RollingOverlappingAllan::kBytesPerClusterSize);
  const std::vector<double> y = generate(Model::kWhite, 5000, 3);
  for (double v : y) {
    small.push(v);
    ASSERT_EQ(small.stateBytes(), bytes);
  }
  small.reset();
  EXPECT_EQ(small.stateBytes(), bytes);
}

TEST(RollingOverlappingAllan, ResetForgetsEverything) {
  const std::vector<double> a = generate(Model::kBiasOnSmallNoise, 10000, 21);
  const std::vector<double> b = generate(Model::kRandomWalk, 3000, 22);
  RollingOverlappingAllan reused(2048);
  for (double v : a) reused.push(v);
  reused.reset();
  EXPECT_EQ(reused.totalCount(), 0u);
  EXPECT_EQ(reused.windowCount(), 0u);
  for (std::size_t i = 0; i < reused.clusterSizes().size(); ++i) {
    EXPECT_TRUE(std::isnan(reused.windowVariance(i)));
    EXPECT_TRUE(std::isnan(reused.sinceStartVariance(i)));
  }
  RollingOverlappingAllan fresh(2048);
  for (double v : b) {
    reused.push(v);
    fresh.push(v);
  }
  for (std::size_t i = 0; i < fresh.clusterSizes().size(); ++i) {
    EXPECT_EQ(std::isnan(reused.windowVariance(i)), std::isnan(fresh.windowVariance(i)));
    if (!std::isnan(fresh.windowVariance(i))) {
      EXPECT_EQ(reused.windowVariance(i), fresh.windowVariance(i));
      EXPECT_EQ(reused.sinceStartVariance(i), fresh.sinceStartVariance(i));
    }
  }
  expectMatchesBatch(reused, b, "after reset");
}

TEST(RollingOverlappingAllan, BadSamplesThrowAndLeaveTheStateUnchanged) {
  std::vector<double> y = generate(Model::kWhite, 300, 8);
  RollingOverlappingAllan rolling(128);
  for (std::size_t k = 0; k < 200; ++k) rolling.push(y[k]);
  const double before = rolling.windowVariance(0);
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                     1e101, -1e101}) {
    EXPECT_THROW(rolling.push(bad), std::invalid_argument) << bad;
  }
  EXPECT_EQ(rolling.totalCount(), 200u);
  EXPECT_EQ(rolling.windowVariance(0), before);
  for (std::size_t k = 200; k < 300; ++k) rolling.push(y[k]);
  expectMatchesBatch(rolling, y, "after rejected samples");
}

TEST(RollingOverlappingAllan, ConstantInputGivesExactlyZero) {
  RollingOverlappingAllan rolling(100);
  for (int k = 0; k < 1000; ++k) rolling.push(-12.345);
  for (std::size_t i = 0; i < rolling.clusterSizes().size(); ++i) {
    EXPECT_EQ(rolling.windowVariance(i), 0.0);
    EXPECT_EQ(rolling.sinceStartVariance(i), 0.0);
  }
}

// ---- snapshot --------------------------------------------------------------------------

// The window snapshot is allanDeviationTable's overlapping half on the window's samples;
// since start has the whole history's oadev with the window's noise type and N = total + 1.
TEST(RollingOverlappingAllan, SnapshotMatchesAllanDeviationTable) {
  for (Model model : {Model::kBiasOnSmallNoise, Model::kRandomWalk}) {
    const std::vector<double> y = generate(model, 5000, 31);
    RollingOverlappingAllan rolling(2048);
    for (double v : y) rolling.push(v);
    const AllanOptions options{0.9};
    const auto snap = rolling.snapshot(0.02, options);
    const auto window = std::span<const double>(y).last(2048);
    const auto ms = rolling.clusterSizes();
    const auto table = allanDeviationTable(window, 0.02, ms, options);
    const std::vector<double> whole = overlappingAllanVariances(y, ms);
    ASSERT_EQ(snap.window.size(), ms.size());
    ASSERT_EQ(snap.since_start.size(), ms.size());
    bool saw_random_walk = false;
    for (std::size_t i = 0; i < ms.size(); ++i) {
      const std::string at = modelName(model) + " m=" + std::to_string(ms[i]);
      const AllanPoint& w = snap.window[i];
      const AllanPoint& t = table[i];
      EXPECT_EQ(w.m, t.m) << at;
      EXPECT_DOUBLE_EQ(w.tau_s, t.tau_s) << at;
      expectRelNear(w.oadev, t.oadev, kRelTol, at);
      EXPECT_EQ(w.oadev_terms, t.oadev_terms) << at;
      EXPECT_EQ(w.noise_alpha, t.noise_alpha) << at;
      expectRelNear(w.edf, t.edf, 1e-12, at);
      expectRelNear(w.oadev_lo, t.oadev_lo, kRelTol, at);
      expectRelNear(w.oadev_hi, t.oadev_hi, kRelTol, at);
      EXPECT_TRUE(std::isnan(w.adev)) << at;
      EXPECT_EQ(w.adev_terms, 0u) << at;
      saw_random_walk = saw_random_walk || w.noise_alpha == -2;

      const AllanPoint& s = snap.since_start[i];
      EXPECT_EQ(s.m, ms[i]) << at;
      expectRelNear(s.oadev, std::sqrt(whole[i]), kRelTol, at);
      EXPECT_EQ(s.oadev_terms, 5000 - 2 * ms[i] + 1) << at;
      EXPECT_EQ(s.noise_alpha, w.noise_alpha) << at;
      expectRelNear(s.edf, overlappingAllanEdf(w.noise_alpha, 5001, ms[i]), 1e-12, at);
      EXPECT_LT(s.oadev_lo, s.oadev) << at;
      EXPECT_GT(s.oadev_hi, s.oadev) << at;
    }
    if (model == Model::kRandomWalk) {
      EXPECT_TRUE(saw_random_walk);
    }
  }
}

TEST(RollingOverlappingAllan, SnapshotOfAFewSamplesHasNoConfidenceYet) {
  RollingOverlappingAllan rolling(16);  // m = 1 … 8
  auto snap = rolling.snapshot(0.02);
  for (const AllanPoint& p : snap.window) {
    EXPECT_TRUE(std::isnan(p.oadev));
    EXPECT_EQ(p.oadev_terms, 0u);
    EXPECT_TRUE(std::isnan(p.edf));
  }
  const std::vector<double> y = {1.0, 1.5, 0.75, 2.0, 1.25};
  for (std::size_t k = 0; k < 3; ++k) rolling.push(y[k]);
  snap = rolling.snapshot(0.02);
  // Three samples, m = 1: two terms d = y₁ − y₀ = 0.5 and y₂ − y₁ = −0.75, σ² = Σd²/(2·1²·2).
  EXPECT_DOUBLE_EQ(snap.window[0].oadev, std::sqrt((0.25 + 0.5625) / 4.0));
  EXPECT_TRUE(std::isnan(snap.window[0].edf));
  EXPECT_TRUE(std::isnan(snap.since_start[0].oadev_lo));
  rolling.push(y[3]);  // four samples: the noise type can be identified
  snap = rolling.snapshot(0.02);
  const auto table = allanDeviationTable(std::span<const double>(y).first(4), 0.02, rolling.clusterSizes());
  for (std::size_t i = 0; i < table.size(); ++i) {
    EXPECT_EQ(snap.window[i].noise_alpha, table[i].noise_alpha);
    expectRelNear(snap.window[i].oadev, table[i].oadev, kRelTol, "m=" + std::to_string(table[i].m));
    expectRelNear(snap.window[i].edf, table[i].edf, 1e-12, "m=" + std::to_string(table[i].m));
  }
  EXPECT_TRUE(std::isfinite(snap.window[0].edf));
  EXPECT_THROW(rolling.snapshot(0.0), std::invalid_argument);
  EXPECT_THROW(rolling.snapshot(std::nan("")), std::invalid_argument);
  EXPECT_THROW(rolling.snapshot(0.02, AllanOptions{1.0}), std::invalid_argument);
}

namespace {

// Every accumulator of `a` and `b`, exactly equal (window and since start).
void expectSameState(const RollingOverlappingAllan& a, const RollingOverlappingAllan& b) {
  ASSERT_EQ(a.totalCount(), b.totalCount());
  for (std::size_t i = 0; i < a.clusterSizes().size(); ++i) {
    const double wa = a.windowVariance(i), wb = b.windowVariance(i);
    EXPECT_TRUE(wa == wb || (std::isnan(wa) && std::isnan(wb))) << "window m=" << a.clusterSizes()[i];
    const double sa = a.sinceStartVariance(i), sb = b.sinceStartVariance(i);
    EXPECT_TRUE(sa == sb || (std::isnan(sa) && std::isnan(sb))) << "since start m=" << a.clusterSizes()[i];
  }
}

// Copies `source` in steps of `points`, pushing `pushes_per_step` samples into it after each
// step; returns the last step's result and leaves `copy` as the steps made it.
RollingOverlappingAllan::CopyStep copyWhilePushing(RollingOverlappingAllan& source, RollingOverlappingAllan& copy,
                                                   std::size_t points, std::size_t pushes_per_step,
                                                   const std::vector<double>& more, std::size_t& next) {
  copy.beginCopyFrom(source);
  while (true) {
    const auto step = copy.continueCopyFrom(source, points);
    if (step != RollingOverlappingAllan::CopyStep::Copying) return step;
    for (std::size_t k = 0; k < pushes_per_step && next < more.size(); ++k) source.push(more[next++]);
  }
}

}  // namespace

// The copy in steps is the source as it was when the copy began, bit for bit: its statistics
// now, and every statistic after the same further samples (which reads the whole phase ring).
TEST(RollingOverlappingAllan, CopyInStepsIsTheSourceAtItsBeginningWhileTheSourceGoesOn) {
  const std::size_t window = 1000;
  for (const std::size_t filled : {std::size_t{300}, std::size_t{1000}, std::size_t{3777}}) {
    SCOPED_TRACE("samples before the copy: " + std::to_string(filled));
    const auto x = generate(Model::kRandomWalk, filled + 4000, 17 + filled);
    RollingOverlappingAllan source(window), copy(window);
    for (std::size_t i = 0; i < filled; ++i) source.push(x[i]);
    const RollingOverlappingAllan at_beginning = source;
    std::size_t next = filled;
    ASSERT_EQ(copyWhilePushing(source, copy, 64, 7, x, next), RollingOverlappingAllan::CopyStep::Done);
    EXPECT_GT(next, filled + 100);  // the source took samples while it was copied
    expectSameState(copy, at_beginning);
    RollingOverlappingAllan reference = at_beginning;
    for (std::size_t i = filled; i < filled + 2500; ++i) {
      copy.push(x[i]);
      reference.push(x[i]);
    }
    expectSameState(copy, reference);
  }
}

TEST(RollingOverlappingAllan, CopyInStepsOverrunWhenThePushesOvertakeItOrTheSourceIsReset) {
  const std::size_t window = 500;
  const auto x = generate(Model::kWhite, 5000, 5);
  RollingOverlappingAllan source(window), copy(window);
  for (std::size_t i = 0; i < 2000; ++i) source.push(x[i]);
  std::size_t next = 2000;
  // 20 samples pushed for every 10 points copied: the pushes reach points not yet copied.
  EXPECT_EQ(copyWhilePushing(source, copy, 10, 20, x, next), RollingOverlappingAllan::CopyStep::Overrun);

  copy.beginCopyFrom(source);
  source.reset();
  source.push(1.0);
  EXPECT_EQ(copy.continueCopyFrom(source, 1000), RollingOverlappingAllan::CopyStep::Overrun);

  // Begun again, it completes.
  const RollingOverlappingAllan at_beginning = source;
  copy.beginCopyFrom(source);
  EXPECT_EQ(copy.continueCopyFrom(source, 1000), RollingOverlappingAllan::CopyStep::Done);
  expectSameState(copy, at_beginning);

  RollingOverlappingAllan other_window(400);
  EXPECT_THROW(other_window.beginCopyFrom(source), std::invalid_argument);
  EXPECT_THROW(other_window.continueCopyFrom(source, 10), std::logic_error);
}
