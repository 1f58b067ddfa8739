#pragma once
// The errors only motion reveals, learned from the inclination correction: each gyro axis's
// sensitivity error and the accelerometer's lever arm (its offset from the centre the board
// turns about).
//
// Gyro: a rate read as ω_m = (1 + s)⊙ω + b and corrected as ω̂ = ω_m − b̂ − ŝ⊙ω_m turns the
// quasi-inertial frame q_g at the error rate ε_I = R_g·((s − ŝ)⊙ω_m + b − b̂), to first order.
// Accelerometer: a sensor r away from the centre of a turn reads, beside gravity and the
// centre's own acceleration, K·r with K = [ω]×² + [α]× (centripetal and tangential); the
// estimator reads a − K·r̂. What remains, R_g·K·(r − r̂), tilts the gravity it low-passes.
//
// The gravity low-pass L sees both tilts and the inclination correction undoes them: its
// rotation vector c per step (world frame, horizontal) is
//
//   c/Δt = −R_c·L[ε_I] + J·R_c·Δ(L[R_g·K]·r − L[R_g·K·r̂])/(g·Δt),   J·(x, y, z) = (y, −x)
//
// (the second term: a horizontal acceleration d [g] is undone by the rotation J·d). With the
// estimates actually applied as known terms, that is linear in θ = (s, b, r): two equations a
// sample, solved by a Kalman filter on θ. The regressors pass through the same low-pass as
// gravity, so the lag between a turn and the correction it causes is modelled rather than left
// in the noise. ŝ and r̂ are applied; b is only the bias the regression needs beside them
// (the attitude estimator keeps its own, learned at rest).
//
// Why: the MPU6050's gyro sensitivity is specified to ±3 % (datasheet, initial calibration
// tolerance): a 1 % error turns a 360° turn into a 3.6° heading error that no filter sees at
// rest. And a board turned about a point 20 cm away at 400 °/s reads 1 g of centripetal
// acceleration, which a gravity low-pass takes for tilt.
#include <array>

#include "processing/attitude/quaternion.hpp"

namespace gyrod::processing::attitude {

struct MotionErrorParameters {
  double sensitivity_initial_std = 0.03;              // prior σ of each gyro axis's sensitivity error
  double sensitivity_limit = 0.05;                    // |ŝ| is held below
  double lever_arm_initial_std_m = 0.1;               // prior σ of each lever-arm component
  double lever_arm_random_walk_m_per_sqrt_s = 0.001;  // a grip that shifts
  double lever_arm_limit_m = 0.5;                     // |r̂| per component is held below
  double bias_initial_std_rad_s = 0.02;               // prior σ of b
  double bias_random_walk_rad_s_per_sqrt_s = 1e-4;
  double correction_noise_density = 0.015;  // c/Δt's noise [rad/s/√Hz]: what no state explains
};

// A second-order section's coefficients (transposed direct form II, a0 = 1).
struct LowpassCoefficients {
  double b0 = 0.0, b1 = 0.0, b2 = 0.0, a1 = 0.0, a2 = 0.0;
};

class MotionErrorEstimator {
 public:
  MotionErrorEstimator() = default;
  // Throws std::invalid_argument naming a parameter out of range.
  MotionErrorEstimator(const MotionErrorParameters& params, const LowpassCoefficients& lowpass, double rate_hz,
                       bool estimate_sensitivity, bool estimate_lever_arm);
  void reset();
  // After the strapdown step: q_g, the measured rate and the bias applied [rad/s]. Returns the
  // lever-arm acceleration K·r̂ [g] to take off this sample's accel.
  Vector3 propagate(const Quaternion& q_gyro, const Vector3& rate_rad_s, const Vector3& bias_rad_s);
  // After the inclination correction: its rotation vector's world x and y [rad], q_c, and a
  // weight in (0, 1] that divides the measurement's variance.
  void update(const Quaternion& q_correction, double cx, double cy, double weight);
  // ŝ per sensor axis (0.01: the axis reads 1 % high).
  const Vector3& sensitivityError() const { return sensitivity_; }
  // r̂ [m], sensor axes.
  const Vector3& leverArm() const { return lever_arm_; }

 private:
  static constexpr int kStates = 9;  // s 3, b 3, r 3
  // L[R_g·diag(ω)] 9, L[R_g] 9, L[R_g·(ŝ⊙ω + b̂)] 3, L[R_g·K]/g 9, L[R_g·K·r̂]/g 3
  static constexpr int kChannels = 33;
  static constexpr int kLeverChannels = 21;  // the first of the last twelve
  MotionErrorParameters p_;
  LowpassCoefficients lp_;
  double dt_ = 0.0;
  bool estimate_sensitivity_ = true, estimate_lever_arm_ = true;
  double measurement_variance_ = 0.0;
  std::array<double, kStates> process_variance_{};
  std::array<double, kChannels> s1_{}, s2_{}, out_{};
  std::array<double, kChannels - kLeverChannels> previous_lever_out_{};
  Vector3 previous_rate_{};
  bool primed_ = false;
  std::array<double, kStates> theta_{};
  std::array<std::array<double, kStates>, kStates> cov_{};
  Vector3 sensitivity_{}, lever_arm_{};
};

}  // namespace gyrod::processing::attitude
