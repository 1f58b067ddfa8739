// The simulator's portable building blocks: splitmix64 and xoshiro256** against the
// authors' published outputs, the normal generator's distribution, and the elementary
// functions against libm (which is accurate to about an ulp on the build machine).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "processing/distributions.hpp"
#include "processing/portable_math.hpp"
#include "processing/portable_random.hpp"

using namespace gyrod::processing;

TEST(SplitMix64, PublishedOutputsForSeedZero) {
  // splitmix64.c (Vigna), state 0: the first outputs as published with xoshiro's seeding.
  SplitMix64 g(0);
  EXPECT_EQ(g.next(), 0xE220A8397B1DCDAFULL);
  EXPECT_EQ(g.next(), 0x6E789E6AA1B965F4ULL);
  EXPECT_EQ(g.next(), 0x06C45D188009454FULL);
  EXPECT_EQ(g.next(), 0xF88BB8A8724C81ECULL);
}

TEST(Xoshiro256StarStar, ReferenceOutputsFromState1234) {
  // xoshiro256starstar.c with s = {1, 2, 3, 4}: reference sequence used by its ports.
  Xoshiro256StarStar g(std::array<std::uint64_t, 4>{1, 2, 3, 4});
  const std::uint64_t expected[] = {11520ULL,
                                    0ULL,
                                    1509978240ULL,
                                    1215971899390074240ULL,
                                    1216172134540287360ULL,
                                    607988272756665600ULL,
                                    16172922978634559625ULL,
                                    8476171486693032832ULL,
                                    10595114339597558777ULL,
                                    2904607092377533576ULL};
  for (std::uint64_t e : expected) EXPECT_EQ(g.next(), e);
  EXPECT_THROW(Xoshiro256StarStar(std::array<std::uint64_t, 4>{0, 0, 0, 0}), std::invalid_argument);
}

TEST(Xoshiro256StarStar, SeedingUsesSplitMix64Outputs) {
  SplitMix64 s(0);
  const std::array<std::uint64_t, 4> state = {s.next(), s.next(), s.next(), s.next()};
  Xoshiro256StarStar a(0), b(state);
  for (int i = 0; i < 100; ++i) ASSERT_EQ(a.next(), b.next());
}

TEST(Xoshiro256StarStar, UniformIsTopBitsTimesTwoToMinus53) {
  Xoshiro256StarStar a(7), b(7);
  for (int i = 0; i < 1000; ++i) {
    const double u = a.uniform();
    ASSERT_EQ(u, std::ldexp(static_cast<double>(b.next() >> 11), -53));
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
  }
}

TEST(NormalGenerator, MomentsAndCdfOfStandardNormal) {
  // n = 400 000 draws: sample mean SE 1/√n, variance SE √(2/n), P(Z ≤ z) SE √(p(1−p)/n);
  // each checked at 5 SE (independent truth: Φ from Boost via distributions.hpp).
  const int n = 400000;
  const double points[] = {-2.5, -1.0, -0.3, 0.0, 0.7, 1.5, 3.0};
  for (std::uint64_t seed : {1ULL, 2ULL, 99ULL}) {
    NormalGenerator g(seed);
    double sum = 0.0, sum2 = 0.0, sum4 = 0.0;
    std::array<int, 7> below{};
    for (int i = 0; i < n; ++i) {
      const double z = g.next();
      sum += z;
      sum2 += z * z;
      sum4 += z * z * z * z;
      for (std::size_t k = 0; k < below.size(); ++k) below[k] += z <= points[k];
    }
    EXPECT_NEAR(sum / n, 0.0, 5.0 / std::sqrt(n)) << "seed " << seed;
    EXPECT_NEAR(sum2 / n, 1.0, 5.0 * std::sqrt(2.0 / n)) << "seed " << seed;
    EXPECT_NEAR(sum4 / n, 3.0, 5.0 * std::sqrt(96.0 / n)) << "seed " << seed;  // Var(Z⁴) = 105 − 9
    for (std::size_t k = 0; k < below.size(); ++k) {
      const double p = normalCdf(points[k]);
      EXPECT_NEAR(static_cast<double>(below[k]) / n, p, 5.0 * std::sqrt(p * (1.0 - p) / n))
          << "seed " << seed << " z " << points[k];
    }
  }
}

TEST(NormalGenerator, ConsecutiveDrawsUncorrelated) {
  // The polar method returns its pair in turn; lag-1 correlation must still be 0 (SE 1/√n).
  NormalGenerator g(5);
  const int n = 200000;
  double prev = g.next(), sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double z = g.next();
    sum += prev * z;
    prev = z;
  }
  EXPECT_NEAR(sum / n, 0.0, 5.0 / std::sqrt(n));
}

namespace {
// |a − b| in units of the spacing of doubles at b.
double ulpDistance(double a, double b) {
  return std::fabs(a - b) / (std::nextafter(std::fabs(b), std::numeric_limits<double>::infinity()) - std::fabs(b));
}
}  // namespace

TEST(PortableMath, LogWithinTwoUlpOfLibm) {
  Xoshiro256StarStar g(11);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    // log-uniform over the whole normal range, plus the polar method's range (0, 1).
    const double x = i % 2 ? g.uniform() + 0x1.0p-60 : std::ldexp(1.0 + g.uniform(), static_cast<int>(g.next() % 2000) - 1000);
    worst = std::max(worst, ulpDistance(portable::log(x), std::log(x)));
  }
  EXPECT_LE(worst, 2.0);
  EXPECT_EQ(portable::log(1.0), 0.0);
  EXPECT_NEAR(portable::log(std::numeric_limits<double>::denorm_min()), std::log(std::numeric_limits<double>::denorm_min()), 1e-12);
  EXPECT_THROW(portable::log(0.0), std::invalid_argument);
  EXPECT_THROW(portable::log(-1.0), std::invalid_argument);
  EXPECT_THROW(portable::log(std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_THROW(portable::log(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

TEST(PortableMath, ExpAndExpm1WithinTwoUlpOfLibm) {
  Xoshiro256StarStar g(12);
  double worst_exp = 0.0, worst_expm1 = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double x = 1400.0 * g.uniform() - 700.0;
    worst_exp = std::max(worst_exp, ulpDistance(portable::exp(x), std::exp(x)));
    const double y = std::ldexp(2.0 * g.uniform() - 1.0, -static_cast<int>(g.next() % 40));
    worst_expm1 = std::max(worst_expm1, ulpDistance(portable::expm1(y), std::expm1(y)));
  }
  EXPECT_LE(worst_exp, 2.0);
  EXPECT_LE(worst_expm1, 2.0);
  EXPECT_EQ(portable::exp(0.0), 1.0);
  EXPECT_EQ(portable::exp(-800.0), 0.0);
  EXPECT_EQ(portable::exp(800.0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(portable::expm1(0.0), 0.0);
  EXPECT_THROW(portable::exp(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

TEST(PortableMath, TanWithinFourUlpOfLibm) {
  Xoshiro256StarStar g(13);
  double worst = 0.0;
  for (int i = 0; i < 100000; ++i) {
    const double x = 2.4 * g.uniform() - 1.2;
    worst = std::max(worst, ulpDistance(portable::tan(x), std::tan(x)));
  }
  EXPECT_LE(worst, 4.0);  // the quotient of two series, each within about an ulp
  EXPECT_THROW(portable::tan(1.3), std::invalid_argument);
}
