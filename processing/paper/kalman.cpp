#include "processing/paper/kalman.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "processing/paper/ar_model.hpp"

namespace gyrod::processing {

namespace {

void requireFinite(double v, const char* who, const char* name) {
  if (!std::isfinite(v))
    throw std::invalid_argument(std::string(who) + " needs a finite " + name + ", got " + std::to_string(v));
}

void validateNoise(const char* who, double q, double r, double p0) {
  requireFinite(q, who, "q");
  requireFinite(r, who, "r");
  requireFinite(p0, who, "p0");
  if (q < 0.0)
    throw std::invalid_argument(std::string(who) + " needs a process noise q >= 0, got " + std::to_string(q));
  if (!(r > 0.0))
    throw std::invalid_argument(std::string(who) + " needs a measurement noise r > 0, got " + std::to_string(r));
  if (p0 < 0.0)
    throw std::invalid_argument(std::string(who) + " needs an initial covariance p0 >= 0, got " + std::to_string(p0));
}

}  // namespace

ScalarKalmanFilter::ScalarKalmanFilter(const ScalarKalmanParameters& p) : params_(p) {
  requireFinite(p.a, "the Kalman filter", "a");
  validateNoise("the Kalman filter", p.q, p.r, p.p0);
  if (p.x0) requireFinite(*p.x0, "the Kalman filter", "x0");
  reset();
}

void ScalarKalmanFilter::reset() {
  initialised_ = params_.x0.has_value();
  x_ = params_.x0.value_or(0.0);
  p_ = params_.p0;
  k_ = 0.0;
  innovation_ = 0.0;
}

double ScalarKalmanFilter::update(double z) {
  if (!std::isfinite(z))
    throw std::invalid_argument("the Kalman filter cannot take a measurement that is not finite, got " +
                                std::to_string(z));
  if (!initialised_) {
    // Paper: x̂0 = Z0, P0 as given; nothing to predict from yet.
    initialised_ = true;
    x_ = z;
    p_ = params_.p0;
    k_ = 0.0;
    innovation_ = 0.0;
    return x_;
  }
  const double a = params_.a;
  const double x_prior = a * x_;                  // paper eq. 12
  const double p_prior = a * p_ * a + params_.q;  // eq. 15 (B = 1)
  k_ = p_prior / (p_prior + params_.r);           // eq. 14 (H = 1); r > 0 keeps it defined
  innovation_ = z - x_prior;
  x_ = x_prior + k_ * innovation_;  // eq. 13
  p_ = (1.0 - k_) * p_prior;        // eq. 16
  return x_;
}

void ScalarKalmanFilter::filterInPlace(std::span<double> z) {
  std::size_t i = 0;
  for (; i < z.size(); ++i) {
    const bool had_covariance = initialised_;
    const double p_before = p_;
    z[i] = update(z[i]);
    if (had_covariance && p_ == p_before) {
      ++i;
      break;
    }
  }
  // P is at its fixed point: P⁻, K and P stay as they are; x̂ and the innovation as update().
  const double a = params_.a, k = k_;
  double x = x_, innovation = innovation_;
  for (; i < z.size(); ++i) {
    if (!std::isfinite(z[i])) {
      x_ = x;
      innovation_ = innovation;
      update(z[i]);  // throws, naming the value
    }
    const double x_prior = a * x;
    innovation = z[i] - x_prior;
    x = x_prior + k * innovation;
    z[i] = x;
  }
  x_ = x;
  innovation_ = innovation;
}

double steadyStatePriorCovariance(double a, double q, double r) {
  requireFinite(a, "the steady-state Kalman covariance", "a");
  validateNoise("the steady-state Kalman covariance", q, r, 0.0);
  // M² + b·M − QR = 0 with b = R(1 − A²) − Q. The roots have product −QR ≤ 0; take the
  // larger (the positive one for Q > 0), written to avoid cancellation for either sign of b.
  const double b = r * (1.0 - a * a) - q;
  const double disc = std::sqrt(b * b + 4.0 * q * r);
  return b > 0.0 ? 2.0 * q * r / (b + disc) : (disc - b) / 2.0;
}

double steadyStateGain(double a, double q, double r) {
  const double m = steadyStatePriorCovariance(a, q, r);
  return m / (m + r);
}

double steadyStatePosteriorCovariance(double a, double q, double r) {
  const double m = steadyStatePriorCovariance(a, q, r);
  // (1 − K)·M with K = M/(M + R), i.e. M·R/(M + R).
  return m * r / (m + r);
}

KalmanIdentification identifyKalmanParameters(std::span<const double> raw_detrended,
                                              std::span<const double> mean_filtered) {
  if (raw_detrended.size() != mean_filtered.size())
    throw std::invalid_argument(
        "the Kalman filter identification needs as many raw samples as mean-filtered ones; there are " +
        std::to_string(raw_detrended.size()) + " raw and " + std::to_string(mean_filtered.size()) + " mean-filtered");
  if (mean_filtered.size() < 2)
    throw std::invalid_argument("the Kalman filter identification needs at least 2 samples, got " +
                                std::to_string(mean_filtered.size()));
  // A, Q: the AR(1) Yule–Walker fit of the mean-filtered series (throws on non-finite
  // values or zero variance).
  const std::vector<ArModel> ar1 = yuleWalker(mean_filtered, 1);

  // R: variance of the error raw − mean_filtered (mean removed, divisor N).
  const double n = static_cast<double>(raw_detrended.size());
  double mean = 0.0;
  for (std::size_t i = 0; i < raw_detrended.size(); ++i) {
    if (!std::isfinite(raw_detrended[i]))
      throw std::invalid_argument("the Kalman filter identification cannot use raw sample " + std::to_string(i) +
                                  ": it is not finite");
    mean += raw_detrended[i] - mean_filtered[i];
  }
  mean /= n;
  double ss = 0.0;
  for (std::size_t i = 0; i < raw_detrended.size(); ++i) {
    const double d = raw_detrended[i] - mean_filtered[i] - mean;
    ss += d * d;
  }
  const double r = ss / n;
  if (!(r > 0.0))
    throw std::invalid_argument(
        "the Kalman filter identification needs raw samples that differ from the mean-filtered ones by more than "
        "a constant (the measurement noise R would be 0)");

  KalmanIdentification id;
  id.params.a = ar1[0].phi[0];
  id.params.q = ar1[0].noise_var;
  id.params.r = r;
  id.params.p0 = 0.0;
  id.phi_std_error = ar1[0].phi_std_error[0];
  return id;
}

ArKalmanFilter::ArKalmanFilter(std::span<const double> phi, double q, double r, double p0) : q_(q), r_(r), p0_(p0) {
  if (phi.empty() || phi.size() > kMaxArOrder)
    throw std::invalid_argument("the AR Kalman filter needs an AR order in [1, " + std::to_string(kMaxArOrder) +
                                "], got " + std::to_string(phi.size()));
  for (double v : phi) requireFinite(v, "the AR Kalman filter", "a coefficient phi");
  validateNoise("the AR Kalman filter", q, r, p0);
  const auto p = static_cast<Eigen::Index>(phi.size());
  // Companion matrix: first row φ1..φp, ones on the subdiagonal (x_{k−i} shifts down).
  f_.setZero(p, p);
  for (Eigen::Index j = 0; j < p; ++j) f_(0, j) = phi[static_cast<std::size_t>(j)];
  for (Eigen::Index i = 1; i < p; ++i) f_(i, i - 1) = 1.0;
  x_.setZero(p);
  k_.setZero(p);
  tmp_.setZero(p);
  p_.setZero(p, p);
  ptmp_.setZero(p, p);
  reset();
}

void ArKalmanFilter::reset() {
  initialised_ = false;
  x_.setZero();
  k_.setZero();
  p_.setIdentity();
  p_ *= p0_;
}

double ArKalmanFilter::update(double z) {
  if (!std::isfinite(z))
    throw std::invalid_argument("the AR Kalman filter cannot take a measurement that is not finite, got " +
                                std::to_string(z));
  if (!initialised_) {
    initialised_ = true;
    x_.setConstant(z);
    p_.setIdentity();
    p_ *= p0_;
    k_.setZero();
    return z;
  }
  // Predict: x̂⁻ = F·x̂, P⁻ = F·P·Fᵀ + G·Q·Gᵀ (Q enters P⁻(0,0) only).
  tmp_.noalias() = f_.lazyProduct(x_);
  ptmp_.noalias() = f_.lazyProduct(p_);
  p_.noalias() = ptmp_.lazyProduct(f_.transpose());
  p_(0, 0) += q_;
  // Update with H = e1ᵀ: S = P⁻(0,0) + R, K = P⁻(:,0)/S, P = (I − K·H)·P⁻ = P⁻ − K·P⁻(0,:).
  const double s = p_(0, 0) + r_;
  k_ = p_.col(0) / s;
  const double innovation = z - tmp_(0);
  x_ = tmp_ + k_ * innovation;
  ptmp_.noalias() = k_.lazyProduct(p_.row(0));
  p_ -= ptmp_;
  // Keep P exactly symmetric against rounding drift over long runs.
  ptmp_ = p_.transpose();
  p_ = 0.5 * (p_ + ptmp_);
  return x_(0);
}

}  // namespace gyrod::processing
