// The overlapping Allan variance at every octave τ of a long random walk against a
// double-double reference written here: the phase, the mean and the second differences in
// double-double (Knuth's TwoSum), the squares summed in double-double. A rate random walk is
// the hard case: its phase grows like M^1.5, so a plain double phase would lose ~10⁻⁶ of
// each second difference. The multi-τ sweep (blocked, threaded) must agree to 1e-12.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

#include "processing/allan/allan.hpp"

using namespace gyrod::processing;

namespace {

struct DoubleDouble {
  double hi = 0.0;
  double lo = 0.0;
};

// Exact sum a + b = s + e.
DoubleDouble twoSum(double a, double b) {
  const double s = a + b;
  const double bv = s - a;
  return {s, (a - (s - bv)) + (b - bv)};
}

DoubleDouble add(DoubleDouble a, DoubleDouble b) {
  const DoubleDouble s = twoSum(a.hi, b.hi);
  const double lo = s.lo + (a.lo + b.lo);
  const DoubleDouble r = twoSum(s.hi, lo);
  return r;
}

DoubleDouble negate(DoubleDouble a) { return {-a.hi, -a.lo}; }

std::vector<double> randomWalk(std::size_t count, std::uint64_t seed) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> step(0.0, 1e-3);
  std::vector<double> y(count);
  double level = 0.3;
  for (double& v : y) {
    level += step(gen);
    v = level;
  }
  return y;
}

// σ²(m) = Σ (x_{i+2m} − 2x_{i+m} + x_i)² / (2 m² (M − 2m + 1)), everything double-double
// but the square of each difference (its rounding, 2⁻⁵³ relative, is far below the bar).
std::vector<double> referenceVariances(const std::vector<double>& rate, const std::vector<std::size_t>& ms) {
  DoubleDouble sum;
  for (double v : rate) sum = add(sum, {v, 0.0});
  // sum / M in double-double: the quotient's remainder gives the low part.
  const double count = static_cast<double>(rate.size());
  const double q = sum.hi / count;
  const DoubleDouble mean = {q, (sum.hi - q * count + sum.lo) / count};  // q·count is exact enough here
  std::vector<DoubleDouble> phase(rate.size() + 1);
  for (std::size_t i = 0; i < rate.size(); ++i) phase[i + 1] = add(phase[i], add({rate[i], 0.0}, negate(mean)));
  std::vector<double> out;
  for (std::size_t m : ms) {
    DoubleDouble total;
    const std::size_t terms = rate.size() - 2 * m + 1;
    for (std::size_t i = 0; i < terms; ++i) {
      const DoubleDouble d =
          add(add(phase[i + 2 * m], negate(phase[i + m])), negate(add(phase[i + m], negate(phase[i]))));
      const double d2 = (d.hi + d.lo) * (d.hi + d.lo);
      total = add(total, {d2, 0.0});
    }
    const double md = static_cast<double>(m);
    out.push_back((total.hi + total.lo) / (2.0 * md * md * static_cast<double>(terms)));
  }
  return out;
}

TEST(AllanReference, TenMillionRandomWalkSamplesAgreeWithDoubleDoubleAtEveryOctave) {
  const std::vector<double> rate = randomWalk(10'000'000, 20261123);
  const std::vector<std::size_t> ms = octaveClusterSizes(rate.size());
  ASSERT_EQ(ms.size(), 23u);
  const std::vector<double> got = overlappingAllanVariances(rate, ms);
  const std::vector<double> want = referenceVariances(rate, ms);
  for (std::size_t j = 0; j < ms.size(); ++j) {
    ASSERT_GT(want[j], 0.0);
    EXPECT_NEAR(got[j] / want[j], 1.0, 1e-12) << "m = " << ms[j];
  }
  // The table uses the same sweep.
  const std::vector<AllanPoint> table = allanDeviationTable(rate, 0.02, ms);
  for (std::size_t j = 0; j < ms.size(); ++j)
    EXPECT_NEAR(table[j].oadev * table[j].oadev / want[j], 1.0, 1e-12) << "m = " << ms[j];
}

// White rate noise on a bias, like a still gyro (the bench's series): the phase stays small
// against the long-m differences, so the sweep leaves the lo parts out of most long-m blocks
// (allowed only where they cannot move a block's total by 1e-13). It must still agree with
// the double-double reference, and with the one-m-at-a-time sum (which always adds lo).
TEST(AllanReference, WhiteNoiseOnABiasAgreesWithDoubleDoubleAtEveryOctave) {
  std::mt19937_64 gen(20261125);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<double> rate(2'000'000);
  for (double& v : rate) v = 1.367 + noise(gen);
  const std::vector<std::size_t> ms = octaveClusterSizes(rate.size());
  const std::vector<double> got = overlappingAllanVariances(rate, ms);
  const std::vector<double> want = referenceVariances(rate, ms);
  for (std::size_t j = 0; j < ms.size(); ++j) {
    ASSERT_GT(want[j], 0.0);
    EXPECT_NEAR(got[j] / want[j], 1.0, 1e-12) << "m = " << ms[j];
    EXPECT_NEAR(got[j] / overlappingAllanVariance(rate, ms[j]), 1.0, 2e-13) << "m = " << ms[j];
  }
  // Up to m = 32 the hi-only bound is out of reach on this series (a difference of σ·√(2m)
  // against a phase of ~70), so every block adds the lo parts, which the sweep reads widened
  // to double once a block: exactly the one-m sum's bits, which converts them at each m.
  for (std::size_t j = 0; ms[j] <= 32; ++j) EXPECT_EQ(got[j], overlappingAllanVariance(rate, ms[j])) << "m = " << ms[j];
}

}  // namespace
