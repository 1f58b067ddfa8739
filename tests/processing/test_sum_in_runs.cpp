// allan_kernels::totalOfRuns(sumRuns(…)), the sample sum behind every Allan estimator's
// mean: the exact sum rounded once, for lengths that leave every kind of tail (inside the sixteen chains of a run,
// a partial last run), the same bits for any thread count, and a non-finite sample never
// hidden. The exact sums come from integers: every sample is a whole multiple k of 2⁻³⁰ with
// |k| < 2⁵⁶, so the sum of up to 10⁵ of them is an exact int64 times 2⁻³⁰, and converting
// that int64 to double is the correctly rounded sum.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <vector>

#include "fixed_threads.hpp"
#include "processing/allan/allan_kernels.hpp"
#include "processing/base/parallel_share.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kScale = 0x1p-30;

struct ScaledSeries {
  std::vector<double> samples;
  std::int64_t exact_units = 0;  // Σ k_i: the exact sum is exact_units·2⁻³⁰
};

// A bias of `bias_units` with noise of ±noise_units, and every 97th sample a spike of
// ±2⁵⁴ units that the next sample takes back: beside a spike a double's last bit is 4 units,
// so a naive sum loses the noise's low bits there.
ScaledSeries scaledSeries(std::size_t n, std::int64_t bias_units, std::int64_t noise_units, std::uint64_t seed) {
  std::mt19937_64 gen(seed);
  std::uniform_int_distribution<std::int64_t> noise(-noise_units, noise_units);
  ScaledSeries s;
  s.samples.resize(n);
  std::int64_t pending_spike = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t k = bias_units + noise(gen);
    if (pending_spike != 0) {
      k -= pending_spike;
      pending_spike = 0;
    } else if (i % 97 == 96) {
      pending_spike = (gen() & 1U) != 0 ? (std::int64_t{1} << 54) : -(std::int64_t{1} << 54);
      k += pending_spike;
    }
    // k rounded to a double (a spike's sample keeps 53 bits), then scaled exactly; the exact
    // sum counts the sample as stored.
    s.samples[i] = static_cast<double>(k) * kScale;
    s.exact_units += static_cast<std::int64_t>(s.samples[i] / kScale);
  }
  return s;
}

double sampleSum(const double* rate, std::size_t count) {
  return allan_kernels::totalOfRuns(allan_kernels::sumRuns(rate, count));
}

}  // namespace

TEST(SumInRuns, IsTheExactSumRoundedOnceForEveryKindOfTail) {
  const std::size_t run = allan_kernels::kPhaseRun;
  // Inside the first chain step, inside a run, a whole run, runs with a partial last one.
  for (std::size_t n : {std::size_t{1}, std::size_t{15}, std::size_t{17}, std::size_t{1000}, run, run + 1, 3 * run + 37,
                        7 * run + 16, std::size_t{100000}}) {
    const ScaledSeries s = scaledSeries(n, 1'000'000'007, 50'000'000, 20261126 + n);
    const double expected = static_cast<double>(s.exact_units) * kScale;
    EXPECT_EQ(sampleSum(s.samples.data(), n), expected) << n << " samples";
  }
}

TEST(SumInRuns, KeepsTheNoiseThatANaiveSumLosesBesideSpikes) {
  const ScaledSeries s = scaledSeries(50'000, 3, 1'000, 7);
  const double expected = static_cast<double>(s.exact_units) * kScale;
  double naive = 0.0;
  for (double v : s.samples) naive += v;
  ASSERT_NE(naive, expected);  // the series is hard for a plain sum
  EXPECT_EQ(sampleSum(s.samples.data(), s.samples.size()), expected);
}

TEST(SumInRuns, IsTheSameBitsForAnyThreadCount) {
  const ScaledSeries s = scaledSeries(9 * allan_kernels::kPhaseRun + 5, -400'000'000, 30'000'000, 11);
  double one = 0.0;
  {
    const FixedThreads threads(1);
    one = sampleSum(s.samples.data(), s.samples.size());
  }
  for (std::size_t t : {2U, 3U, 5U}) {
    const FixedThreads threads(t);
    EXPECT_EQ(sampleSum(s.samples.data(), s.samples.size()), one) << t << " threads";
  }
}

TEST(SumInRuns, ANonFiniteSampleMakesTheSumNonFinite) {
  ScaledSeries s = scaledSeries(2 * allan_kernels::kPhaseRun + 3, 5, 5, 3);
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                     -std::numeric_limits<double>::infinity()}) {
    for (std::size_t at : {std::size_t{0}, std::size_t{4}, allan_kernels::kPhaseRun + 9, s.samples.size() - 1}) {
      std::vector<double> samples = s.samples;
      samples[at] = bad;
      EXPECT_FALSE(std::isfinite(sampleSum(samples.data(), samples.size()))) << "sample " << at << " = " << bad;
    }
  }
}

namespace {

struct Phase {
  std::vector<double> hi;
  std::vector<float> lo;
};

Phase integrated(const std::vector<double>& rate, double mean, std::span<const allan_kernels::RunSum> sums) {
  Phase p{std::vector<double>(rate.size() + 1), std::vector<float>(rate.size() + 1)};
  allan_kernels::integratePhase(rate.data(), rate.size(), mean, sums, p.hi.data(), p.lo.data());
  return p;
}

std::vector<double> biasAndNoise(std::size_t n, double bias, double sigma, std::uint64_t seed) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<double> rate(n);
  for (double& v : rate) v = bias + noise(gen);
  return rate;
}

}  // namespace

// Where every sample lies within a factor 2 of the mean (a gyro whose bias outweighs its
// noise), rate[i] − mean is exact and a run's total is its sum less kPhaseRun·mean: the phase
// is the one pass 1 gives (a difference of ~ε² of the phase could move a last bit; none does
// here). That the sums are read is shown by corrupting one: the phase after it moves.
TEST(PhaseFromRunSums, AGyroBiasAboveItsNoiseTakesTheRunTotalsFromTheSums) {
  const std::size_t run = allan_kernels::kPhaseRun;
  const std::vector<double> rate = biasAndNoise(6 * run + 100, 1.367, 0.05, 5);
  const std::vector<allan_kernels::RunSum> sums = allan_kernels::sumRuns(rate.data(), rate.size());
  const double mean = allan_kernels::totalOfRuns(sums) / static_cast<double>(rate.size());
  const Phase from_sums = integrated(rate, mean, sums);
  const Phase from_pass = integrated(rate, mean, {});
  EXPECT_EQ(from_sums.hi, from_pass.hi);
  EXPECT_EQ(from_sums.lo, from_pass.lo);

  std::vector<allan_kernels::RunSum> corrupted = sums;
  corrupted[2].hi += 1.0;
  const Phase moved = integrated(rate, mean, corrupted);
  EXPECT_EQ(moved.hi[3 * run], from_pass.hi[3 * run]);  // the last point of run 2, from its own start
  EXPECT_NEAR(moved.hi[3 * run + 1] - from_pass.hi[3 * run + 1], 1.0, 1e-9);  // run 3 starts 1 higher
}

// A mean near zero puts samples on both sides of it: rate[i] − mean rounds, so every run's total
// comes from pass 1 and the sums are not read.
TEST(PhaseFromRunSums, SamplesFarFromTheMeanAreIntegratedAgain) {
  const std::size_t run = allan_kernels::kPhaseRun;
  const std::vector<double> rate = biasAndNoise(5 * run + 7, 0.01, 0.05, 6);
  std::vector<allan_kernels::RunSum> sums = allan_kernels::sumRuns(rate.data(), rate.size());
  const double mean = allan_kernels::totalOfRuns(sums) / static_cast<double>(rate.size());
  const Phase from_pass = integrated(rate, mean, {});
  for (auto& s : sums) s.hi += 1.0;
  const Phase ignored = integrated(rate, mean, sums);
  EXPECT_EQ(ignored.hi, from_pass.hi);
  EXPECT_EQ(ignored.lo, from_pass.lo);
}
