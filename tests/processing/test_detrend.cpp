// Constant and least-squares linear trend removal against exact lines and the plain
// (uncentred) normal equations solved in the test.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <span>
#include <stdexcept>
#include <vector>

#include "processing/base/detrend.hpp"

using namespace gyrod::processing;

TEST(Detrend, ExactOnAPureLine) {
  const double dt = 0.02;
  std::vector<double> x(1001);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 1.367 - 0.003 * (static_cast<double>(i) * dt);
  const LinearTrend t = fitLinearTrend(x, dt);
  EXPECT_NEAR(t.offset, 1.367, 1e-12);
  EXPECT_NEAR(t.slope_per_s, -0.003, 1e-12);
  const LinearTrend removed = removeLinearTrend(x, dt);
  EXPECT_NEAR(removed.offset, 1.367, 1e-12);
  for (double v : x) EXPECT_NEAR(v, 0.0, 1e-12);
}

TEST(Detrend, MatchesPlainNormalEquationsOnRandomData) {
  // Solve [n Σt; Σt Σt²][b0; b1] = [Σx; Σt·x] by Cramer's rule in long double.
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, 0.3);
  const double dt = 0.05;
  std::vector<double> x(5000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 2.0 + 0.01 * static_cast<double>(i) * dt + noise(rng);
  long double n = 0, st = 0, stt = 0, sx = 0, stx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const long double t = static_cast<long double>(i) * dt;
    n += 1;
    st += t;
    stt += t * t;
    sx += x[i];
    stx += t * x[i];
  }
  const long double det = n * stt - st * st;
  const double b0 = static_cast<double>((sx * stt - st * stx) / det);
  const double b1 = static_cast<double>((n * stx - st * sx) / det);
  const LinearTrend t = fitLinearTrend(x, dt);
  EXPECT_NEAR(t.offset, b0, 1e-10);
  EXPECT_NEAR(t.slope_per_s, b1, 1e-12);

  // The residual of a least-squares line is orthogonal to 1 and to t.
  std::vector<double> r = x;
  removeLinearTrend(r, dt);
  double s0 = 0, s1 = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    s0 += r[i];
    s1 += r[i] * static_cast<double>(i) * dt;
  }
  EXPECT_NEAR(s0, 0.0, 1e-9);
  EXPECT_NEAR(s1, 0.0, 1e-6);
}

TEST(Detrend, LargeOffsetDoesNotCostPrecision) {
  // The centred form keeps the slope exact with an offset 10⁶ times the slope's effect.
  const double dt = 0.02;
  std::vector<double> x(180000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 1e4 + 1e-6 * static_cast<double>(i) * dt;
  EXPECT_NEAR(fitLinearTrend(x, dt).slope_per_s, 1e-6, 1e-12);
}

TEST(Detrend, RemoveConstant) {
  std::vector<double> x{1.0, 2.0, 6.0};
  EXPECT_DOUBLE_EQ(removeConstant(x), 3.0);
  EXPECT_EQ(x, (std::vector<double>{-2.0, -1.0, 3.0}));
}

TEST(Detrend, RejectsBadInput) {
  std::vector<double> one{1.0};
  std::vector<double> two{1.0, 2.0};
  EXPECT_THROW(fitLinearTrend(one, 0.02), std::invalid_argument);
  EXPECT_THROW(fitLinearTrend(two, 0.0), std::invalid_argument);
  EXPECT_THROW(fitLinearTrend(two, -1.0), std::invalid_argument);
  EXPECT_THROW(fitLinearTrend(two, NAN), std::invalid_argument);
  EXPECT_THROW(removeLinearTrend(one, 0.02), std::invalid_argument);
  EXPECT_THROW(removeConstant(std::span<double>{}), std::invalid_argument);
}

// The analysis fits the trend beside the tests and subtracts it in shares on the cores: any
// cut of the series must give removeLinearTrend's bits.
TEST(Detrend, SubtractingAFittedTrendInSharesIsRemoveLinearTrendBitForBit) {
  std::mt19937 gen(17);
  std::normal_distribution<double> noise(0.0, 0.3);
  std::vector<double> x(10007);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 1.7 + 0.002 * static_cast<double>(i) + noise(gen);
  std::vector<double> whole = x;
  const LinearTrend removed = removeLinearTrend(whole, 0.02);
  const LinearTrend fitted = fitLinearTrend(x, 0.02);
  EXPECT_EQ(fitted.offset, removed.offset);
  EXPECT_EQ(fitted.slope_per_s, removed.slope_per_s);
  for (std::size_t cut : {std::size_t{1}, std::size_t{4096}, x.size() / 2, x.size() - 1}) {
    std::vector<double> shares = x;
    subtractLinearTrend(std::span(shares).first(cut), fitted, 0.02, 0);
    subtractLinearTrend(std::span(shares).subspan(cut), fitted, 0.02, cut);
    for (std::size_t i = 0; i < x.size(); ++i) ASSERT_EQ(shares[i], whole[i]) << "cut " << cut << ", sample " << i;
  }
}
