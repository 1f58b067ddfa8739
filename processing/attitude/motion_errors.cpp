#include "processing/attitude/motion_errors.hpp"

#include <algorithm>
#include <cmath>

#include "processing/attitude/parameter_check.hpp"

namespace gyrod::processing::attitude {
namespace {

using Matrix3 = std::array<Vector3, 3>;
constexpr double kStandardGravity = 9.80665;  // m/s² per g

Matrix3 rotationMatrix(const Quaternion& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
           {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
           {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
}

// K = [ω]×² + [α]×: the acceleration of a point r from the centre of rotation is K·r.
Matrix3 leverArmMatrix(const Vector3& w, const Vector3& a) {
  const double xx = w[0] * w[0], yy = w[1] * w[1], zz = w[2] * w[2];
  return {{{-(yy + zz), w[0] * w[1] - a[2], w[0] * w[2] + a[1]},
           {w[0] * w[1] + a[2], -(xx + zz), w[1] * w[2] - a[0]},
           {w[0] * w[2] - a[1], w[1] * w[2] + a[0], -(xx + yy)}}};
}

}  // namespace

MotionErrorEstimator::MotionErrorEstimator(const MotionErrorParameters& params, const LowpassCoefficients& lowpass,
                                           double rate_hz, const LearnedMotionErrors& learned)
    : p_(params), lp_(lowpass), dt_(1.0 / rate_hz), learned_(learned) {
  requirePositiveParameter(p_.sensitivity_initial_std, "motion errors sensitivity_initial_std");
  requirePositiveParameter(p_.cross_axis_initial_std, "motion errors cross_axis_initial_std");
  requirePositiveParameter(p_.sensitivity_limit, "motion errors sensitivity_limit");
  requirePositiveParameter(p_.lever_arm_initial_std_m, "motion errors lever_arm_initial_std_m");
  requirePositiveParameter(p_.lever_arm_limit_m, "motion errors lever_arm_limit_m");
  requirePositiveParameter(p_.bias_initial_std_rad_s, "motion errors bias_initial_std_rad_s");
  requirePositiveParameter(p_.accel_delay_initial_std_s, "motion errors accel_delay_initial_std_s");
  requirePositiveParameter(p_.accel_delay_limit_s, "motion errors accel_delay_limit_s");
  requirePositiveParameter(p_.correction_noise_density, "motion errors correction_noise_density");
  requireNonNegativeParameter(p_.lever_arm_random_walk_m_per_sqrt_s, "motion errors lever_arm_random_walk");
  requireNonNegativeParameter(p_.bias_random_walk_rad_s_per_sqrt_s, "motion errors bias_random_walk");
  // White at the sample rate with this density: the information a second does not depend on
  // the rate.
  measurement_variance_ = p_.correction_noise_density * p_.correction_noise_density * rate_hz;
  for (int i = 0; i < 3; ++i) {
    process_variance_[kBias + i] = p_.bias_random_walk_rad_s_per_sqrt_s * p_.bias_random_walk_rad_s_per_sqrt_s * dt_;
    if (learned_.lever_arm)
      process_variance_[kLever + i] =
          p_.lever_arm_random_walk_m_per_sqrt_s * p_.lever_arm_random_walk_m_per_sqrt_s * dt_;
  }
  reset();
}

void MotionErrorEstimator::reset() {
  s1_ = {};
  s2_ = {};
  out_ = {};
  previous_lever_out_ = {};
  previous_rate_ = {};
  previous_turn_ = {};
  primed_ = false;
  theta_ = {};
  cov_ = {};
  const double s0 = p_.sensitivity_initial_std, x0 = p_.cross_axis_initial_std;
  for (int i = 0; i < 3; ++i) {
    if (learned_.sensitivity) cov_[i][i] = s0 * s0;
    if (learned_.cross_axis) cov_[3 + i][3 + i] = x0 * x0;
    cov_[kBias + i][kBias + i] = p_.bias_initial_std_rad_s * p_.bias_initial_std_rad_s;
    if (learned_.lever_arm) cov_[kLever + i][kLever + i] = p_.lever_arm_initial_std_m * p_.lever_arm_initial_std_m;
  }
  if (learned_.accel_delay) cov_[kDelay][kDelay] = p_.accel_delay_initial_std_s * p_.accel_delay_initial_std_s;
  sensitivity_ = {};
  lever_arm_ = {};
  accel_delay_s_ = 0.0;
}

void MotionErrorEstimator::setBias(const Vector3& bias_rad_s) {
  for (int i = 0; i < 3; ++i) theta_[kBias + i] = bias_rad_s[i];
}

Vector3 MotionErrorEstimator::propagate(const Quaternion& q_gyro, const Vector3& rate, const Vector3& bias,
                                        const Vector3& accel) {
  const Matrix3 r = rotationMatrix(q_gyro);
  Vector3 angular_acceleration{};
  if (primed_)
    for (int i = 0; i < 3; ++i) angular_acceleration[i] = (rate[i] - previous_rate_[i]) / dt_;
  previous_rate_ = rate;
  const Matrix3 k = leverArmMatrix(rate, angular_acceleration);
  const Vector3 turning_accel{rate[1] * accel[2] - rate[2] * accel[1], rate[2] * accel[0] - rate[0] * accel[2],
                              rate[0] * accel[1] - rate[1] * accel[0]};  // ω×a
  Vector3 applied_accel_g{};                                             // K·r̂/g + δ̂·ω×a, sensor frame
  for (int i = 0; i < 3; ++i)
    applied_accel_g[i] =
        (k[i][0] * lever_arm_[0] + k[i][1] * lever_arm_[1] + k[i][2] * lever_arm_[2]) / kStandardGravity +
        accel_delay_s_ * turning_accel[i];

  // The cross-axis pairs (j, k) in θ's order xy, xz, yz.
  constexpr int kPairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  std::array<double, kChannels> x{};
  for (int i = 0; i < 3; ++i) {
    double applied_rate = 0.0, applied_accel = 0.0;
    for (int j = 0; j < 3; ++j) {
      x[6 * i + j] = r[i][j] * rate[j];
      const int a = kPairs[j][0], b = kPairs[j][1];
      x[6 * i + 3 + j] = r[i][a] * rate[b] + r[i][b] * rate[a];
      x[kBiasChannels + 3 * i + j] = r[i][j];
      const Vector3& s = sensitivity_[j];
      applied_rate += r[i][j] * (s[0] * rate[0] + s[1] * rate[1] + s[2] * rate[2] + bias[j]);
      double rk = 0.0;
      for (int m = 0; m < 3; ++m) rk += r[i][m] * k[m][j];
      x[kLeverChannels + 3 * i + j] = rk / kStandardGravity;
      applied_accel += r[i][j] * applied_accel_g[j];
    }
    x[kAppliedChannels + i] = applied_rate;
    x[kLeverChannels + 9 + i] = applied_accel;
  }
  for (int c = kLeverChannels; c < kChannels; ++c) previous_lever_out_[c - kLeverChannels] = out_[c];
  previous_turn_ = turnLowpass();
  if (!primed_) {  // the steady state of a constant input, as the gravity low-pass starts
    for (int c = 0; c < kChannels; ++c) {
      s2_[c] = (lp_.b2 - lp_.a2) * x[c];
      s1_[c] = (lp_.b1 - lp_.a1) * x[c] + s2_[c];
      out_[c] = x[c];
    }
    for (int c = kLeverChannels; c < kChannels; ++c) previous_lever_out_[c - kLeverChannels] = out_[c];
    previous_turn_ = turnLowpass();
    primed_ = true;
    return applied_accel_g;
  }
  for (int c = 0; c < kChannels; ++c) {
    const double y = lp_.b0 * x[c] + s1_[c];
    s1_[c] = lp_.b1 * x[c] - lp_.a1 * y + s2_[c];
    s2_[c] = lp_.b2 * x[c] - lp_.a2 * y;
    out_[c] = y;
  }
  for (int i = 0; i < kStates; ++i) cov_[i][i] += process_variance_[i];
  return applied_accel_g;
}

Vector3 MotionErrorEstimator::turnLowpass() const {
  Vector3 turn;  // L[R_g·ω]: the diagonal regressors summed over the sensor axes
  for (int i = 0; i < 3; ++i) turn[i] = out_[6 * i] + out_[6 * i + 1] + out_[6 * i + 2];
  return turn;
}

void MotionErrorEstimator::update(const Quaternion& q_correction, double cx, double cy, double weight) {
  if (!primed_ || !(weight > 0.0)) return;
  const Matrix3 rc = rotationMatrix(q_correction);
  const double measured[2] = {cx / dt_, cy / dt_};
  const double variance = measurement_variance_ / weight;
  // The delay's tilt, the "acceleration" L[R_g·ω] × z = (y, −x, 0), changed by this step.
  const Vector3 turn = turnLowpass();
  const Vector3 delay_tilt_change{turn[1] - previous_turn_[1], previous_turn_[0] - turn[0], 0.0};
  // J picks, for the correction's world x, the disturbance's y, and for its y, minus its x.
  const int other_row[2] = {1, 0};
  const double sign[2] = {1.0, -1.0};
  for (int row = 0; row < 2; ++row) {
    std::array<double, kStates> h{};
    double known = 0.0;
    const int lever_row = other_row[row];
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 3; ++i) {
        h[j] -= rc[row][i] * out_[6 * i + j];
        h[3 + j] -= rc[row][i] * out_[6 * i + 3 + j];
        h[kBias + j] -= rc[row][i] * out_[kBiasChannels + 3 * i + j];
        const double d_lever = out_[kLeverChannels + 3 * i + j] - previous_lever_out_[3 * i + j];
        h[kLever + j] += sign[row] * rc[lever_row][i] * d_lever / dt_;
      }
      h[kDelay] += sign[row] * rc[lever_row][j] * delay_tilt_change[j] / dt_;
      const double d_applied = out_[kLeverChannels + 9 + j] - previous_lever_out_[9 + j];
      known += rc[row][j] * out_[kAppliedChannels + j] - sign[row] * rc[lever_row][j] * d_applied / dt_;
    }
    std::array<double, kStates> ph{};
    double hph = 0.0, predicted = 0.0;
    for (int a = 0; a < kStates; ++a) {
      for (int b = 0; b < kStates; ++b) ph[a] += cov_[a][b] * h[b];
      hph += h[a] * ph[a];
      predicted += h[a] * theta_[a];
    }
    const double innovation = measured[row] - known - predicted;
    const double s = hph + variance;
    for (int a = 0; a < kStates; ++a) theta_[a] += ph[a] / s * innovation;
    for (int a = 0; a < kStates; ++a) {  // P stays symmetric: one triangle, mirrored
      const double k = ph[a] / s;
      for (int b = a; b < kStates; ++b) cov_[a][b] -= k * ph[b];
      for (int b = a + 1; b < kStates; ++b) cov_[b][a] = cov_[a][b];
    }
  }
  const double limit = p_.sensitivity_limit;
  for (int i = 0; i < 3; ++i) {
    sensitivity_[i][i] = std::clamp(theta_[i], -limit, limit);
    lever_arm_[i] = std::clamp(theta_[kLever + i], -p_.lever_arm_limit_m, p_.lever_arm_limit_m);
  }
  sensitivity_[0][1] = sensitivity_[1][0] = std::clamp(theta_[3], -limit, limit);
  sensitivity_[0][2] = sensitivity_[2][0] = std::clamp(theta_[4], -limit, limit);
  sensitivity_[1][2] = sensitivity_[2][1] = std::clamp(theta_[5], -limit, limit);
  accel_delay_s_ = std::clamp(theta_[kDelay], -p_.accel_delay_limit_s, p_.accel_delay_limit_s);
}

}  // namespace gyrod::processing::attitude
