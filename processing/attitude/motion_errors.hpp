#pragma once
// The errors only motion reveals, learned from the inclination correction: the gyro's
// sensitivity matrix (each axis's scale error and the cross-axis terms between axes), the
// accelerometer's lever arm (its offset from the centre the board turns about) and its delay
// behind the gyro.
//
// Gyro: a rate read as ω_m = (I + S)·ω + b and corrected as ω̂ = ω_m − b̂ − Ŝ·ω_m turns the
// quasi-inertial frame q_g at the error rate ε_I = R_g·((S − Ŝ)·ω_m + b − b̂), to first order.
// S is taken symmetric: its antisymmetric part is a rotation of the gyro's axes against the
// accelerometer's, which tilts the estimate by a bounded angle, while a symmetric part turns a
// coning motion into a steady drift (as a scale error turns a spin into one), which is what the
// heading cannot afford.
// Accelerometer: a sensor r away from the centre of a turn reads, beside gravity and the
// centre's own acceleration, K·r with K = [ω]×² + [α]× (centripetal and tangential); and an
// accel that lags the gyro by δ reads f(t − δ) ≈ f + δ·ω×f of a vector fixed in the world, which
// in the world frame is gravity tilted by δ·(R_g·ω) × g. The estimator reads a − K·r̂ − δ̂·ω×a;
// what remains, R_g·K·(r − r̂) and (δ − δ̂)·(R_g·ω) × z [g], tilts the gravity it low-passes.
//
// The gravity low-pass L sees both tilts and the inclination correction undoes them: its
// rotation vector c per step (world frame, horizontal) is
//
//   c/Δt = −R_c·L[ε_I] + J·R_c·Δ(L[R_g·K]·r − L[R_g·K·r̂] + (δ − δ̂)·L[R_g·ω] × z)/(g·Δt),
//   J·(x, y, z) = (y, −x)
//
// (the second term: a horizontal acceleration d [g] is undone by the rotation J·d). With the
// estimates actually applied as known terms, that is linear in θ = (S, b, r, δ): two equations a
// sample, solved by a Kalman filter on θ. The regressors pass through the same low-pass as
// gravity, so the lag between a turn and the correction it causes is modelled rather than left
// in the noise. Ŝ, r̂ and δ̂ are applied; b is the bias the regression needs beside them, which
// the attitude estimator sets to its rest mean while the board rests (it keeps its own).
//
// Why: the MPU6050's gyro sensitivity is specified to ±3 % and its cross-axis sensitivity to
// ±2 % (datasheet): a 1 % scale error turns a 360° turn into a 3.6° heading error, and 0.2 % of
// cross-axis coupling drifts the heading by degrees a minute while the board cones at 100 °/s,
// neither of which any filter sees at rest. A board turned about a point 20 cm away at 400 °/s
// reads 1 g of centripetal acceleration, which a gravity low-pass takes for tilt. And an accel
// 5 ms behind the gyro (another chip, samples paired across reads; inside the MPU6050 the two
// low-pass filters differ by up to 1 ms) tilts the estimate by 0.5° while it turns at 100 °/s.
#include <array>

#include "processing/attitude/quaternion.hpp"

namespace gyrod::processing::attitude {

struct MotionErrorParameters {
  double sensitivity_initial_std = 0.03;              // prior σ of each gyro axis's sensitivity error
  double cross_axis_initial_std = 0.02;               // prior σ of each cross-axis term
  double sensitivity_limit = 0.05;                    // |ŝ| is held below
  double lever_arm_initial_std_m = 0.1;               // prior σ of each lever-arm component
  double lever_arm_random_walk_m_per_sqrt_s = 0.001;  // a grip that shifts
  double lever_arm_limit_m = 0.5;                     // |r̂| per component is held below
  double bias_initial_std_rad_s = 0.02;               // prior σ of b
  double bias_random_walk_rad_s_per_sqrt_s = 1e-4;
  double accel_delay_initial_std_s = 0.01;  // prior σ of the accel's delay behind the gyro
  double accel_delay_limit_s = 0.05;        // |δ̂| is held below
  double correction_noise_density = 0.015;  // c/Δt's noise [rad/s/√Hz]: what no state explains
};

// A second-order section's coefficients (transposed direct form II, a0 = 1).
struct LowpassCoefficients {
  double b0 = 0.0, b1 = 0.0, b2 = 0.0, a1 = 0.0, a2 = 0.0;
};

// Which of the errors are learned; the others stay zero.
struct LearnedMotionErrors {
  bool sensitivity = true;  // each axis's scale error, the diagonal of S
  bool cross_axis = true;   // the off-diagonal of S
  bool lever_arm = true;
  bool accel_delay = true;
};

class MotionErrorEstimator {
 public:
  MotionErrorEstimator() = default;
  // Throws std::invalid_argument naming a parameter out of range.
  MotionErrorEstimator(const MotionErrorParameters& params, const LowpassCoefficients& lowpass, double rate_hz,
                       const LearnedMotionErrors& learned);
  void reset();
  // After the strapdown step: q_g, the measured rate and the bias applied [rad/s], and this
  // sample's accel [g]. Returns K·r̂ + δ̂·ω×a [g], to take off the accel.
  Vector3 propagate(const Quaternion& q_gyro, const Vector3& rate_rad_s, const Vector3& bias_rad_s,
                    const Vector3& accel_g);
  // After the inclination correction: its rotation vector's world x and y [rad], q_c, and a
  // weight in (0, 1] that divides the measurement's variance.
  void update(const Quaternion& q_correction, double cx, double cy, double weight);
  // While the board rests: the regression's bias is the rest mean [rad/s], which is known far
  // better than the motion can tell it.
  void setBias(const Vector3& bias_rad_s);
  // ŝ per sensor axis (0.01: the axis reads 1 % high), the diagonal of Ŝ.
  Vector3 sensitivityError() const { return {sensitivity_[0][0], sensitivity_[1][1], sensitivity_[2][2]}; }
  // Ŝ's cross-axis terms (xy, xz, yz): axis x reads xy of the rate about y, and y as much of x's.
  Vector3 crossAxis() const { return {sensitivity_[0][1], sensitivity_[0][2], sensitivity_[1][2]}; }
  const std::array<Vector3, 3>& sensitivityMatrix() const { return sensitivity_; }
  // r̂ [m], sensor axes.
  const Vector3& leverArm() const { return lever_arm_; }
  // δ̂ [s]: how long the accel's sample lags the gyro's.
  double accelDelay() const { return accel_delay_s_; }

 private:
  // θ: S as (xx, yy, zz, xy, xz, yz), b 3, r 3, δ.
  static constexpr int kStates = 13;
  static constexpr int kBias = 6, kLever = 9, kDelay = 12;
  // Per world axis i, S's regressors R_g[i][j]·ω_j (diagonal) and R_g[i][j]·ω_k + R_g[i][k]·ω_j
  // (cross-axis) 18; L[R_g] 9; L[R_g·(Ŝ·ω + b̂)] 3; L[R_g·K]/g 9; L[R_g·(K·r̂ + δ̂·ω×a)] 3.
  static constexpr int kChannels = 42;
  static constexpr int kBiasChannels = 18, kAppliedChannels = 27;
  static constexpr int kLeverChannels = 30;  // the first of the last twelve
  Vector3 turnLowpass() const;
  MotionErrorParameters p_;
  LowpassCoefficients lp_;
  double dt_ = 0.0;
  LearnedMotionErrors learned_;
  double measurement_variance_ = 0.0;
  std::array<double, kStates> process_variance_{};
  std::array<double, kChannels> s1_{}, s2_{}, out_{};
  std::array<double, kChannels - kLeverChannels> previous_lever_out_{};
  Vector3 previous_rate_{};
  Vector3 previous_turn_{};  // L[R_g·ω] of the previous sample
  bool primed_ = false;
  std::array<double, kStates> theta_{};
  std::array<std::array<double, kStates>, kStates> cov_{};
  std::array<Vector3, 3> sensitivity_{};  // Ŝ, symmetric
  Vector3 lever_arm_{};
  double accel_delay_s_ = 0.0;
};

}  // namespace gyrod::processing::attitude
