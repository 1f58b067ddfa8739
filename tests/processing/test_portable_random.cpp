// The simulator's portable building blocks: splitmix64 and xoshiro256** against the
// authors' published outputs, the normal generators' distributions (polar method and
// ziggurat, against Φ and the truncated-normal tail), and the elementary
// functions against libm (which is accurate to about an ulp on the build machine).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "processing/base/distributions.hpp"
#include "processing/base/portable_math.hpp"
#include "processing/base/portable_random.hpp"

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

namespace {

// n = 400 000 draws: sample mean SE 1/√n, variance SE √(2/n), P(Z ≤ z) SE √(p(1−p)/n);
// each checked at 5 SE (independent truth: Φ from Boost via distributions.hpp).
template <class Generator>
void expectMomentsAndCdfOfStandardNormal() {
  const int n = 400000;
  const double points[] = {-2.5, -1.0, -0.3, 0.0, 0.7, 1.5, 3.0};
  for (std::uint64_t seed : {1ULL, 2ULL, 99ULL}) {
    Generator g(seed);
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

}  // namespace

TEST(NormalGenerator, MomentsAndCdfOfStandardNormal) { expectMomentsAndCdfOfStandardNormal<NormalGenerator>(); }

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

// ---- the ziggurat -----------------------------------------------------------------------

TEST(ZigguratNormalGenerator, TablesAreMarsagliaTsangs256Layers) {
  const NormalZigguratLayers& z = normalZigguratLayers();
  const int n = NormalZigguratLayers::kLayers;
  // Marsaglia & Tsang (2000), 256 layers: r = 3.6541528853610088, v = 4.92867323399e-3
  // (for f = e^{−x²/2}); the bisection lands on the same double. Their v is given to 12
  // digits and its last differs by 2 from r·f(r) + tail at that r (4.9286732339747e-3).
  EXPECT_EQ(z.r, 3.6541528853610088);
  EXPECT_NEAR(z.v, 4.92867323399e-3, 3e-14);
  // v is the base layer's area r·f(r) + ∫_r^∞ f = r·f(r) + √(π/2)·erfc(r/√2) (libm).
  const double tail = std::sqrt(std::numbers::pi / 2.0) * std::erfc(z.r / std::numbers::sqrt2);
  EXPECT_NEAR(z.v / (z.r * std::exp(-0.5 * z.r * z.r) + tail), 1.0, 1e-14);
  EXPECT_NEAR(z.x[0], z.v / std::exp(-0.5 * z.r * z.r), 1e-14 * z.x[0]);
  EXPECT_EQ(z.x[1], z.r);
  EXPECT_EQ(z.x[n], 0.0);
  EXPECT_EQ(z.f[n], 1.0);
  for (int i = 1; i < n; ++i) {
    ASSERT_LT(z.x[i + 1], z.x[i]) << i;
    // f[i] = e^{−x[i]²/2} and every layer's rectangle x[i]·(f[i+1] − f[i]) has area v;
    // the top one too, which is what fixes r.
    EXPECT_NEAR(z.f[i], std::exp(-0.5 * z.x[i] * z.x[i]), 1e-14) << i;
    EXPECT_NEAR(z.x[i] * (z.f[i + 1] - z.f[i]) / z.v, 1.0, 1e-12) << i;
  }
}

// The ziggurat as Marsaglia & Tsang wrote it, every wedge point against the density itself:
// the generator's squeezes must decide every point as this does (same deviates, bit for bit).
class UnsqueezedZiggurat {
 public:
  explicit UnsqueezedZiggurat(std::uint64_t seed) : uniform_(seed) {}
  double next() {
    const NormalZigguratLayers& z = normalZigguratLayers();
    std::uint64_t u = uniform_.next();
    for (;;) {
      const std::size_t i = u & 0xFF;
      const bool negative = (u & 0x100) != 0;
      const double x = static_cast<double>(u >> 11) * 0x1.0p-53 * z.x[i];
      if (x < z.x[i + 1]) return negative ? -x : x;
      if (i == 0) {
        double a = 0.0, b = 0.0;
        do {
          a = -portable::log(1.0 - uniform_.uniform()) / z.r;
          b = -portable::log(1.0 - uniform_.uniform());
        } while (!(b + b > a * a));
        return negative ? -(z.r + a) : z.r + a;
      }
      const double y = z.f[i] + uniform_.uniform() * (z.f[i + 1] - z.f[i]);
      if (y < portable::exp(-0.5 * x * x)) return negative ? -x : x;
      u = uniform_.next();
    }
  }

 private:
  Xoshiro256StarStar uniform_;
};

TEST(ZigguratNormalGenerator, SqueezedWedgesDecideAsTheDensity) {
  for (std::uint64_t seed : {11ULL, 12ULL}) {
    ZigguratNormalGenerator g(seed);
    UnsqueezedZiggurat reference(seed);
    for (int k = 0; k < 5000000; ++k) {
      const double want = reference.next();
      const double got = g.next();
      ASSERT_EQ(std::bit_cast<std::uint64_t>(got), std::bit_cast<std::uint64_t>(want))
          << "seed " << seed << ", deviate " << k;
    }
  }
}

TEST(ZigguratNormalGenerator, MomentsAndCdfOfStandardNormal) {
  expectMomentsAndCdfOfStandardNormal<ZigguratNormalGenerator>();
}

TEST(ZigguratNormalGenerator, ChiSquareOverLayerAndEquiprobableBins) {
  // Two binnings, n = 1 000 000 draws each, three seeds; χ² against its quantile at
  // 1 − 1e-6 (a false alarm once in a million runs):
  //  (a) |z| in the ziggurat's own layers (x[i+1], x[i]] and the tail (r, ∞) — the places
  //      a wrong table or a wrong wedge test would show — with P = 2(Φ(x[i]) − Φ(x[i+1]));
  //  (b) z in 100 bins of probability 1/100 each, edges Φ⁻¹(k/100) (both signs).
  const NormalZigguratLayers& z = normalZigguratLayers();
  const int layers = NormalZigguratLayers::kLayers;
  const int n = 1000000;
  std::vector<double> eq_edges;
  for (int k = 1; k < 100; ++k) eq_edges.push_back(normalQuantile(k / 100.0));
  for (std::uint64_t seed : {3ULL, 4ULL, 5ULL}) {
    ZigguratNormalGenerator g(seed);
    std::vector<int> layer_count(layers, 0), eq_count(100, 0);  // layer bin 0: the tail
    for (int k = 0; k < n; ++k) {
      const double v = g.next();
      const double a = std::fabs(v);
      // bin i ≥ 1 holds (x[i+1], x[i]]; x is decreasing, so find the first x[j] < a.
      const auto first_below = std::upper_bound(z.x.begin() + 1, z.x.end(), a, std::greater<double>());
      int bin = static_cast<int>(first_below - z.x.begin()) - 1;  // x[bin+1] < a ≤ x[bin]
      if (a > z.r) bin = 0;
      if (a == 0.0) bin = layers - 1;
      ++layer_count[static_cast<std::size_t>(bin)];
      ++eq_count[static_cast<std::size_t>(std::upper_bound(eq_edges.begin(), eq_edges.end(), v) - eq_edges.begin())];
    }
    double chi2_layers = 0.0;
    for (int i = 0; i < layers; ++i) {
      const double p = i == 0 ? 2.0 * (1.0 - normalCdf(z.r)) : 2.0 * (normalCdf(z.x[i]) - normalCdf(z.x[i + 1]));
      const double expected = p * n;
      chi2_layers += (layer_count[i] - expected) * (layer_count[i] - expected) / expected;
    }
    double chi2_eq = 0.0;
    for (int c : eq_count) chi2_eq += (c - n / 100.0) * (c - n / 100.0) / (n / 100.0);
    EXPECT_LT(chi2_layers, chiSquareQuantile(1.0 - 1e-6, layers - 1)) << "seed " << seed;
    EXPECT_LT(chi2_eq, chiSquareQuantile(1.0 - 1e-6, 99)) << "seed " << seed;
  }
}

TEST(ZigguratNormalGenerator, TailBeyondRHasTheTruncatedNormalShape) {
  // The tail (|z| > r, about 1 draw in 3900) comes from a separate sampler. n = 4 000 000
  // per seed: P(|Z| > r) and P(|Z| > 4.5) at 5 binomial SE, and given |Z| > r the mean of
  // |Z| − r at 5 SE: for a normal truncated at r, with λ = φ(r)/Q(r), E = λ − r and
  // Var = 1 + r·λ − λ².
  const double r = normalZigguratLayers().r;
  const int n = 4000000;
  const double q_r = 1.0 - normalCdf(r), q_45 = 1.0 - normalCdf(4.5);
  const double lambda = std::exp(-0.5 * r * r) / std::sqrt(2.0 * std::numbers::pi) / q_r;
  const double mean_excess = lambda - r, var_excess = 1.0 + r * lambda - lambda * lambda;
  for (std::uint64_t seed : {6ULL, 7ULL, 8ULL}) {
    ZigguratNormalGenerator g(seed);
    int beyond_r = 0, beyond_45 = 0;
    double sum_excess = 0.0;
    for (int k = 0; k < n; ++k) {
      const double a = std::fabs(g.next());
      if (a > r) {
        ++beyond_r;
        sum_excess += a - r;
      }
      beyond_45 += a > 4.5;
    }
    EXPECT_NEAR(beyond_r, n * 2.0 * q_r, 5.0 * std::sqrt(n * 2.0 * q_r)) << "seed " << seed;
    EXPECT_NEAR(beyond_45, n * 2.0 * q_45, 5.0 * std::sqrt(n * 2.0 * q_45)) << "seed " << seed;
    ASSERT_GT(beyond_r, 0);
    EXPECT_NEAR(sum_excess / beyond_r, mean_excess, 5.0 * std::sqrt(var_excess / beyond_r)) << "seed " << seed;
  }
}

TEST(ZigguratNormalGenerator, ConsecutiveDrawsAndTheirSizesUncorrelated) {
  // One word gives layer, sign and U: z_k·z_{k+1} and |z_k|·|z_{k+1}| must be
  // uncorrelated (lag-1 correlation SE 1/√n, 5 SE).
  ZigguratNormalGenerator g(9);
  const int n = 400000;
  const double mean_abs = std::sqrt(2.0 / std::numbers::pi), var_abs = 1.0 - 2.0 / std::numbers::pi;
  double prev = g.next(), sum = 0.0, sum_abs = 0.0;
  for (int i = 0; i < n; ++i) {
    const double z = g.next();
    sum += prev * z;
    sum_abs += (std::fabs(prev) - mean_abs) * (std::fabs(z) - mean_abs) / var_abs;
    prev = z;
  }
  EXPECT_NEAR(sum / n, 0.0, 5.0 / std::sqrt(n));
  EXPECT_NEAR(sum_abs / n, 0.0, 5.0 / std::sqrt(n));
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
    const double x =
        i % 2 ? g.uniform() + 0x1.0p-60 : std::ldexp(1.0 + g.uniform(), static_cast<int>(g.next() % 2000) - 1000);
    worst = std::max(worst, ulpDistance(portable::log(x), std::log(x)));
  }
  EXPECT_LE(worst, 2.0);
  EXPECT_EQ(portable::log(1.0), 0.0);
  EXPECT_NEAR(portable::log(std::numeric_limits<double>::denorm_min()),
              std::log(std::numeric_limits<double>::denorm_min()), 1e-12);
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
