#pragma once
// A 6-axis attitude estimator: the orientation q_ws (sensor → world, world z up, heading 0 at
// the first sample) from the angular rate and the accelerometer (docs/attitude.md).
//
//   q = q_c ⊗ q_g
//   q_g  the strapdown integral of the bias-corrected rate: q_g ← q_g ⊗ Exp((ω − b̂)·Δt), a
//        quasi-inertial frame that drifts only as slowly as the residual bias;
//   a_I  the accelerometer rotated into that frame, R(q_g)·a, through a second-order
//        Butterworth low-pass of cutoff √2/(2π·τ) (VQF's choice: −40 dB/decade keeps a hand's
//        1 Hz accelerations out far better than a first-order filter of the same delay). Every
//        sample enters with the same weight: a weight that depends on |a| makes the weighted
//        mean of a linear acceleration nonzero (acceleration along gravity raises |a|, across
//        it hardly), and on BROAD's fast translation trial that bias tilted the estimate by
//        tens of degrees (docs/attitude.md);
//   q_c  the inclination correction: after each step the smallest rotation about a horizontal
//        axis that turns R(q_c)·ā_I to +z, applied in full (the low-pass sets the time scale),
//        so q_c never turns about world z and the heading is the gyro's alone. The first
//        sample sets q_c to the accel's roll and pitch with heading 0 (Z-Y-X Euler angles).
// Low-passing in the quasi-inertial frame rather than the sensor frame keeps the filter's
// delay off the rotation itself: a rotating sensor's gravity moves in the sensor frame but
// stays put in that frame.
//
// The gyro bias b̂ (sensor frame), when estimate_bias is set:
//   at rest (the rate and the accel stay within rest_* of their 0.5 s low-pass, and that
//   low-passed rate below bias_limit_dps, for rest_duration_s; a steady turn slower than
//   bias_limit_dps is taken for rest and learned as bias): b̂ ← b̂ + (ω − b̂)·Δt/T_rest, the rest mean of the raw rate;
//   in motion: a residual bias e turns q_g by R(q)·e·Δt a step, which the inclination correction
//   undoes about the horizontal axes: the correction's rotation vector c (world, z = 0)
//   estimates −R(q)·e·Δt, so b̂ ← b̂ − w·R(q)ᵀ·c/T_motion: an integral term that learns the
//   components of the bias that are horizontal at the time, and, as the sensor turns, the
//   vertical one too. w = 1/(1 + ((|a| − 1 g)/s)²) weights the sample by how far its norm is
//   from 1 g (linear acceleration, taps, vibration): a correction made while the accel was
//   disturbed says little about the bias. |b̂| is held below bias_limit_dps.
// With estimate_bias unset (a rate already bias-corrected, e.g. gyrod's `rate` stream), b̂ = 0.
//
// Motion errors (processing/attitude/motion_errors.hpp), when the estimate_* below are set: the
// gyro's symmetric sensitivity matrix Ŝ (each axis's scale error and the cross-axis terms),
// applied as ω̂ = ω − b̂ − Ŝ·ω; the accel's lever arm r̂ from the centre of rotation, whose
// acceleration K·r̂ (centripetal and tangential) is taken off the accel before the low-pass; and
// the accel's delay δ̂ behind the gyro, taken off as δ̂·ω×a; all learned by a Kalman filter from
// the same inclination corrections.
//
// Uncertainty (1σ, radians internally, degrees in AttitudeSample):
//   inclination σ² = N_a²/(2τ) + N_g²·τ/2 + (σ_b·τ)²: the steady state of the first-order
//     complementary filter, accel white noise N_a [g/√Hz ≈ rad/√Hz] through the low-pass,
//     gyro angle random walk N_g through its complement, a residual bias σ_b for τ;
//   heading σ² = N_g²·t + (∫σ_b dt)²: the angle random walk and the residual bias (fully
//     correlated in time) integrated from the start; σ_b² starts at initial_bias_std_dps²,
//     relaxes to N_g²/(2·T_rest) at rest (as e^{−2t/T_rest}) and grows by K_g²·Δt (rate random walk) otherwise.
//
// update() allocates nothing and is O(1).
#include <cstddef>

#include "processing/attitude/motion_errors.hpp"
#include "processing/attitude/quaternion.hpp"

namespace gyrod::processing::attitude {

struct AttitudeParameters {
  double rate_hz = 0.0;
  double accel_time_constant_s = 3.0;  // τ
  double accel_norm_scale_g = 0.1;     // s: a sample |a| − 1 g = s away counts half
  bool estimate_bias = true;
  double rest_bias_time_constant_s = 2.0;     // T_rest
  double motion_bias_time_constant_s = 60.0;  // T_motion
  double rest_gyro_deviation_dps = 2.0;       // rest: |ω − ω̄| stays below
  double rest_accel_deviation_g = 0.05;       // rest: |a − ā| stays below
  double rest_duration_s = 1.5;               // for at least this long
  double bias_limit_dps = 5.0;
  bool estimate_sensitivity = true;  // the gyro's sensitivity error per axis, learned in motion
  bool estimate_cross_axis = true;   // the gyro's cross-axis sensitivity (symmetric)
  bool estimate_lever_arm = true;    // the accel's offset from the centre of rotation
  bool estimate_accel_delay = true;  // how long the accel's sample lags the gyro's
  MotionErrorParameters motion_errors{};
  // Noise terms for the 1σ (defaults: an MPU6050's datasheet figures).
  double gyro_angle_random_walk_dps_per_sqrt_hz = 0.005;  // N_g
  double gyro_rate_random_walk_dps_per_sqrt_s = 1e-4;     // K_g
  double accel_noise_density_g_per_sqrt_hz = 400e-6;      // N_a
  double initial_bias_std_dps = 1.0;                      // σ_b at the start
};

struct AttitudeSample {
  Quaternion q{kIdentityQuaternion};  // q_ws
  double roll_deg = 0.0, pitch_deg = 0.0, heading_deg = 0.0;
  double inclination_std_deg = 0.0;  // 1σ of the inclination (roll/pitch) error
  double heading_std_deg = 0.0;      // 1σ of the heading change since the first sample
  Vector3 bias_dps{};                // b̂, sensor frame
  Vector3 gyro_sensitivity_error{};  // ŝ per sensor axis (0.01: reads 1 % high)
  Vector3 gyro_cross_axis{};         // Ŝ's xy, xz, yz: axis x reads xy of the rate about y, y as much of x's
  double accel_delay_s = 0.0;        // δ̂: the accel's sample lags the gyro's by this
  Vector3 lever_arm_m{};             // r̂, the accel's offset from the centre of rotation
  bool rest = false;
};

class AttitudeEstimator {
 public:
  // Throws std::invalid_argument naming a parameter out of range.
  explicit AttitudeEstimator(const AttitudeParameters& params);

  // One sample: rate [°/s] and accel [g], sensor axes. A non-finite accel skips the
  // inclination correction for that sample.
  AttitudeSample update(const Vector3& rate_dps, const Vector3& accel_g);
  void reset();
  const AttitudeParameters& parameters() const { return p_; }
  const MotionErrorEstimator& motionErrors() const { return motion_errors_; }

 private:
  void updateRest(const Vector3& rate_dps, const Vector3& accel_g);
  // Returns the correction's rotation vector (world frame, z = 0); zero when none was made.
  Vector3 correctInclination(const Vector3& accel_g, double weight);
  AttitudeSample output() const;

  AttitudeParameters p_;
  double dt_ = 0.0;
  double rest_alpha_ = 0.0;                // the 0.5 s low-pass of the rest test
  double rest_bias_alpha_ = 0.0;           // Δt/T_rest as a first-order step
  double rest_bias_variance_alpha_ = 0.0;  // the same for σ_b², 2Δt/T_rest
  double bias_variance_rest_ = 0.0;        // σ_b² that the rest mean reaches, (rad/s)²
  Quaternion q_gyro_{kIdentityQuaternion};
  Quaternion q_correction_{kIdentityQuaternion};
  // The Butterworth low-pass: coefficients and, per axis, the transposed direct form II state.
  double lp_b0_ = 0.0, lp_b1_ = 0.0, lp_b2_ = 0.0, lp_a1_ = 0.0, lp_a2_ = 0.0;
  Vector3 lp_s1_{}, lp_s2_{};
  Vector3 accel_lowpass_{};  // ā_I, the filter's output
  bool started_ = false;
  Vector3 bias_rad_s_{};
  MotionErrorEstimator motion_errors_;
  Vector3 rest_rate_mean_{}, rest_accel_mean_{};
  double rest_time_s_ = 0.0;
  bool rest_ = false;
  bool bias_known_ = false;            // a rest has been seen
  double bias_variance_ = 0.0;         // σ_b², (rad/s)²
  double heading_arw_variance_ = 0.0;  // N_g²·t
  double heading_bias_drift_ = 0.0;    // ∫σ_b dt
};

}  // namespace gyrod::processing::attitude
