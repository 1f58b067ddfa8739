// The bias against temperature of a still record (processing/motion/temperature_bias_fit.hpp): on
// synthetic records with a known bias, coefficient and warm-up shape, each estimate lies within
// three of its own standard errors of the truth, and what the record cannot show is not fitted.
#include "processing/motion/temperature_bias_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

using namespace gyrod::processing;

namespace {

struct Synthetic {
  std::vector<double> secs, rate, temp;
};

// 20 min at 50 Hz: T warms from 25 to 40 °C (τ = 300 s) with 0.02 °C of noise; the rate is
// bias + k·(T_true − 25) + A·e^{−t/τb} + white noise of std σ.
Synthetic warmUpRecord(std::uint64_t seed, double bias, double k, double amplitude, double tau_b, double sigma,
                       double final_c = 40.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  Synthetic s;
  for (int i = 0; i < 60000; ++i) {
    const double t = i / 50.0;
    const double temp = final_c + (25.0 - final_c) * std::exp(-t / 300.0);
    s.secs.push_back(t);
    s.temp.push_back(temp + 0.02 * normal(rng));
    double r = bias + k * (temp - 25.0) + sigma * normal(rng);
    if (amplitude != 0.0) r += amplitude * std::exp(-t / tau_b);
    s.rate.push_back(r);
  }
  return s;
}

}  // namespace

TEST(TemperatureBiasFit, RecoversBiasAndCoefficientWithinThreeStandardErrors) {
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const Synthetic s = warmUpRecord(seed, 1.2, 0.03, 0.0, 0.0, 0.1);
    const TemperatureBiasFit f = fitTemperatureBias(s.secs, s.rate, s.temp);
    ASSERT_TRUE(f.coefficientFitted());
    EXPECT_NEAR(f.coefficient_dps_per_c, 0.03, 3.0 * f.coefficient_std_dps_per_c) << "seed " << seed;
    EXPECT_NEAR(f.bias_dps, 1.2 + 0.03 * (f.reference_c - 25.0), 3.0 * f.bias_std_dps) << "seed " << seed;
    EXPECT_EQ(f.warm_up_amplitude_dps, 0.0) << "seed " << seed << ": no shape was hidden";
    // White noise: σ/√n for the bias at the mean temperature, within a factor of 2.
    EXPECT_GT(f.bias_std_dps, 0.5 * 0.1 / std::sqrt(60000.0));
    EXPECT_LT(f.bias_std_dps, 2.0 * 0.1 / std::sqrt(60000.0));
  }
}

TEST(TemperatureBiasFit, FindsAWarmUpShapeBeyondTheTemperature) {
  // A 0.05 °/s transient of τ = 60 s (faster than the temperature's 300 s).
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Synthetic s = warmUpRecord(seed, -0.4, -0.02, 0.05, 60.0, 0.05);
    const TemperatureBiasFit f = fitTemperatureBias(s.secs, s.rate, s.temp);
    std::printf("seed %llu: shape %.5g +- %.2g, tau %.4g s; k %.6g +- %.2g; bias %.6g +- %.2g\n",
                static_cast<unsigned long long>(seed), f.warm_up_amplitude_dps, f.warm_up_amplitude_std_dps,
                f.warm_up_time_constant_s, f.coefficient_dps_per_c, f.coefficient_std_dps_per_c, f.bias_dps,
                f.bias_std_dps);
    EXPECT_NEAR(f.warm_up_amplitude_dps, 0.05, 3.0 * f.warm_up_amplitude_std_dps) << "seed " << seed;
    EXPECT_NEAR(f.warm_up_time_constant_s, 60.0, 15.0) << "seed " << seed;
    EXPECT_NEAR(f.coefficient_dps_per_c, -0.02, 3.0 * f.coefficient_std_dps_per_c) << "seed " << seed;
    EXPECT_NEAR(f.bias_dps, -0.4 - 0.02 * (f.reference_c - 25.0), 3.0 * f.bias_std_dps) << "seed " << seed;
  }
}

TEST(TemperatureBiasFit, AFlatTemperatureFitsNoCoefficient) {
  const Synthetic s = warmUpRecord(4, 0.3, 0.03, 0.0, 0.0, 0.1, 25.0);
  const TemperatureBiasFit f = fitTemperatureBias(s.secs, s.rate, s.temp);
  EXPECT_FALSE(f.coefficientFitted());
  EXPECT_EQ(f.coefficient_dps_per_c, 0.0);
  EXPECT_NEAR(f.bias_dps, 0.3, 3.0 * f.bias_std_dps);
}

TEST(TemperatureBiasFit, RejectsBadInput) {
  const std::vector<double> t = {0.0, 1.0}, r = {0.0, 0.0}, temp = {25.0};
  EXPECT_THROW(fitTemperatureBias(t, r, temp), std::invalid_argument);
  std::vector<double> secs(100), rate(100, 0.0), temps(100, 25.0);
  for (std::size_t i = 0; i < secs.size(); ++i) secs[i] = 0.02 * static_cast<double>(i);
  EXPECT_THROW(fitTemperatureBias(secs, rate, temps), std::invalid_argument);  // 2 s: fewer than 8 blocks
}
