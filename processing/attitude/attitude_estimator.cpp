#include "processing/attitude/attitude_estimator.hpp"

#include <cmath>

#include "processing/attitude/parameter_check.hpp"

namespace gyrod::processing::attitude {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
constexpr double kRestLowpassTimeConstantS = 0.5;

double norm(const Vector3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

}  // namespace

AttitudeEstimator::AttitudeEstimator(const AttitudeParameters& params) : p_(params) {
  requirePositiveParameter(p_.rate_hz, "rate_hz");
  requirePositiveParameter(p_.accel_time_constant_s, "accel_time_constant_s");
  requirePositiveParameter(p_.accel_norm_scale_g, "accel_norm_scale_g");
  requirePositiveParameter(p_.rest_bias_time_constant_s, "rest_bias_time_constant_s");
  requirePositiveParameter(p_.motion_bias_time_constant_s, "motion_bias_time_constant_s");
  requirePositiveParameter(p_.rest_gyro_deviation_dps, "rest_gyro_deviation_dps");
  requirePositiveParameter(p_.rest_accel_deviation_g, "rest_accel_deviation_g");
  requirePositiveParameter(p_.rest_duration_s, "rest_duration_s");
  requirePositiveParameter(p_.bias_limit_dps, "bias_limit_dps");
  for (double v : {p_.gyro_angle_random_walk_dps_per_sqrt_hz, p_.gyro_rate_random_walk_dps_per_sqrt_s,
                   p_.accel_noise_density_g_per_sqrt_hz, p_.initial_bias_std_dps})
    requireNonNegativeParameter(v, "noise terms");
  dt_ = 1.0 / p_.rate_hz;
  rest_alpha_ = 1.0 - std::exp(-dt_ / kRestLowpassTimeConstantS);
  rest_bias_alpha_ = 1.0 - std::exp(-dt_ / p_.rest_bias_time_constant_s);
  rest_bias_variance_alpha_ = 1.0 - std::exp(-2.0 * dt_ / p_.rest_bias_time_constant_s);
  // Bilinear transform of the analog Butterworth pair at fc = √2/(2π·τ).
  const double fc = std::sqrt(2.0) / (2.0 * kPi * p_.accel_time_constant_s);
  const double c = std::tan(kPi * fc * dt_);
  const double d = c * c + std::sqrt(2.0) * c + 1.0;
  lp_b0_ = c * c / d;
  lp_b1_ = 2.0 * lp_b0_;
  lp_b2_ = lp_b0_;
  lp_a1_ = 2.0 * (c * c - 1.0) / d;
  lp_a2_ = (1.0 - std::sqrt(2.0) * c + c * c) / d;
  const double arw = p_.gyro_angle_random_walk_dps_per_sqrt_hz * kDegToRad;
  bias_variance_rest_ = arw * arw / (2.0 * p_.rest_bias_time_constant_s);
  motion_errors_ = MotionErrorEstimator(
      p_.motion_errors, {lp_b0_, lp_b1_, lp_b2_, lp_a1_, lp_a2_}, p_.rate_hz,
      {p_.estimate_sensitivity, p_.estimate_cross_axis, p_.estimate_lever_arm, p_.estimate_accel_delay});
  reset();
}

void AttitudeEstimator::reset() {
  q_gyro_ = kIdentityQuaternion;
  q_correction_ = kIdentityQuaternion;
  accel_lowpass_ = {};
  lp_s1_ = {};
  lp_s2_ = {};
  started_ = false;
  bias_rad_s_ = {};
  motion_errors_.reset();
  rest_rate_mean_ = {};
  rest_accel_mean_ = {};
  rest_time_s_ = 0.0;
  rest_ = false;
  bias_known_ = false;
  const double b0 = p_.estimate_bias ? p_.initial_bias_std_dps * kDegToRad : 0.0;
  bias_variance_ = b0 * b0;
  heading_arw_variance_ = 0.0;
  heading_bias_drift_ = 0.0;
}

// The rest test: the rate and the accel within their bounds of their 0.5 s low-pass and that
// low-passed rate below bias_limit_dps, for rest_duration_s without a break.
void AttitudeEstimator::updateRest(const Vector3& rate_dps, const Vector3& accel_g) {
  if (!started_) {
    rest_rate_mean_ = rate_dps;
    rest_accel_mean_ = accel_g;
  }
  double rate_dev2 = 0.0, accel_dev2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    rest_rate_mean_[i] += rest_alpha_ * (rate_dps[i] - rest_rate_mean_[i]);
    rest_accel_mean_[i] += rest_alpha_ * (accel_g[i] - rest_accel_mean_[i]);
    rate_dev2 += (rate_dps[i] - rest_rate_mean_[i]) * (rate_dps[i] - rest_rate_mean_[i]);
    accel_dev2 += (accel_g[i] - rest_accel_mean_[i]) * (accel_g[i] - rest_accel_mean_[i]);
  }
  // A steady turn passes the deviation tests; a mean rate beyond any bias the estimator accepts
  // is motion.
  const double mean_rate2 = rest_rate_mean_[0] * rest_rate_mean_[0] + rest_rate_mean_[1] * rest_rate_mean_[1] +
                            rest_rate_mean_[2] * rest_rate_mean_[2];
  const bool quiet = mean_rate2 < p_.bias_limit_dps * p_.bias_limit_dps &&
                     rate_dev2 < p_.rest_gyro_deviation_dps * p_.rest_gyro_deviation_dps &&
                     accel_dev2 < p_.rest_accel_deviation_g * p_.rest_accel_deviation_g;
  rest_time_s_ = quiet ? rest_time_s_ + dt_ : 0.0;
  rest_ = rest_time_s_ >= p_.rest_duration_s;
  if (rest_) bias_known_ = true;
}

Vector3 AttitudeEstimator::correctInclination(const Vector3& accel_g, double weight) {
  const Vector3 a_inertial = rotate(q_gyro_, accel_g);
  if (!started_) {
    // The first sample sets roll and pitch from the accel and heading 0 (Z-Y-X Euler):
    // q_c = Ry(pitch) ⊗ Rx(roll), with q_g = identity, ā_I = a.
    accel_lowpass_ = a_inertial;
    for (int i = 0; i < 3; ++i) {  // the steady state of a constant input
      lp_s2_[i] = (lp_b2_ - lp_a2_) * a_inertial[i];
      lp_s1_[i] = (lp_b1_ - lp_a1_) * a_inertial[i] + lp_s2_[i];
    }
    const double roll = std::atan2(accel_g[1], accel_g[2]);
    const double pitch = std::atan2(-accel_g[0], std::sqrt(accel_g[1] * accel_g[1] + accel_g[2] * accel_g[2]));
    q_correction_ = multiply(fromRotationVector({0.0, pitch, 0.0}), fromRotationVector({roll, 0.0, 0.0}));
    return {};
  }
  for (int i = 0; i < 3; ++i) {
    const double x = a_inertial[i];
    const double y = lp_b0_ * x + lp_s1_[i];
    lp_s1_[i] = lp_b1_ * x - lp_a1_ * y + lp_s2_[i];
    lp_s2_[i] = lp_b2_ * x - lp_a2_ * y;
    accel_lowpass_[i] = y;
  }
  Vector3 v = rotate(q_correction_, accel_lowpass_);
  const double n = norm(v);
  if (!(n > 0.0)) return {};
  for (double& c : v) c /= n;
  // The rotation by acos(v_z) about v × z = (v_y, −v_x, 0), which turns v to +z.
  const double w = std::sqrt(0.5 * (1.0 + v[2]));
  if (w < 1e-6) return {};  // upside down: the axis is undefined; the next sample decides
  const Quaternion step{w, 0.5 * v[1] / w, -0.5 * v[0] / w, 0.0};
  q_correction_ = normalized(multiply(step, q_correction_));
  // c = 2·(x, y, 0) of the step (small angle), world frame.
  const Vector3 c{2.0 * step[1], 2.0 * step[2], 0.0};
  if (p_.estimate_bias && !rest_) {
    // c into the sensor frame.
    const Quaternion q = multiply(q_correction_, q_gyro_);
    const Vector3 c_sensor = rotateInverse(q, c);
    const double gain = weight / p_.motion_bias_time_constant_s;
    for (int i = 0; i < 3; ++i) bias_rad_s_[i] -= gain * c_sensor[i];
  }
  return c;
}

AttitudeSample AttitudeEstimator::update(const Vector3& rate_dps, const Vector3& accel_g) {
  const bool accel_ok = std::isfinite(accel_g[0]) && std::isfinite(accel_g[1]) && std::isfinite(accel_g[2]);
  if (p_.estimate_bias && accel_ok) {
    updateRest(rate_dps, accel_g);
    if (rest_)
      for (int i = 0; i < 3; ++i) bias_rad_s_[i] += rest_bias_alpha_ * (rate_dps[i] * kDegToRad - bias_rad_s_[i]);
  }
  if (p_.estimate_bias) {
    const double limit = p_.bias_limit_dps * kDegToRad;
    const double b = norm(bias_rad_s_);
    if (b > limit)
      for (double& c : bias_rad_s_) c *= limit / b;
  }

  Vector3 r, rate_rad_s;
  for (int i = 0; i < 3; ++i) rate_rad_s[i] = rate_dps[i] * kDegToRad;
  const auto& s_hat = motion_errors_.sensitivityMatrix();
  for (int i = 0; i < 3; ++i) {
    const double error = s_hat[i][0] * rate_rad_s[0] + s_hat[i][1] * rate_rad_s[1] + s_hat[i][2] * rate_rad_s[2];
    r[i] = (rate_rad_s[i] - error - bias_rad_s_[i]) * dt_;
  }
  if (started_) q_gyro_ = normalized(multiply(q_gyro_, fromRotationVector(r)));
  // The motion errors are learned from the corrections that follow the first sample, once the
  // bias is known (a rate already corrected, or a first rest): an unknown bias turns the
  // quasi-inertial frame as a sensitivity error would, and would be learned as one. Until then,
  // and while the board rests, the regression's own bias is the rest mean.
  const bool learn =
      (p_.estimate_sensitivity || p_.estimate_cross_axis || p_.estimate_lever_arm || p_.estimate_accel_delay) &&
      started_ && (bias_known_ || !p_.estimate_bias);
  if (!learn || rest_) motion_errors_.setBias(bias_rad_s_);
  Vector3 accel = accel_g;
  if (learn) {  // K·r̂ + δ̂·ω×a off the accel: what is left is gravity and the centre's own acceleration
    const Vector3 lever = motion_errors_.propagate(q_gyro_, rate_rad_s, bias_rad_s_, accel_ok ? accel_g : Vector3{});
    for (int i = 0; i < 3; ++i) accel[i] -= lever[i];
  }

  if (accel_ok) {
    const double deviation = (norm(accel) - 1.0) / p_.accel_norm_scale_g;
    const double weight = 1.0 / (1.0 + deviation * deviation);
    const Vector3 c = correctInclination(accel, weight);
    started_ = true;
    if (learn) motion_errors_.update(q_correction_, c[0], c[1], weight);
  }

  // The 1σ bookkeeping.
  const double arw = p_.gyro_angle_random_walk_dps_per_sqrt_hz * kDegToRad;
  const double rrw = p_.gyro_rate_random_walk_dps_per_sqrt_s * kDegToRad;
  if (p_.estimate_bias) {
    if (rest_)  // the rest mean's error decays as e^{−t/T_rest}, its variance at twice that rate
      bias_variance_ += rest_bias_variance_alpha_ * (bias_variance_rest_ - bias_variance_);
    else
      bias_variance_ += rrw * rrw * dt_;
  }
  heading_arw_variance_ += arw * arw * dt_;
  heading_bias_drift_ += std::sqrt(bias_variance_) * dt_;
  return output();
}

AttitudeSample AttitudeEstimator::output() const {
  constexpr double kRadToDeg = 1.0 / kDegToRad;
  AttitudeSample s;
  s.q = multiply(q_correction_, q_gyro_);
  if (s.q[0] < 0.0)
    for (double& c : s.q) c = -c;  // one sign for the same rotation: w ≥ 0
  const EulerAngles e = eulerAngles(s.q);
  s.roll_deg = e.roll * kRadToDeg;
  s.pitch_deg = e.pitch * kRadToDeg;
  s.heading_deg = e.heading * kRadToDeg;
  const double tau = p_.accel_time_constant_s;
  const double na = p_.accel_noise_density_g_per_sqrt_hz;
  const double arw = p_.gyro_angle_random_walk_dps_per_sqrt_hz * kDegToRad;
  const double incl_var = na * na / (2.0 * tau) + arw * arw * tau / 2.0 + bias_variance_ * tau * tau;
  s.inclination_std_deg = std::sqrt(incl_var) * kRadToDeg;
  s.heading_std_deg = std::sqrt(heading_arw_variance_ + heading_bias_drift_ * heading_bias_drift_) * kRadToDeg;
  for (int i = 0; i < 3; ++i) s.bias_dps[i] = bias_rad_s_[i] * kRadToDeg;
  s.gyro_sensitivity_error = motion_errors_.sensitivityError();
  s.gyro_cross_axis = motion_errors_.crossAxis();
  s.accel_delay_s = motion_errors_.accelDelay();
  s.lever_arm_m = motion_errors_.leverArm();
  s.rest = rest_;
  return s;
}

}  // namespace gyrod::processing::attitude
