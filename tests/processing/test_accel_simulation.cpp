// The simulated accelerometer: gravity at the attitude integrated from the true rates
// (AttitudeIntegrator), the three accel noise terms against their Allan laws, quantisation and
// saturation at AFS_SEL, and the gyro stream untouched bit for bit by asking for accel.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/simulation/motion_profile.hpp"
#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod::processing;

namespace {

void expectVector(const std::array<double, 3>& v, const std::array<double, 3>& want, double tol, const char* what) {
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(v[a], want[a], tol) << what << " axis " << a;
}

AccelModel whiteAccel(double density) {
  AccelModel accel;
  for (auto& axis : accel.axes) axis.velocity_random_walk_g_per_sqrt_hz = density;
  return accel;
}

SimulationModel chipModel() {
  SimulationModel m;
  m.rate_hz = 100.0;
  m.dlpf_cfg = 3;
  m.fs_sel = 0;
  for (auto& axis : m.axes) {
    axis.terms.arw_deg_per_sqrt_h = 0.9;
    axis.terms.bias_instability_deg_per_h = 8.0;
    axis.bias_dps = -0.7;
  }
  return m;
}

}  // namespace

TEST(AttitudeIntegrator, StartsLevelAndAQuarterTurnMovesGravityToTheRightAxis) {
  AttitudeIntegrator level;
  expectVector(level.gravityInBody(), {0.0, 0.0, 1.0}, 0.0, "level");
  // +90° about x: the body's y axis comes up, so gravity's specific force reads +1 g on y.
  AttitudeIntegrator about_x;
  for (int i = 0; i < 1000; ++i) about_x.step({9.0, 0.0, 0.0}, 0.01);
  expectVector(about_x.gravityInBody(), {0.0, 1.0, 0.0}, 1e-12, "90 deg about x");
  // +90° about y: the body's x axis points down, so gravity reads −1 g on x.
  AttitudeIntegrator about_y;
  for (int i = 0; i < 1000; ++i) about_y.step({0.0, 9.0, 0.0}, 0.01);
  expectVector(about_y.gravityInBody(), {-1.0, 0.0, 0.0}, 1e-12, "90 deg about y");
  // About the vertical nothing changes.
  AttitudeIntegrator about_z;
  for (int i = 0; i < 1000; ++i) about_z.step({0.0, 0.0, 31.0}, 0.01);
  expectVector(about_z.gravityInBody(), {0.0, 0.0, 1.0}, 1e-12, "about z");
}

TEST(AttitudeIntegrator, BodyRatesComposeInTheBodyFrame) {
  // 90° about x, then 90° about the (new) body z, against the matrices:
  // R = Rx(90)·Rz(90); f_b = Rᵀ·e_z = Rz(90)ᵀ·Rx(90)ᵀ·e_z = Rz(−90)·(0, 1, 0) = (1, 0, 0).
  AttitudeIntegrator a;
  a.step({90.0, 0.0, 0.0}, 1.0);
  a.step({0.0, 0.0, 90.0}, 1.0);
  expectVector(a.gravityInBody(), {1.0, 0.0, 0.0}, 1e-12, "x then z");
  // A constant rate is integrated exactly: one big step equals many small ones.
  AttitudeIntegrator one, many;
  one.step({3.0, -4.0, 12.0}, 10.0);
  for (int i = 0; i < 10000; ++i) many.step({3.0, -4.0, 12.0}, 1e-3);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(one.quaternion()[k], many.quaternion()[k], 1e-10);
  // Large steps (beyond portable::tan's range for a single piece) still work.
  AttitudeIntegrator big;
  big.step({720.0, 0.0, 0.0}, 1.0);  // two whole turns
  expectVector(big.gravityInBody(), {0.0, 0.0, 1.0}, 1e-12, "two turns");
}

TEST(AttitudeIntegrator, StaysAUnitQuaternionOverALongRun) {
  AttitudeIntegrator a;
  for (int i = 0; i < 200000; ++i) a.step({37.0 * std::sin(i * 1e-3), 11.0, -23.0 * std::cos(i * 7e-4)}, 1e-3);
  const auto& q = a.quaternion();
  EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-14);
  const auto g = a.gravityInBody();
  EXPECT_NEAR(g[0] * g[0] + g[1] * g[1] + g[2] * g[2], 1.0, 1e-14);
}

TEST(AccelSimulation, TheGyroStreamIsTheSameBitsWithOrWithoutAccel) {
  for (bool with_motion : {false, true}) {
    SimulationModel without = chipModel();
    SimulationModel with = without;
    with.accel = whiteAccel(4e-4);
    with.accel->axes[1].bias_instability_g = 1e-4;
    with.accel->axes[2].acceleration_random_walk_g_per_sqrt_s = 1e-4;
    const MotionProfile motion = MotionProfile::sine(0, 0.5, 30.0);
    NoiseSimulator a = with_motion ? NoiseSimulator(without, 100.0, 42, motion) : NoiseSimulator(without, 100.0, 42);
    NoiseSimulator b = with_motion ? NoiseSimulator(with, 100.0, 42, motion) : NoiseSimulator(with, 100.0, 42);
    for (int i = 0; i < 10000; ++i) {
      const SimulatedSample x = a.next();
      const SimulatedSample y = b.next();
      for (int k = 0; k < 3; ++k) ASSERT_EQ(x.rate_dps[k], y.rate_dps[k]) << "sample " << i;
      ASSERT_EQ(x.temperature_c, y.temperature_c);
      ASSERT_TRUE(std::isnan(x.accel_g[0]));
      ASSERT_TRUE(std::isfinite(y.accel_g[0]) && std::isfinite(y.accel_g[1]) && std::isfinite(y.accel_g[2]));
    }
  }
}

TEST(AccelSimulation, AtRestItIsGravityPlusBiasPlusWhiteNoiseOfTheStatedDensity) {
  SimulationModel m;
  m.rate_hz = 200.0;
  m.accel = whiteAccel(4e-4);  // the product spec's 400 µg/√Hz: σ = N·√rate = 5.66 mg
  m.accel->axes[0].bias_g = 0.03;
  NoiseSimulator sim(m, 500.0, 3);
  std::array<std::vector<double>, 3> a;
  for (std::size_t i = 0; i < sim.sampleCount(); ++i) {
    const SimulatedSample s = sim.next();
    for (int k = 0; k < 3; ++k) a[k].push_back(s.accel_g[k]);
  }
  const std::array<double, 3> want = {0.03, 0.0, 1.0};
  const double sigma = 4e-4 * std::sqrt(200.0);
  for (int k = 0; k < 3; ++k) {
    const double n = static_cast<double>(a[k].size());
    const double mean = std::accumulate(a[k].begin(), a[k].end(), 0.0) / n;
    double var = 0.0;
    for (double v : a[k]) var += (v - mean) * (v - mean);
    var /= n - 1.0;
    EXPECT_NEAR(mean, want[k], 5.0 * sigma / std::sqrt(n)) << "axis " << k;
    EXPECT_NEAR(std::sqrt(var), sigma, 0.02 * sigma) << "axis " << k;  // 1e5 samples: ±0.2 % (1σ)
    // White noise: σ²(τ) = N²/τ at τ = 1 s (m = 200).
    const double avar = overlappingAllanVariance(a[k], 200);
    EXPECT_NEAR(avar, 4e-4 * 4e-4, 0.15 * 4e-4 * 4e-4) << "axis " << k;
  }
}

TEST(AccelSimulation, BiasInstabilityAndRandomWalkFollowTheirAllanLaws) {
  SimulationModel m;
  m.rate_hz = 10.0;
  m.accel = AccelModel{};
  m.accel->axes[0].bias_instability_g = 1e-3;                     // flat σ² = (2 ln2/π)·B²
  m.accel->axes[1].acceleration_random_walk_g_per_sqrt_s = 1e-4;  // σ² = K²τ/3
  const double duration = 40000.0;
  NoiseSimulator sim(m, duration, 9);
  std::vector<double> x, y;
  for (std::size_t i = 0; i < sim.sampleCount(); ++i) {
    const SimulatedSample s = sim.next();
    x.push_back(s.accel_g[0]);
    y.push_back(s.accel_g[1]);
  }
  const double flat = 2.0 * std::numbers::ln2 / std::numbers::pi * 1e-6;
  for (std::size_t m_tau : {10u, 100u, 1000u}) {  // τ = 1, 10, 100 s
    EXPECT_NEAR(overlappingAllanVariance(x, m_tau) / flat, 1.0, 0.3) << "tau " << m_tau / 10.0;
    const double tau = static_cast<double>(m_tau) / 10.0;
    EXPECT_NEAR(overlappingAllanVariance(y, m_tau) / (1e-8 * tau / 3.0), 1.0, 0.3) << "tau " << tau;
  }
}

TEST(AccelSimulation, AQuarterTurnTiltsGravityAndTheNoiseStaysOnTop) {
  SimulationModel m = chipModel();
  m.accel = whiteAccel(1e-4);
  // 9 °/s about x for 10 s from t = 2 s: a quarter turn.
  NoiseSimulator sim(m, 20.0, 5, MotionProfile::constant(0, 9.0, 2.0, 10.0));
  std::array<double, 3> before{}, after{};
  int nb = 0, na = 0;
  for (std::size_t i = 0; i < sim.sampleCount(); ++i) {
    const SimulatedSample s = sim.next();
    if (s.t_s < 2.0) {
      for (int k = 0; k < 3; ++k) before[k] += s.accel_g[k];
      ++nb;
    } else if (s.t_s >= 12.5) {
      for (int k = 0; k < 3; ++k) after[k] += s.accel_g[k];
      ++na;
    }
  }
  for (int k = 0; k < 3; ++k) {
    before[k] /= nb;
    after[k] /= na;
  }
  expectVector(before, {0.0, 0.0, 1.0}, 5e-4, "before");
  expectVector(after, {0.0, 1.0, 0.0}, 5e-4, "after the quarter turn");
}

TEST(AccelSimulation, QuantisedAtTheRangeAndSaturatedLikeTheChip) {
  for (int afs : {0, 2}) {
    SimulationModel m = chipModel();
    m.accel = whiteAccel(4e-4);
    m.accel->afs_sel = afs;
    m.accel->axes[0].bias_g = 100.0;  // beyond any range
    NoiseSimulator sim(m, 10.0, 1);
    const double lsb = 16384.0 / (1 << afs);
    for (int i = 0; i < 500; ++i) {
      const SimulatedSample s = sim.next();
      EXPECT_EQ(s.accel_g[0], 32767.0 / lsb);
      for (int k = 1; k < 3; ++k) {
        const double counts = s.accel_g[k] * lsb;
        ASSERT_EQ(counts, std::round(counts)) << "afs " << afs;
      }
    }
  }
}

TEST(AccelSimulation, BadAccelModelsNameTheParameter) {
  const auto message = [](SimulationModel m) -> std::string {
    try {
      validateSimulationModel(m);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  SimulationModel m;
  m.accel = AccelModel{};
  EXPECT_EQ(message(m), "");
  m.accel->afs_sel = 4;
  EXPECT_NE(message(m).find("accel.afs_sel"), std::string::npos) << message(m);
  m.accel->afs_sel = 0;
  m.accel->axes[2].velocity_random_walk_g_per_sqrt_hz = -1.0;
  EXPECT_NE(message(m).find("accel axis z: velocity_random_walk_g_per_sqrt_hz"), std::string::npos) << message(m);
  m.accel->axes[2].velocity_random_walk_g_per_sqrt_hz = 0.0;
  m.accel->axes[1].bias_g = std::nan("");
  EXPECT_NE(message(m).find("accel axis y: bias_g"), std::string::npos) << message(m);
}
