// The known-form detectors (the reference of the model check's detection curves) against
// their nulls in white noise, where each has a textbook distribution, and against effects
// of known size.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "processing/base/portable_random.hpp"
#include "processing/model_check/detail.hpp"
#include "processing/model_check/known_form_detectors.hpp"

using namespace gyrod::processing;

namespace {

std::vector<double> whiteNoise(NormalGenerator& g, std::size_t n, double sd) {
  std::vector<double> x(n);
  for (double& v : x) v = sd * g.next();
  return x;
}

// Binomial count of exceedances at rate p in `trials`: within 4 standard deviations.
void expectRate(std::size_t count, std::size_t trials, double p) {
  const double mean = p * static_cast<double>(trials);
  const double sd = std::sqrt(mean * (1.0 - p));
  EXPECT_NEAR(static_cast<double>(count), mean, 4.0 * sd) << count << " of " << trials;
}

}  // namespace

TEST(KnownFormDetectors, SinusoidStatisticIsChiSquare2InWhiteNoise) {
  NormalGenerator g(11);
  const double threshold = 2.0 * std::log(100.0);  // 1 % point of χ²(2)
  std::size_t above = 0;
  const std::size_t trials = 3000;
  for (std::size_t t = 0; t < trials; ++t) {
    const std::vector<double> x = whiteNoise(g, 1000, 0.3);
    above += knownSinusoidStatistic(x, 50.0, 3.7) > threshold ? 1 : 0;
  }
  expectRate(above, trials, 0.01);
}

TEST(KnownFormDetectors, SinusoidStatisticGrowsAsNTimesSnr) {
  // E[stat] ≈ 2 + n·A²/(2σ²): with n = 4000, A/σ = 0.2 that is 82.
  NormalGenerator g(12);
  double sum = 0.0;
  for (int t = 0; t < 200; ++t) {
    std::vector<double> x = whiteNoise(g, 4000, 1.0);
    for (std::size_t i = 0; i < x.size(); ++i)
      x[i] += 0.2 * std::sin(2.0 * std::numbers::pi * 3.7 * static_cast<double>(i) / 50.0 + 1.0);
    sum += knownSinusoidStatistic(x, 50.0, 3.7);
  }
  EXPECT_NEAR(sum / 200.0, 82.0, 4.0);
  EXPECT_THROW(knownSinusoidStatistic(std::vector<double>(100, 0.0), 50.0, 25.0), std::invalid_argument);
}

TEST(KnownFormDetectors, TemperatureStatisticIsStudentTInWhiteNoise) {
  NormalGenerator g(13);
  std::vector<double> temp(2000);
  for (std::size_t i = 0; i < temp.size(); ++i) temp[i] = 25.0 + std::sin(static_cast<double>(i) / 150.0);
  std::size_t above = 0;
  const std::size_t trials = 3000;
  for (std::size_t t = 0; t < trials; ++t) {
    const std::vector<double> x = whiteNoise(g, 2000, 1.0);
    // 200 blocks of 10: t(197), whose two-sided 1 % point is 2.601.
    above += knownTemperatureStatistic(x, temp, 10) > 2.601 ? 1 : 0;
  }
  expectRate(above, trials, 0.01);
  std::vector<double> x = whiteNoise(g, 2000, 1.0);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] += 0.5 * (temp[i] - 25.0);
  EXPECT_GT(knownTemperatureStatistic(x, temp, 10), 10.0);
  EXPECT_THROW(knownTemperatureStatistic(x, std::vector<double>(2000, 25.0), 10), std::invalid_argument);
}

TEST(KnownFormDetectors, StepStatisticFindsAStepAtItsPredictedPower) {
  NormalGenerator g(14);
  // White noise, 120 blocks of 50, the step 2500 samples in (block boundary 50): windows
  // W = 1..32 blocks fit; the sd of each difference is √(2/(50·W)).
  const std::vector<double> d0 = knownStepDifferences(whiteNoise(g, 6000, 1.0), 2500, 50);
  ASSERT_EQ(d0.size(), 6u);
  std::vector<double> sd(d0.size());
  for (std::size_t j = 0; j < sd.size(); ++j) sd[j] = std::sqrt(2.0 / (50.0 * std::pow(2.0, static_cast<double>(j))));
  std::vector<double> clean;
  for (int t = 0; t < 400; ++t)
    clean.push_back(knownStepStatistic(knownStepDifferences(whiteNoise(g, 6000, 1.0), 2500, 50), sd));
  const double threshold = calibratedThreshold(clean, 0.01);
  EXPECT_GT(threshold, 2.576);  // max of several correlated |z|: above the single one's 1 % point
  EXPECT_LT(threshold, 3.3);
  // A step of 0.16 σ at W = 32 blocks is 0.16/√(2/1600) = 4.5 sd: found nearly always;
  // of 0.03 σ (0.85 sd) rarely.
  std::size_t big = 0, small = 0;
  for (int t = 0; t < 100; ++t) {
    std::vector<double> x = whiteNoise(g, 6000, 1.0), y = x;
    for (std::size_t i = 2500; i < x.size(); ++i) {
      x[i] += 0.16;
      y[i] += 0.03;
    }
    big += knownStepStatistic(knownStepDifferences(x, 2500, 50), sd) > threshold ? 1 : 0;
    small += knownStepStatistic(knownStepDifferences(y, 2500, 50), sd) > threshold ? 1 : 0;
  }
  EXPECT_GE(big, 90u);
  EXPECT_LE(small, 30u);
  EXPECT_THROW(knownStepDifferences(std::vector<double>(100, 0.0), 100, 10), std::invalid_argument);
}

TEST(KnownFormDetectors, SpectralScoreIsStandardNormalOnExponentialBins) {
  Xoshiro256StarStar u(15);
  const std::vector<double> shape = gaussMarkovSpectralShape(2.0, 50.0, 4096);
  std::vector<double> base(shape.size());
  for (std::size_t k = 0; k < base.size(); ++k) base[k] = 1.0 + 10.0 / (1.0 + static_cast<double>(k));
  double sum = 0.0, sum2 = 0.0;
  const int trials = 2000;
  std::vector<double> p(base.size());
  for (int t = 0; t < trials; ++t) {
    for (std::size_t k = 0; k < p.size(); ++k) p[k] = -base[k] * std::log(1.0 - u.uniform());
    const double s = spectralScoreStatistic(p, base, shape);
    sum += s;
    sum2 += s * s;
  }
  const double mean = sum / trials, var = sum2 / trials - mean * mean;
  EXPECT_NEAR(mean, 0.0, 0.1);
  EXPECT_NEAR(var, 1.0, 0.12);
  // An added component ε·g shifts the score by ε·Σ w_k g_k/b_k / √Σw² = ε·√Σ(g/b)².
  double norm = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) norm += shape[k] * shape[k] / (base[k] * base[k]);
  std::vector<double> expected(base.size());
  for (std::size_t k = 0; k < p.size(); ++k) expected[k] = base[k] + 0.05 * shape[k];
  EXPECT_NEAR(spectralScoreStatistic(expected, base, shape), 0.05 * std::sqrt(norm), 1e-9);
}

TEST(KnownFormDetectors, GaussMarkovShapeIsTheAr1Spectrum) {
  const std::vector<double> s = gaussMarkovSpectralShape(1.0, 50.0, 1000);
  const double rho = std::exp(-1.0 / 50.0);
  EXPECT_NEAR(s[0], (1.0 + rho) / (1.0 - rho), 1e-9);
  EXPECT_NEAR(s[500], (1.0 - rho) / (1.0 + rho), 1e-12);
  // Its mean over the full circle is the variance: 1 (Parseval).
  double mean = s[0] + s[500];
  for (std::size_t k = 1; k < 500; ++k) mean += 2.0 * s[k];
  EXPECT_NEAR(mean / 1000.0, 1.0, 1e-6);
}

TEST(KnownFormDetectors, CalibratedThresholdIsTheEmpiricalQuantile) {
  std::vector<double> v;
  for (int i = 0; i <= 1000; ++i) v.push_back(static_cast<double>(1000 - i));
  EXPECT_DOUBLE_EQ(calibratedThreshold(v, 0.01), 990.0);
  EXPECT_THROW(calibratedThreshold({}, 0.01), std::invalid_argument);
  EXPECT_THROW(calibratedThreshold(v, 1.5), std::invalid_argument);
}
