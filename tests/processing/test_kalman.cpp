// Scalar and companion-form AR Kalman filters against a hand-computed sequence, the
// Riccati recursion iterated plainly, the quadratic formula, each other, and simulation.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "processing/paper/kalman.hpp"

using namespace gyrod::processing;

namespace {

// The paper's AR(1) numbers (Table 3) with its raw-data variance as R.
constexpr double kPaperA = -0.2855;
constexpr double kPaperQ = 0.0577;
constexpr double kPaperR = 0.0667;

double riccatiIteratedPlainly(double a, double q, double r) {
  double m = 0.0;  // P⁻ starting from P0 = 0
  for (int i = 0; i < 100000; ++i) m = a * a * m * r / (m + r) + q;
  return m;
}

double quadraticPositiveRoot(double a, double q, double r) {
  const double b = r * (1.0 - a * a) - q;
  return (-b + std::sqrt(b * b + 4.0 * q * r)) / 2.0;
}

struct Simulated {
  std::vector<double> state, measured;
};

// AR(p) state plus white measurement noise, 2000-sample burn-in.
Simulated simulateArPlusNoise(const std::vector<double>& phi, double q, double r, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> w(0.0, std::sqrt(q));
  std::normal_distribution<double> v(0.0, std::sqrt(r));
  const std::size_t burn = 2000;
  std::vector<double> x(n + burn, 0.0);
  for (std::size_t k = 0; k < x.size(); ++k) {
    double s = w(rng);
    for (std::size_t j = 1; j <= phi.size() && j <= k; ++j) s += phi[j - 1] * x[k - j];
    x[k] = s;
  }
  Simulated out;
  out.state.assign(x.begin() + static_cast<std::ptrdiff_t>(burn), x.end());
  for (double s : out.state) out.measured.push_back(s + v(rng));
  return out;
}

}  // namespace

// The fixed-maximum-size types hold their coefficients inline (no heap buffer), which is
// what lets ArKalmanFilter::update run without allocating.
static_assert(sizeof(ArKalmanFilter::Matrix) >= kMaxArOrder * kMaxArOrder * sizeof(double));
static_assert(sizeof(ArKalmanFilter::Vector) >= kMaxArOrder * sizeof(double));

TEST(ScalarKalmanFilter, HandComputedThreeSteps) {
  // A = 0.5, Q = 1, R = 1, P0 = 0, x̂0 = Z0. Z = 2, 4, −2:
  //  k=0: x̂ = 2, P = 0.
  //  k=1: x̂⁻ = 1, P⁻ = 1, K = 1/2, x̂ = 1 + (4 − 1)/2 = 2.5, P = 0.5.
  //  k=2: x̂⁻ = 1.25, P⁻ = 0.125 + 1 = 1.125, K = 9/17, x̂ = 1.25 − (9/17)·3.25 = −8/17,
  //       P = (8/17)·1.125 = 9/17.
  ScalarKalmanFilter f({.a = 0.5, .q = 1.0, .r = 1.0, .p0 = 0.0, .x0 = std::nullopt});
  EXPECT_DOUBLE_EQ(f.update(2.0), 2.0);
  EXPECT_EQ(f.covariance(), 0.0);
  EXPECT_EQ(f.gain(), 0.0);
  EXPECT_DOUBLE_EQ(f.update(4.0), 2.5);
  EXPECT_DOUBLE_EQ(f.gain(), 0.5);
  EXPECT_DOUBLE_EQ(f.covariance(), 0.5);
  EXPECT_DOUBLE_EQ(f.innovation(), 3.0);
  EXPECT_DOUBLE_EQ(f.update(-2.0), -8.0 / 17.0);
  EXPECT_DOUBLE_EQ(f.gain(), 9.0 / 17.0);
  EXPECT_DOUBLE_EQ(f.covariance(), 9.0 / 17.0);
  EXPECT_DOUBLE_EQ(f.innovation(), -3.25);

  // reset() replays the same sequence.
  f.reset();
  EXPECT_DOUBLE_EQ(f.update(2.0), 2.0);
  EXPECT_DOUBLE_EQ(f.update(4.0), 2.5);
}

TEST(ScalarKalmanFilter, GivenInitialStateIsPredictedFromAtOnce) {
  // x̂0 = 1, P0 = 0: x̂⁻ = 0.5, P⁻ = 1, K = 1/2, x̂ = 0.5 + (2 − 0.5)/2 = 1.25.
  ScalarKalmanFilter f({.a = 0.5, .q = 1.0, .r = 1.0, .p0 = 0.0, .x0 = 1.0});
  EXPECT_DOUBLE_EQ(f.update(2.0), 1.25);
  EXPECT_DOUBLE_EQ(f.gain(), 0.5);
}

TEST(ScalarKalmanFilter, SteadyStateMatchesIteratedRiccatiAndQuadraticFormula) {
  struct Case {
    double a, q, r;
  };
  for (const Case& c : {Case{kPaperA, kPaperQ, kPaperR}, Case{0.95, 0.01, 1.0}, Case{0.0, 2.0, 0.5},
                        Case{1.2, 0.1, 0.3}, Case{-1.0, 1e-4, 10.0}}) {
    const double m_iter = riccatiIteratedPlainly(c.a, c.q, c.r);
    const double m_quad = quadraticPositiveRoot(c.a, c.q, c.r);
    const double m = steadyStatePriorCovariance(c.a, c.q, c.r);
    EXPECT_NEAR(m, m_iter, 1e-12 * m_iter) << c.a;
    EXPECT_NEAR(m, m_quad, 1e-12 * m_quad) << c.a;
    EXPECT_NEAR(steadyStateGain(c.a, c.q, c.r), m_iter / (m_iter + c.r), 1e-12);
    EXPECT_NEAR(steadyStatePosteriorCovariance(c.a, c.q, c.r), (1.0 - m_iter / (m_iter + c.r)) * m_iter,
                1e-12 * m_iter);

    // The filter's gain converges there whatever the data (the gain ignores Z); slowest
    // for |A| = 1 with a small gain, where the error shrinks by (1 − K∞)²A² ≈ 0.994 a step.
    ScalarKalmanFilter f({.a = c.a, .q = c.q, .r = c.r, .p0 = 0.0, .x0 = std::nullopt});
    for (int k = 0; k < 20000; ++k) f.update(std::sin(0.1 * k));
    EXPECT_NEAR(f.gain(), m_iter / (m_iter + c.r), 1e-12) << c.a;
  }
  // No process noise and a stable model: the state is known exactly in the limit.
  EXPECT_EQ(steadyStatePriorCovariance(0.5, 0.0, 1.0), 0.0);
}

TEST(ScalarKalmanFilter, SteadyErrorVarianceMatchesSimulation) {
  // On data from the model itself the error x̂ − x has variance P∞ = (1 − K∞)·P⁻∞. The
  // errors are correlated over a few samples: with N = 40000 the empirical MSE has a
  // relative sd of ≈ 1 %, so 5 % is > 4 sd.
  for (double a : {kPaperA, 0.9}) {
    const double p_inf = steadyStatePosteriorCovariance(a, kPaperQ, kPaperR);
    for (std::uint64_t seed : {1u, 2u, 3u}) {
      const Simulated s = simulateArPlusNoise({a}, kPaperQ, kPaperR, 40000, seed);
      ScalarKalmanFilter f({.a = a, .q = kPaperQ, .r = kPaperR, .p0 = 0.0, .x0 = std::nullopt});
      double se = 0.0, se_raw = 0.0;
      std::size_t count = 0;
      for (std::size_t k = 0; k < s.state.size(); ++k) {
        const double est = f.update(s.measured[k]);
        if (k < 100) continue;  // let P converge
        se += (est - s.state[k]) * (est - s.state[k]);
        se_raw += (s.measured[k] - s.state[k]) * (s.measured[k] - s.state[k]);
        ++count;
      }
      const double mse = se / static_cast<double>(count);
      EXPECT_NEAR(mse, p_inf, 0.05 * p_inf) << "a=" << a << " seed=" << seed;
      EXPECT_LT(mse, se_raw / static_cast<double>(count));
    }
  }
}

TEST(ScalarKalmanFilter, RejectsInvalidParameters) {
  const auto make = [](double a, double q, double r, double p0, std::optional<double> x0 = std::nullopt) {
    return ScalarKalmanFilter({.a = a, .q = q, .r = r, .p0 = p0, .x0 = x0});
  };
  EXPECT_THROW(make(0.5, -1.0, 1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(make(0.5, 1.0, 0.0, 0.0), std::invalid_argument);
  EXPECT_THROW(make(0.5, 1.0, -1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(make(0.5, 1.0, 1.0, -1.0), std::invalid_argument);
  EXPECT_THROW(make(NAN, 1.0, 1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(make(0.5, INFINITY, 1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(make(0.5, 1.0, 1.0, 0.0, NAN), std::invalid_argument);
  EXPECT_NO_THROW(make(0.5, 0.0, 1.0, 0.0));
  ScalarKalmanFilter f = make(0.5, 1.0, 1.0, 0.0);
  EXPECT_THROW(f.update(NAN), std::invalid_argument);
  EXPECT_THROW(steadyStatePriorCovariance(0.5, -1.0, 1.0), std::invalid_argument);
  EXPECT_THROW(steadyStateGain(0.5, 1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(steadyStatePosteriorCovariance(NAN, 1.0, 1.0), std::invalid_argument);
}

// filterInPlace against update() sample by sample: the same bits for every output and the
// same state after, for parameters whose P reaches its fixed point (most), one that starts
// at it (q = 0, P0 = 0), a given x0, a series shorter than the convergence, and a series
// split in two calls (the second starts at the fixed point already).
TEST(ScalarKalmanFilter, FilterInPlaceIsUpdateSampleBySample) {
  const Simulated data = simulateArPlusNoise({kPaperA}, kPaperQ, kPaperR, 20000, 11);
  const std::vector<ScalarKalmanParameters> cases = {
      {.a = kPaperA, .q = kPaperQ, .r = kPaperR, .p0 = 0.0, .x0 = std::nullopt},
      {.a = 0.999, .q = 1e-6, .r = 0.01, .p0 = 0.0, .x0 = std::nullopt},
      {.a = 0.5, .q = 0.0, .r = 1.0, .p0 = 0.0, .x0 = std::nullopt},
      {.a = 0.9, .q = 0.02, .r = 0.05, .p0 = 3.0, .x0 = 0.25},
  };
  for (const auto& params : cases) {
    for (std::size_t n : {std::size_t{1}, std::size_t{5}, data.measured.size()}) {
      SCOPED_TRACE("a = " + std::to_string(params.a) + ", n = " + std::to_string(n));
      ScalarKalmanFilter stepped(params), batch(params), split(params);
      std::vector<double> expected(data.measured.begin(), data.measured.begin() + static_cast<std::ptrdiff_t>(n));
      for (double& v : expected) v = stepped.update(v);
      std::vector<double> got(data.measured.begin(), data.measured.begin() + static_cast<std::ptrdiff_t>(n));
      std::vector<double> halves = got;
      batch.filterInPlace(got);
      split.filterInPlace(std::span<double>(halves).first(n / 2));
      split.filterInPlace(std::span<double>(halves).subspan(n / 2));
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(got[i], expected[i]) << "sample " << i;
        ASSERT_EQ(halves[i], expected[i]) << "sample " << i << " (two calls)";
      }
      for (const ScalarKalmanFilter* f : {&batch, &split}) {
        EXPECT_EQ(f->gain(), stepped.gain());
        EXPECT_EQ(f->covariance(), stepped.covariance());
        EXPECT_EQ(f->innovation(), stepped.innovation());
        EXPECT_EQ(ScalarKalmanFilter(*f).update(0.125), ScalarKalmanFilter(stepped).update(0.125));
      }
    }
  }
}

// A non-finite sample stops filterInPlace as it stops update(): the samples before it
// filtered, the error thrown, the state that of the samples before it.
TEST(ScalarKalmanFilter, FilterInPlaceStopsAtANonFiniteSample) {
  const Simulated data = simulateArPlusNoise({kPaperA}, kPaperQ, kPaperR, 3000, 12);
  const ScalarKalmanParameters params{.a = kPaperA, .q = kPaperQ, .r = kPaperR, .p0 = 0.0, .x0 = std::nullopt};
  for (std::size_t bad : {std::size_t{2}, std::size_t{2500}}) {
    std::vector<double> z = data.measured;
    z[bad] = NAN;
    ScalarKalmanFilter stepped(params), batch(params);
    std::vector<double> expected(z.begin(), z.begin() + static_cast<std::ptrdiff_t>(bad));
    for (double& v : expected) v = stepped.update(v);
    EXPECT_THROW(batch.filterInPlace(z), std::invalid_argument);
    for (std::size_t i = 0; i < bad; ++i) ASSERT_EQ(z[i], expected[i]) << "sample " << i;
    EXPECT_TRUE(std::isnan(z[bad]));
    EXPECT_EQ(batch.update(0.5), stepped.update(0.5));
  }
}

TEST(ArKalmanFilter, OrderOneEqualsScalarFilter) {
  const Simulated s = simulateArPlusNoise({kPaperA}, kPaperQ, kPaperR, 3000, 8);
  for (double p0 : {0.0, 0.3}) {
    const double phi[] = {kPaperA};
    ArKalmanFilter ar(phi, kPaperQ, kPaperR, p0);
    ScalarKalmanFilter sc({.a = kPaperA, .q = kPaperQ, .r = kPaperR, .p0 = p0, .x0 = std::nullopt});
    ASSERT_EQ(ar.order(), 1u);
    for (std::size_t k = 0; k < s.measured.size(); ++k) {
      ASSERT_NEAR(ar.update(s.measured[k]), sc.update(s.measured[k]), 1e-12) << k;
      ASSERT_NEAR(ar.gain(), sc.gain(), 1e-12) << k;
      ASSERT_NEAR(ar.covariance(), sc.covariance(), 1e-12) << k;
    }
  }
}

TEST(ArKalmanFilter, Ar2FilterReducesErrorToItsSteadyCovariance) {
  // AR(2) φ = (0.6, −0.3) with σa² = 0.04 observed through white noise R = 0.09.
  const std::vector<double> phi{0.6, -0.3};
  const double q = 0.04, r = 0.09;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const Simulated s = simulateArPlusNoise(phi, q, r, 40000, seed);
    ArKalmanFilter f(phi, q, r);
    ASSERT_EQ(f.order(), 2u);
    double se = 0.0, se_raw = 0.0;
    std::size_t count = 0;
    for (std::size_t k = 0; k < s.state.size(); ++k) {
      const double est = f.update(s.measured[k]);
      if (k < 100) continue;
      se += (est - s.state[k]) * (est - s.state[k]);
      se_raw += (s.measured[k] - s.state[k]) * (s.measured[k] - s.state[k]);
      ++count;
    }
    const double mse = se / static_cast<double>(count);
    const double mse_raw = se_raw / static_cast<double>(count);
    EXPECT_NEAR(mse_raw, r, 0.05 * r);
    EXPECT_LT(mse, 0.5 * mse_raw);
    // The filter's own steady a-posteriori variance of x_k is the error it achieves.
    EXPECT_NEAR(mse, f.covariance(), 0.05 * f.covariance()) << "seed=" << seed;
  }
}

TEST(ArKalmanFilter, FirstUpdateReturnsTheMeasurement) {
  const double phi[] = {0.5, 0.2, -0.1};
  ArKalmanFilter f(phi, 0.1, 0.2, 0.5);
  EXPECT_EQ(f.update(3.25), 3.25);
  EXPECT_EQ(f.gain(), 0.0);
  EXPECT_EQ(f.covariance(), 0.5);
  // Second step from x̂ = [3.25, 3.25, 3.25], P = 0.5·I: x̂⁻(0) = 0.6·3.25 = 1.95,
  // P⁻(0,0) = 0.5·(0.25 + 0.04 + 0.01) + 0.1 = 0.25, K(0) = 0.25/0.45.
  const double k0 = 0.25 / 0.45;
  EXPECT_NEAR(f.update(1.0), 1.95 + k0 * (1.0 - 1.95), 1e-12);
  EXPECT_NEAR(f.gain(), k0, 1e-12);
  f.reset();
  EXPECT_EQ(f.update(-1.0), -1.0);
}

TEST(ArKalmanFilter, RejectsInvalidParameters) {
  const double phi[] = {0.5, 0.1};
  const std::vector<double> too_long(kMaxArOrder + 1, 0.01);
  EXPECT_THROW(ArKalmanFilter(std::span<const double>{}, 0.1, 0.1), std::invalid_argument);
  EXPECT_THROW(ArKalmanFilter(too_long, 0.1, 0.1), std::invalid_argument);
  EXPECT_NO_THROW(ArKalmanFilter(std::span<const double>(too_long).first(kMaxArOrder), 0.1, 0.1));
  EXPECT_THROW(ArKalmanFilter(phi, -0.1, 0.1), std::invalid_argument);
  EXPECT_THROW(ArKalmanFilter(phi, 0.1, 0.0), std::invalid_argument);
  EXPECT_THROW(ArKalmanFilter(phi, 0.1, 0.1, -1.0), std::invalid_argument);
  const double bad_phi[] = {0.5, NAN};
  EXPECT_THROW(ArKalmanFilter(bad_phi, 0.1, 0.1), std::invalid_argument);
  ArKalmanFilter f(phi, 0.1, 0.1);
  EXPECT_THROW(f.update(INFINITY), std::invalid_argument);
}

TEST(IdentifyKalmanParameters, ExactOnConstructedData) {
  // mean_filtered: any non-constant series; raw = mean_filtered + (+0.3, −0.3, …) + 5, whose
  // difference has mean 5 and variance exactly 0.09. A and Q are the AR(1) Yule–Walker
  // values γ1/γ0 and γ0(1 − φ²), computed plainly here.
  std::mt19937_64 rng(77);
  std::normal_distribution<double> d(0.0, 1.0);
  std::vector<double> mf(1000), raw(1000);
  for (std::size_t i = 0; i < mf.size(); ++i) {
    mf[i] = d(rng) + (i ? 0.4 * mf[i - 1] : 0.0);
    raw[i] = mf[i] + (i % 2 ? -0.3 : 0.3) + 5.0;
  }
  double mean = 0.0;
  for (double v : mf) mean += v;
  mean /= 1000.0;
  double g0 = 0.0, g1 = 0.0;
  for (std::size_t i = 0; i < mf.size(); ++i) {
    g0 += (mf[i] - mean) * (mf[i] - mean);
    if (i) g1 += (mf[i] - mean) * (mf[i - 1] - mean);
  }
  g0 /= 1000.0;
  g1 /= 1000.0;
  const double phi = g1 / g0;
  const KalmanIdentification id = identifyKalmanParameters(raw, mf);
  EXPECT_NEAR(id.params.a, phi, 1e-12);
  EXPECT_NEAR(id.params.q, g0 * (1.0 - phi * phi), 1e-12);
  EXPECT_NEAR(id.params.r, 0.09, 1e-12);
  EXPECT_EQ(id.params.p0, 0.0);
  EXPECT_FALSE(id.params.x0.has_value());
  EXPECT_NEAR(id.phi_std_error, std::sqrt((1.0 - phi * phi) / 1000.0), 1e-12);
}

TEST(IdentifyKalmanParameters, RecoversSimulatedModel) {
  // mean_filtered = AR(1) with the paper's A and Q; raw = that + white noise of variance
  // 0.01. Tolerances: 4 se for φ; 4·√(2/N) relative for the variances.
  const std::size_t n = 20000;
  for (std::uint64_t seed : {4u, 5u, 6u}) {
    const Simulated s = simulateArPlusNoise({kPaperA}, kPaperQ, 0.01, n, seed);
    const KalmanIdentification id = identifyKalmanParameters(s.measured, s.state);
    const double rel = 4.0 * std::sqrt(2.0 / static_cast<double>(n));
    EXPECT_NEAR(id.params.a, kPaperA, 4.0 * std::sqrt((1.0 - kPaperA * kPaperA) / static_cast<double>(n)));
    EXPECT_NEAR(id.params.q, kPaperQ, rel * kPaperQ);
    EXPECT_NEAR(id.params.r, 0.01, rel * 0.01);
    // And the identified filter is a valid one.
    EXPECT_NO_THROW(ScalarKalmanFilter{id.params});
  }
}

TEST(IdentifyKalmanParameters, RejectsBadInput) {
  const std::vector<double> a{1.0, 2.0, 0.5, 3.0};
  const std::vector<double> b{1.1, 1.9, 0.4, 3.2};
  EXPECT_NO_THROW(identifyKalmanParameters(b, a));
  EXPECT_THROW(identifyKalmanParameters(std::span<const double>(b).first(3), a), std::invalid_argument);
  EXPECT_THROW(identifyKalmanParameters(std::span<const double>(b).first(1), std::span<const double>(a).first(1)),
               std::invalid_argument);
  std::vector<double> shifted = a;
  for (double& v : shifted) v += 2.0;
  EXPECT_THROW(identifyKalmanParameters(shifted, a), std::invalid_argument);  // R = 0
  EXPECT_THROW(identifyKalmanParameters(std::vector<double>(4, 1.0), std::vector<double>(4, 0.0)),
               std::invalid_argument);  // mean-filtered series without variance
  std::vector<double> bad = b;
  bad[2] = NAN;
  EXPECT_THROW(identifyKalmanParameters(bad, a), std::invalid_argument);
}
