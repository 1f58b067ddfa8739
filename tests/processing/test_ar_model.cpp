// Yule–Walker / Levinson–Durbin against simulated AR processes (tolerances from the
// asymptotic standard errors) and against a direct Eigen solve of the Yule–Walker system.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "processing/paper/ar_model.hpp"

using namespace gyrod::processing;

namespace {

// x_k = Σ φj x_{k−j} + a_k with a 2000-sample burn-in from zero (|root| ≤ 0.95 forgets the
// start to 0.95^2000 ≈ 1e-45).
std::vector<double> simulateAr(const std::vector<double>& phi, double sigma_a, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> a(0.0, sigma_a);
  const std::size_t burn = 2000;
  std::vector<double> x(n + burn, 0.0);
  for (std::size_t k = 0; k < x.size(); ++k) {
    double v = a(rng);
    for (std::size_t j = 1; j <= phi.size() && j <= k; ++j) v += phi[j - 1] * x[k - j];
    x[k] = v;
  }
  return {x.begin() + static_cast<std::ptrdiff_t>(burn), x.end()};
}

// Biased autocovariance written plainly.
double plainAutocovariance(const std::vector<double>& x, std::size_t lag) {
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double s = 0.0;
  for (std::size_t i = lag; i < x.size(); ++i) s += (x[i] - mean) * (x[i - lag] - mean);
  return s / static_cast<double>(x.size());
}

}  // namespace

TEST(Autocovariance, MatchesPlainSumsAndHandExample) {
  // x = 1, 2, 3, 4: mean 2.5, deviations −1.5 −0.5 0.5 1.5;
  // γ0 = 5/4, γ1 = (0.75 − 0.25 + 0.75)/4 = 0.3125, γ3 = −2.25/4.
  const std::vector<double> g = autocovariance(std::vector<double>{1, 2, 3, 4}, 3);
  ASSERT_EQ(g.size(), 4u);
  EXPECT_DOUBLE_EQ(g[0], 1.25);
  EXPECT_DOUBLE_EQ(g[1], 0.3125);
  EXPECT_DOUBLE_EQ(g[3], -0.5625);
  const std::vector<double> x = simulateAr({0.5}, 1.0, 1000, 3);
  const std::vector<double> gx = autocovariance(x, 10);
  for (std::size_t k = 0; k <= 10; ++k) EXPECT_NEAR(gx[k], plainAutocovariance(x, k), 1e-12);
}

TEST(YuleWalker, RecoversAr1WithinFourStandardErrors) {
  const std::size_t n = 20000;
  for (double phi : {-0.2855, 0.5, 0.95}) {
    for (std::uint64_t seed : {11u, 12u, 13u}) {
      const std::vector<double> x = simulateAr({phi}, 0.24, n, seed);
      const ArModel m = yuleWalker(x, 1)[0];
      const double se = std::sqrt((1.0 - phi * phi) / static_cast<double>(n));
      EXPECT_NEAR(m.phi[0], phi, 4.0 * se) << "phi=" << phi << " seed=" << seed;
      // Reported se is the AR(1) closed form at the estimate.
      EXPECT_NEAR(m.phi_std_error[0], std::sqrt((1.0 - m.phi[0] * m.phi[0]) / static_cast<double>(n)), 1e-12);
      // σa² = γ0(1 − φ̂²); its relative sampling sd is about √(2/N) = 1 %.
      EXPECT_NEAR(m.noise_var, 0.24 * 0.24, 4.0 * std::sqrt(2.0 / static_cast<double>(n)) * 0.24 * 0.24);
      EXPECT_NEAR(m.aic, static_cast<double>(n) * std::log(m.noise_var) + 2.0, 1e-9);
      EXPECT_NEAR(m.bic, static_cast<double>(n) * std::log(m.noise_var) + std::log(static_cast<double>(n)), 1e-9);
    }
  }
}

TEST(YuleWalker, RecoversAr2) {
  // AR(2) φ = (0.6, −0.3): standard errors √(diag(σa²Γ2⁻¹)/N) = √((1 − φ2²)/N) for both.
  const std::size_t n = 20000;
  const double se = std::sqrt((1.0 - 0.09) / static_cast<double>(n));
  for (std::uint64_t seed : {21u, 22u, 23u}) {
    const std::vector<double> x = simulateAr({0.6, -0.3}, 1.0, n, seed);
    const ArModel m = yuleWalker(x, 2)[1];
    ASSERT_EQ(m.order(), 2u);
    EXPECT_NEAR(m.phi[0], 0.6, 4.0 * se);
    EXPECT_NEAR(m.phi[1], -0.3, 4.0 * se);
    EXPECT_NEAR(m.phi_std_error[0], se, 0.05 * se);
    EXPECT_NEAR(m.phi_std_error[1], se, 0.05 * se);
    EXPECT_NEAR(m.reflection, m.phi[1], 1e-15);  // κp = φp^(p)
  }
}

TEST(YuleWalker, LevinsonDurbinEqualsDirectSolve) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> d(0.0, 1.0);
  std::vector<double> x(500);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = d(rng) + 0.7 * (i ? x[i - 1] : 0.0);  // any data will do
  const std::size_t pmax = 6;
  const std::vector<ArModel> models = yuleWalker(x, pmax);
  ASSERT_EQ(models.size(), pmax);
  for (std::size_t p = 1; p <= pmax; ++p) {
    const auto pp = static_cast<Eigen::Index>(p);
    Eigen::MatrixXd gamma(pp, pp);
    Eigen::VectorXd rhs(pp);
    for (Eigen::Index i = 0; i < pp; ++i) {
      rhs(i) = plainAutocovariance(x, static_cast<std::size_t>(i + 1));
      for (Eigen::Index j = 0; j < pp; ++j)
        gamma(i, j) = plainAutocovariance(x, static_cast<std::size_t>(std::abs(i - j)));
    }
    const Eigen::VectorXd phi = gamma.fullPivLu().solve(rhs);
    const double sigma2 = plainAutocovariance(x, 0) - phi.dot(rhs);
    const Eigen::MatrixXd inv = gamma.inverse();
    const ArModel& m = models[p - 1];
    ASSERT_EQ(m.order(), p);
    for (Eigen::Index j = 0; j < pp; ++j) {
      EXPECT_NEAR(m.phi[static_cast<std::size_t>(j)], phi(j), 1e-12) << "p=" << p;
      EXPECT_NEAR(m.phi_std_error[static_cast<std::size_t>(j)], std::sqrt(sigma2 * inv(j, j) / 500.0), 1e-12);
    }
    EXPECT_NEAR(m.noise_var, sigma2, 1e-12) << "p=" << p;
  }
}

TEST(YuleWalker, InformationCriteriaPickTwoOnAr2Data) {
  // Extra orders beyond the true 2 lower N·ln σa² by ≈ χ²(1) each: AIC (penalty 2) overfits
  // with probability ≈ 16 % per order, BIC (penalty ln N ≈ 9.9) with ≈ 0.2 %. Underfitting is
  // impossible here: dropping φ2 = −0.3 raises N·ln σa² by ≈ N·0.09 ≈ 1800.
  int aic_two = 0;
  for (std::uint64_t seed = 31; seed <= 40; ++seed) {
    const std::vector<ArModel> models = yuleWalker(simulateAr({0.6, -0.3}, 1.0, 20000, seed), 3);
    const std::size_t aic = orderByAic(models);
    EXPECT_GE(aic, 2u);
    aic_two += aic == 2 ? 1 : 0;
    EXPECT_EQ(orderByBic(models), 2u) << "seed=" << seed;
  }
  EXPECT_GE(aic_two, 6);
}

TEST(YuleWalker, OrderSelectionPicksTheMinimum) {
  std::vector<ArModel> models(3);
  for (std::size_t i = 0; i < 3; ++i) models[i].phi.assign(i + 1, 0.0);
  models[0].aic = -10266.99;  // the paper's Table 3
  models[1].aic = -10271.24;
  models[2].aic = -10345.03;
  models[0].bic = -5.0;
  models[1].bic = -7.0;
  models[2].bic = -6.0;
  EXPECT_EQ(orderByAic(models), 3u);
  EXPECT_EQ(orderByBic(models), 2u);
  EXPECT_THROW(orderByAic(std::span<const ArModel>{}), std::invalid_argument);
  EXPECT_THROW(orderByBic(std::span<const ArModel>{}), std::invalid_argument);
}

TEST(YuleWalker, RejectsInvalidInput) {
  const std::vector<double> x{1.0, -1.0, 2.0};
  EXPECT_THROW(yuleWalker(x, 0), std::invalid_argument);
  EXPECT_THROW(yuleWalker(x, 3), std::invalid_argument);
  EXPECT_NO_THROW(yuleWalker(x, 2));
  EXPECT_THROW(yuleWalker(std::vector<double>(10, 4.0), 1), std::invalid_argument);  // zero variance
  EXPECT_THROW(yuleWalker(std::vector<double>{1.0, NAN, 2.0, 0.0}, 1), std::invalid_argument);
  EXPECT_THROW(autocovariance(x, 3), std::invalid_argument);
  EXPECT_THROW(autocovariance(std::vector<double>{}, 0), std::invalid_argument);
}
