// The SI and accelerometer units of the noise terms (processing/base/units.hpp,
// processing/base/noise_units.hpp) against values computed by hand and against the Allan
// variance formulas of noise_terms.hpp.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "processing/base/noise_terms.hpp"
#include "processing/base/noise_units.hpp"
#include "processing/base/units.hpp"

using namespace gyrod::processing;
using namespace gyrod::units;

namespace {

constexpr double kPi = std::numbers::pi;

double figure(NoiseTerm t, double v, SensorKind s, const std::string& key) {
  for (const auto& f : noiseFigures(t, v, s))
    if (f.key == key) return f.value;
  ADD_FAILURE() << "no figure " << key;
  return NAN;
}

}  // namespace

TEST(NoiseUnits, GyroConversionsMatchHandComputedValues) {
  EXPECT_DOUBLE_EQ(arwDegPerSqrtHourToRadPerSecondSqrtHz(1.0), kPi / 180.0 / 60.0);  // 2.9089e-4
  EXPECT_DOUBLE_EQ(rrwDegPerHourSqrtHourToRadPerSecond2SqrtHz(1.0), kPi / 180.0 / 216000.0);
  EXPECT_DOUBLE_EQ(degPerHourToRadPerSecond(3600.0), kPi / 180.0);
  EXPECT_DOUBLE_EQ(degPerHour2ToRadPerSecond2(3600.0 * 3600.0), kPi / 180.0);
  EXPECT_DOUBLE_EQ(microradToRad(2.5), 2.5e-6);
}

TEST(NoiseUnits, AccelConversionsMatchHandComputedValues) {
  EXPECT_DOUBLE_EQ(kStandardGravity, 9.80665);
  EXPECT_DOUBLE_EQ(vrwMetresPerSecondSqrtHourToMetresPerSecond2SqrtHz(60.0), 1.0);
  EXPECT_DOUBLE_EQ(milligToMetresPerSecond2(1.0), 0.00980665);
  EXPECT_DOUBLE_EQ(accelRandomWalkMetresPerSecondHourSqrtHourToSi(216000.0), 1.0);
  EXPECT_DOUBLE_EQ(metresPerSecondHour2ToMetresPerSecond3(3600.0 * 3600.0), 1.0);
}

TEST(NoiseUnits, DiscreteStdIsDensityTimesRootRate) {
  // White noise of 0.01 unit/√Hz sampled at 100 Hz: σ_d = 0.1 per sample.
  EXPECT_DOUBLE_EQ(discreteStdFromDensity(0.01, 100.0), 0.1);
  EXPECT_DOUBLE_EQ(densityFromDiscreteStd(0.1, 100.0), 0.01);
}

// The gyro keeps its paper key first and adds SI; the keys carry their unit.
TEST(NoiseUnits, GyroFiguresKeepThePaperKeyAndAddSi) {
  const auto f = noiseFigures(NoiseTerm::AngleRandomWalk, 0.5, SensorKind::Gyro);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].key, "arw_deg_per_sqrt_h");
  EXPECT_EQ(f[0].value, 0.5);
  EXPECT_EQ(f[1].key, "arw_rad_per_s_sqrt_hz");
  EXPECT_DOUBLE_EQ(f[1].value, 0.5 * kPi / 180.0 / 60.0);
  for (NoiseTerm t : kAllNoiseTerms) EXPECT_EQ(noiseFigures(t, 1.0, SensorKind::Gyro)[0].key, noiseTermKey(t));
}

// An accelerometer series in g goes through the same fit; its figures must be what the Allan
// variance of the term says, read in m/s² (σ²(τ) from noise_terms.hpp, in g²).
TEST(NoiseUnits, AccelFiguresAgreeWithTheAllanVarianceOfTheTerm) {
  const double tau = 7.0, g0 = kStandardGravity;
  const double n = 0.3;  // the fit's number for a series in g
  const double white_density_g = std::sqrt(allanVarianceOfTerm(NoiseTerm::AngleRandomWalk, n, tau) * tau);
  EXPECT_NEAR(figure(NoiseTerm::AngleRandomWalk, n, SensorKind::Accel, "vrw_m_per_s2_sqrt_hz"), white_density_g * g0,
              1e-12);
  EXPECT_NEAR(figure(NoiseTerm::AngleRandomWalk, n, SensorKind::Accel, "vrw_m_per_s_per_sqrt_h"),
              white_density_g * g0 * 60.0, 1e-12);

  const double k = 40.0;
  const double walk_g = std::sqrt(3.0 * allanVarianceOfTerm(NoiseTerm::RateRandomWalk, k, tau) / tau);  // g/s^1.5
  EXPECT_NEAR(
      figure(NoiseTerm::RateRandomWalk, k, SensorKind::Accel, "accel_random_walk_m_per_s3_sqrt_hz") / (walk_g * g0),
      1.0, 1e-12);

  const double b = 36.0;  // the fit's number: σ floor = 0.6643 · (b / 3600) g
  const double floor_g = std::sqrt(allanVarianceOfTerm(NoiseTerm::BiasInstability, b, tau));
  EXPECT_NEAR(figure(NoiseTerm::BiasInstability, b, SensorKind::Accel, "bias_instability_mg"),
              1e3 * floor_g / kBiasInstabilityFactor, 1e-9);
  EXPECT_NEAR(figure(NoiseTerm::BiasInstability, b, SensorKind::Accel, "bias_instability_m_per_s2"),
              floor_g / kBiasInstabilityFactor * g0, 1e-12);
}

TEST(NoiseUnits, KalibrValuesAreTheSiDensityAndRandomWalk) {
  NoiseTerms t;
  t.arw_deg_per_sqrt_h = 0.6;
  t.rrw_deg_per_h_sqrt_h = 20.0;
  EXPECT_DOUBLE_EQ(noiseDensitySi(t, SensorKind::Gyro), 0.6 * kPi / 180.0 / 60.0);
  EXPECT_DOUBLE_EQ(biasRandomWalkSi(t, SensorKind::Gyro), 20.0 * kPi / 180.0 / 216000.0);
  EXPECT_DOUBLE_EQ(noiseDensitySi(t, SensorKind::Accel), 0.6 * kStandardGravity / 60.0);
  EXPECT_DOUBLE_EQ(biasRandomWalkSi(t, SensorKind::Accel), 20.0 * kStandardGravity / 216000.0);
  EXPECT_EQ(sensorOfColumn("ay"), SensorKind::Accel);
  EXPECT_EQ(sensorOfColumn("gy"), SensorKind::Gyro);
}
