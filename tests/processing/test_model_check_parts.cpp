// The parts of the model check against independent truth: the Gauss–Markov Allan variance
// against a numerical integral of its autocovariance, the simulator's extra effects against
// their formulas, Ljung–Box and sample timing against hand computations, the sinusoid fit,
// outlier scores, the null summaries, Levinson and the Kalman innovations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/base/distributions.hpp"
#include "processing/base/portable_random.hpp"
#include "processing/model_check/detail.hpp"
#include "processing/model_check/model_check.hpp"
#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod::processing;
using namespace gyrod::processing::model_check_detail;

namespace {

// Allan variance of a stationary process with autocovariance R(u), by its definition
// σ² = ½·E[(ȳ₂ − ȳ₁)²] = E[ȳ²] − E[ȳ₁ȳ₂], each an integral of R against a triangle:
// E[ȳ²] = (2/τ²)∫₀^τ (τ − u)R(u)du, E[ȳ₁ȳ₂] = (1/τ²)∫₀^{2τ} min(u, 2τ − u)R(u)du. Simpson.
template <class R>
double allanVarianceByIntegral(double tau, R r) {
  const int n = 20000;  // even
  auto simpson = [&](double a, double b, auto f) {
    const double h = (b - a) / n;
    double s = f(a) + f(b);
    for (int i = 1; i < n; ++i) s += f(a + i * h) * (i % 2 ? 4.0 : 2.0);
    return s * h / 3.0;
  };
  const double v = 2.0 / (tau * tau) * simpson(0.0, tau, [&](double u) { return (tau - u) * r(u); });
  const double c =
      1.0 / (tau * tau) * simpson(0.0, 2.0 * tau, [&](double u) { return std::min(u, 2.0 * tau - u) * r(u); });
  return v - c;
}

SimulationModel quietModel(double rate = 50.0) {
  SimulationModel m;
  m.rate_hz = rate;
  return m;
}

}  // namespace

// ---- Gauss–Markov Allan variance --------------------------------------------------------

TEST(GaussMarkovAllanVariance, MatchesTheIntegralOfItsAutocovariance) {
  const double t_corr = 7.0, sigma = 0.3;
  for (double tau : {0.01, 0.5, 3.0, 7.0, 20.0, 300.0}) {
    const double truth = allanVarianceByIntegral(tau, [&](double u) { return sigma * sigma * std::exp(-u / t_corr); });
    EXPECT_NEAR(gaussMarkovAllanVariance(tau, t_corr, sigma), truth, 1e-7 * sigma * sigma) << "tau " << tau;
  }
}

TEST(GaussMarkovAllanVariance, LimitsAreRateRandomWalkAndWhiteNoise) {
  // τ ≪ T: a random walk of q_c = 2σ²/T, σ² = q_c·τ/3; τ ≫ T: white of density q_c·T², σ² = q_c·T²/τ.
  const double t_corr = 10.0, sigma = 1.0, qc = 2.0 * sigma * sigma / t_corr;
  EXPECT_NEAR(gaussMarkovAllanVariance(1e-4, t_corr, sigma) / (qc * 1e-4 / 3.0), 1.0, 1e-4);
  EXPECT_NEAR(gaussMarkovAllanVariance(1e5, t_corr, sigma) / (qc * t_corr * t_corr / 1e5), 1.0, 2e-4);
  EXPECT_THROW(gaussMarkovAllanVariance(0.0, 1.0, 1.0), std::invalid_argument);
  EXPECT_THROW(gaussMarkovAllanVariance(1.0, -1.0, 1.0), std::invalid_argument);
}

// ---- the simulator's extra effects ---------------------------------------------------------

TEST(NoiseSimulatorExtras, DeterministicEffectsFollowTheirFormulas) {
  SimulationModel m = quietModel();
  m.temperature = {20.0, 30.0, 100.0, 0.0};
  AxisExtraEffects& e = m.axes[1].extra;
  e.temperature_coefficient_dps_per_c = 0.02;
  e.temperature_reference_c = 22.0;
  e.sinusoids = {{1.3, 0.05, 0.4}, {7.0, 0.01, -1.0}};
  e.bias_steps = {{10.0, 0.2}, {30.0, -0.05}};
  NoiseSimulator sim(m, 60.0, 3);
  for (int i = 0; i < 3000; ++i) {
    const SimulatedSample s = sim.next();
    const double t = i / 50.0;
    double expected = 0.02 * (30.0 + (20.0 - 30.0) * std::exp(-t / 100.0) - 22.0);
    expected += 0.05 * std::sin(2.0 * std::numbers::pi * 1.3 * t + 0.4) +
                0.01 * std::sin(2.0 * std::numbers::pi * 7.0 * t - 1.0);
    expected += (t >= 10.0 ? 0.2 : 0.0) + (t >= 30.0 ? -0.05 : 0.0);
    ASSERT_NEAR(s.rate_dps[1], expected, 1e-12) << "sample " << i;
    ASSERT_EQ(s.rate_dps[0], 0.0);
    ASSERT_EQ(s.rate_dps[2], 0.0);
  }
}

TEST(NoiseSimulatorExtras, AddingEffectsLeavesTheNoiseRealisationAlone) {
  // The extras draw from their own generator: (noise + extras) − noise = extras, sample by sample.
  SimulationModel base = quietModel();
  for (auto& a : base.axes) {
    a.terms.arw_deg_per_sqrt_h = 0.5;
    a.terms.bias_instability_deg_per_h = 8.0;
  }
  SimulationModel with = base;
  with.axes[0].extra.gauss_markov_tau_s = 2.0;
  with.axes[0].extra.gauss_markov_sigma_dps = 0.01;
  with.axes[2].extra.sinusoids = {{2.0, 0.1, 0.0}};
  SimulationModel only = quietModel();
  only.axes[0].extra = with.axes[0].extra;
  only.axes[2].extra = with.axes[2].extra;
  NoiseSimulator a(base, 100.0, 11), b(with, 100.0, 11), c(only, 100.0, 11);
  for (int i = 0; i < 5000; ++i) {
    const SimulatedSample sa = a.next(), sb = b.next(), sc = c.next();
    for (std::size_t k = 0; k < 3; ++k) ASSERT_NEAR(sb.rate_dps[k], sa.rate_dps[k] + sc.rate_dps[k], 1e-12);
  }
}

TEST(NoiseSimulatorExtras, OutliersAreCountDistinctSamplesOfTheGivenSize) {
  SimulationModel m = quietModel();
  m.axes[0].extra.outlier_count = 25;
  m.axes[0].extra.outlier_amplitude_dps = 3.0;
  NoiseSimulator sim(m, 200.0, 5);
  std::size_t nonzero = 0, positive = 0;
  for (std::size_t i = 0; i < sim.sampleCount(); ++i) {
    const double v = sim.next().rate_dps[0];
    if (v != 0.0) {
      ++nonzero;
      positive += v > 0.0;
      ASSERT_EQ(std::fabs(v), 3.0);
    }
  }
  EXPECT_EQ(nonzero, 25u);
  EXPECT_GT(positive, 0u);  // both signs (P(all one sign) = 2^-24)
  EXPECT_LT(positive, 25u);
}

TEST(NoiseSimulatorExtras, GaussMarkovHasItsVarianceAndCorrelation) {
  // σ² and the lag-1 correlation ρ = e^{−τ0/T} of the sample, against their standard errors
  // (T = 0.5 s = 25 samples; 200 000 samples ≈ 4000 correlation times).
  SimulationModel m = quietModel();
  m.axes[0].extra.gauss_markov_tau_s = 0.5;
  m.axes[0].extra.gauss_markov_sigma_dps = 0.2;
  NoiseSimulator sim(m, 4000.0, 21);
  std::vector<double> x(sim.sampleCount());
  for (double& v : x) v = sim.next().rate_dps[0];
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double c0 = 0.0, c1 = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    c0 += (x[i] - mean) * (x[i] - mean);
    if (i > 0) c1 += (x[i] - mean) * (x[i - 1] - mean);
  }
  const double var = c0 / static_cast<double>(x.size()), rho = c1 / c0;
  const double rho_true = std::exp(-1.0 / 25.0);
  // var of the sample variance of an AR(1): ≈ 2σ⁴(1 + ρ²)/(1 − ρ²)/n.
  const double n = static_cast<double>(x.size());
  const double se_var = std::sqrt(2.0 * std::pow(0.04, 2) * (1 + rho_true * rho_true) / (1 - rho_true * rho_true) / n);
  EXPECT_NEAR(var, 0.04, 5.0 * se_var);
  EXPECT_NEAR(rho, rho_true, 5.0 * std::sqrt((1.0 - rho_true * rho_true) / n));
}

TEST(NoiseSimulatorExtras, BadExtrasAreRejectedNamingTheParameter) {
  SimulationModel m = quietModel();
  m.axes[2].extra.sinusoids = {{-1.0, 0.1, 0.0}};
  try {
    validateSimulationModel(m);
    FAIL() << "negative frequency accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("axis z: extra.sinusoid[0].freq_hz"), std::string::npos) << e.what();
  }
  m = quietModel();
  m.axes[0].extra.gauss_markov_sigma_dps = 0.1;  // no correlation time
  EXPECT_THROW(validateSimulationModel(m), std::invalid_argument);
  m = quietModel();
  m.axes[0].extra.outlier_count = 101;
  EXPECT_THROW(NoiseSimulator(m, 2.0, 1), std::invalid_argument);  // 100 samples
}

// ---- statistics ---------------------------------------------------------------------

TEST(ModelCheckParts, LjungBoxMatchesTheFormulaByHand) {
  const std::vector<double> x = {0.3, -1.2, 0.8, 0.1, -0.4, 1.5, -0.9, 0.2, 0.0, -0.6, 1.1, -0.3};
  const std::size_t n = x.size(), h = 3;
  double mean = 0.0;
  for (double v : x) mean += v / n;
  double c0 = 0.0;
  for (double v : x) c0 += (v - mean) * (v - mean);
  double q = 0.0;
  for (std::size_t k = 1; k <= h; ++k) {
    double ck = 0.0;
    for (std::size_t i = k; i < n; ++i) ck += (x[i] - mean) * (x[i - k] - mean);
    q += (ck / c0) * (ck / c0) / static_cast<double>(n - k);
  }
  q *= n * (n + 2.0);
  const LjungBox lb = ljungBoxTest(x, h, 1);
  EXPECT_NEAR(lb.q, q, 1e-12);
  EXPECT_EQ(lb.dof, 2u);
  EXPECT_NEAR(lb.p_value, 1.0 - chiSquareCdf(q, 2.0), 1e-12);
  EXPECT_THROW(ljungBoxTest(x, 11, 0), std::invalid_argument);
}

TEST(ModelCheckParts, LjungBoxPValueIsUniformOnWhiteNoise) {
  // Under white noise the p-value is U(0, 1): over 200 series, the fraction below 0.1 is
  // 0.1 ± 5·√(0.09/200).
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01;
  int below = 0;
  for (int s = 0; s < 200; ++s) {
    std::vector<double> x(2000);
    for (double& v : x) v = n01(rng);
    below += ljungBoxTest(x, 20, 0).p_value < 0.1;
  }
  EXPECT_NEAR(below / 200.0, 0.1, 5.0 * std::sqrt(0.09 / 200.0));
}

TEST(ModelCheckParts, SampleTimingCountsGapsAndLostSamples) {
  std::vector<double> t;
  for (int i = 0; i < 100; ++i) t.push_back(i * 0.02);
  // Remove samples 20..22 (3 lost) and 60 (1 lost): two gaps.
  std::vector<double> kept;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (!(i >= 20 && i <= 22) && i != 60) kept.push_back(t[i]);
  const SampleTiming s = analyzeSampleTiming(kept);
  EXPECT_EQ(s.gaps, 2u);
  EXPECT_EQ(s.lost, 4u);
  EXPECT_NEAR(s.median_spacing_s, 0.02, 1e-12);
  ASSERT_EQ(s.gap_times_s.size(), 2u);
  EXPECT_NEAR(s.gap_times_s[0], 19 * 0.02, 1e-12);
  EXPECT_NEAR(s.gap_times_s[1], 59 * 0.02, 1e-12);
  EXPECT_THROW(analyzeSampleTiming(std::vector<double>{0.0, 0.1, 0.1}), std::invalid_argument);
}

TEST(ModelCheckParts, SinusoidFitRecoversAmplitudeAndPhase) {
  std::vector<double> x(5000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 0.7 * std::sin(2.0 * std::numbers::pi * 3.3 * i / 50.0 + 1.1) + 0.2;
  // The constant is not in the fit; over many cycles it leaks little: tolerance from its
  // projection, 0.2·|Σ sin|/Σ sin² ≈ 0.2·O(1)/2500.
  const SinusoidFit f = fitSinusoidAt(x, 50.0, 3.3);
  EXPECT_NEAR(f.amp_dps, 0.7, 1e-3);
  EXPECT_NEAR(f.phase_rad, 1.1, 2e-3);
}

TEST(ModelCheckParts, OutlierScoresPickTheSpikes) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> n01;
  std::vector<double> x(20000);
  for (double& v : x) v = n01(rng);
  const std::vector<std::size_t> spikes = {100, 5000, 5003, 19990};
  for (std::size_t i : spikes) x[i] += (i % 2 ? -12.0 : 12.0);
  const std::vector<double> z = localOutlierScores(x, 10);
  std::vector<std::size_t> order(z.size());
  for (std::size_t i = 0; i < z.size(); ++i) order[i] = i;
  std::partial_sort(order.begin(), order.begin() + 4, order.end(),
                    [&](std::size_t a, std::size_t b) { return std::fabs(z[a]) > std::fabs(z[b]); });
  std::vector<std::size_t> top(order.begin(), order.begin() + 4);
  std::sort(top.begin(), top.end());
  EXPECT_EQ(top, spikes);
  // The scale is that of the neighbour differences, sd √(1 + 1/20) for unit white noise, so
  // a 12σ spike scores (12 + e)/√1.05 with e the noise of that difference: 11.7 ± 1 (5 sd).
  EXPECT_NEAR(std::fabs(z[100]), 12.0 / std::sqrt(1.05), 5.0);
}

TEST(ModelCheckParts, NullThresholdsFollowTheirModels) {
  // Two-sided on a normal sample: threshold = σ̂·Φ⁻¹(1 − α/2) with σ̂ from the quantiles.
  std::mt19937_64 rng(1);
  std::normal_distribution<double> n01;
  std::vector<double> v(4000);
  for (double& x : v) x = 3.0 + 2.0 * n01(rng);
  const NullSummary two = summarizeNull(v, 1e-4, true);
  EXPECT_NEAR(two.median, 3.0, 0.15);
  EXPECT_NEAR(two.spread, 2.0, 0.15);
  EXPECT_NEAR(two.threshold, std::max(two.largest, normalQuantile(1.0 - 5e-5) * two.spread), 1e-12);
  EXPECT_TRUE(two.fires(3.0 + 9.0));
  EXPECT_TRUE(two.fires(3.0 - 9.0));
  EXPECT_FALSE(two.fires(3.5));
  // One-sided on a Gumbel(μ = 1, β = 0.5) sample: the fitted (1 − α) quantile is
  // μ − β·ln(−ln(1 − α)) ≈ 1 + 0.5·9.21 = 5.6, within the sampling error of q50 and q90.
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (double& x : v) x = 1.0 - 0.5 * std::log(-std::log(u01(rng)));
  const NullSummary one = summarizeNull(v, 1e-4, false);
  EXPECT_NEAR(one.spread, 0.5, 0.05);
  EXPECT_NEAR(one.threshold, 1.0 - 0.5 * std::log(-std::log1p(-1e-4)), 0.4);
  EXPECT_THROW(summarizeNull({1.0}, 1e-4, false), std::invalid_argument);
}

TEST(ModelCheckParts, LevinsonRecoversAnArFromItsAutocovariance) {
  // AR(2) x = 0.6x₁ − 0.3x₂ + a, σa² = 1: γ from the Yule–Walker equations solved by hand:
  // ρ1 = φ1/(1 − φ2), ρ2 = φ1ρ1 + φ2, γ0 = σa²/(1 − φ1ρ1 − φ2ρ2).
  const double p1 = 0.6, p2 = -0.3;
  const double r1 = p1 / (1 - p2), r2 = p1 * r1 + p2, g0 = 1.0 / (1 - p1 * r1 - p2 * r2);
  const std::vector<double> gamma = {g0, g0 * r1, g0 * r2};
  std::vector<double> phi;
  double v = 0.0;
  ASSERT_TRUE(levinsonFromAutocovariance(gamma, 2, phi, v));
  EXPECT_NEAR(phi[0], p1, 1e-12);
  EXPECT_NEAR(phi[1], p2, 1e-12);
  EXPECT_NEAR(v, 1.0, 1e-12);
  EXPECT_FALSE(levinsonFromAutocovariance(std::vector<double>{1.0, 1.5}, 1, phi, v));  // |ρ1| > 1
}

TEST(ModelCheckParts, KalmanInnovationsOfAnArAreItsPredictionErrors) {
  // With no measurement noise the filter of an AR(2) predicts φ1·z₋₁ + φ2·z₋₂ once started.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01;
  std::vector<double> z(3000);
  for (std::size_t i = 2; i < z.size(); ++i) z[i] = 0.5 * z[i - 1] + 0.2 * z[i - 2] + n01(rng);
  const std::vector<double> phi = {0.5, 0.2};
  const InnovationStats s = kalmanInnovations(z, phi, 1.0, 0.0, 0.0, false);
  ASSERT_EQ(s.innovations.size(), z.size() - 100);
  for (std::size_t k = 0; k < s.innovations.size(); k += 97) {
    const std::size_t i = k + 100;
    ASSERT_NEAR(s.innovations[k], z[i] - 0.5 * z[i - 1] - 0.2 * z[i - 2], 1e-9) << i;
  }
  // Robust: a 20σ spike is rejected and does not count.
  z[1500] += 20.0;
  const InnovationStats r = kalmanInnovations(z, phi, 1.0, 0.0, 0.0, true);
  EXPECT_EQ(r.rejected, 1u);
  EXPECT_LT(r.variance, s.variance * 1.01);
}

TEST(ModelCheckParts, KalmanWithAGaussMarkovStateWhitensArPlusGaussMarkov) {
  // z = white (AR(1) with φ = 0.1) + a slow GM: the filter with both states leaves innovations
  // whose lag-1 correlation is within 5/√n of 0, while the AR part alone does not.
  std::mt19937_64 rng(8);
  std::normal_distribution<double> n01;
  const double rho = std::exp(-1.0 / 200.0), q = 0.05 * (1 - rho * rho);
  std::vector<double> z(40000);
  double a = 0.0, g = 0.0;
  for (double& v : z) {
    a = 0.1 * a + n01(rng);
    g = rho * g + std::sqrt(q) * n01(rng);
    v = a + g;
  }
  auto lag1 = [](const std::vector<double>& e) {
    double c0 = 0.0, c1 = 0.0;
    for (std::size_t i = 0; i < e.size(); ++i) {
      c0 += e[i] * e[i];
      if (i) c1 += e[i] * e[i - 1];
    }
    return c1 / c0;
  };
  const std::vector<double> phi = {0.1};
  const InnovationStats with = kalmanInnovations(z, phi, 1.0, rho, q, false);
  EXPECT_NEAR(lag1(with.innovations), 0.0, 5.0 / std::sqrt(40000.0));
  const LjungBox lb = ljungBoxTest(with.innovations, 30, 3);
  EXPECT_GT(lb.p_value, 1e-4);
  const LjungBox lb_ar = ljungBoxTest(kalmanInnovations(z, phi, 1.0, 0.0, 0.0, false).innovations, 30, 1);
  EXPECT_LT(lb_ar.p_value, 1e-6);
}
