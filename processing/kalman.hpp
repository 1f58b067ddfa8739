#pragma once
// Kalman filter on the AR drift model (paper eqs. 8–16).
// State X(k) = A·X(k−1) + W(k), W ~ N(0, Q); measurement Z(k) = X(k) + V(k), V ~ N(0, R).
// Predict x̂⁻ = A·x̂, P⁻ = A·P·A + Q; gain K = P⁻/(P⁻ + R); update x̂ = x̂⁻ + K·(Z − x̂⁻),
// P = (1 − K)·P⁻. Defaults as in the paper: P0 = 0 and x̂0 = the first measurement.
//
// R, which the paper leaves undefined, is in gyrod the variance of the measurement's
// error about the AR state: see docs/method.md and identifyKalmanParameters().
#include <Eigen/Dense>
#include <cstddef>
#include <optional>
#include <span>

namespace gyrod::processing {

struct ScalarKalmanParameters {
  double a = 0.0;   // A = φ1
  double q = 0.0;   // Q = σa²
  double r = 0.0;   // R
  double p0 = 0.0;  // P0
  std::optional<double> x0;  // x̂0; empty → first measurement
};

class ScalarKalmanFilter {
 public:
  explicit ScalarKalmanFilter(const ScalarKalmanParameters& p);  // throws on q<0, r<0, p0<0, non-finite
  // One measurement in, the updated estimate out. The first call with x0 empty
  // initialises x̂ = Z and returns it (P = P0).
  double update(double z);
  void reset();
  double gain() const { return k_; }
  double covariance() const { return p_; }
  double innovation() const { return innovation_; }  // Z − x̂⁻ of the last update
  const ScalarKalmanParameters& parameters() const { return params_; }

 private:
  ScalarKalmanParameters params_;
  bool initialised_ = false;
  double x_ = 0.0, p_ = 0.0, k_ = 0.0, innovation_ = 0.0;
};

// Steady-state a-priori covariance P⁻∞ of the scalar filter (positive root of the
// discrete algebraic Riccati equation) and the gain K∞ = P⁻∞/(P⁻∞ + R).
double steadyStatePriorCovariance(double a, double q, double r);
double steadyStateGain(double a, double q, double r);

// AR(p) in companion form: state s_k = [x_k, x_{k−1}, …, x_{k−p+1}], F = companion(φ),
// G = e1 (noise enters the first state), H = e1ᵀ. Storage is fixed at construction;
// update() allocates nothing. Maximum order kMaxArOrder.
inline constexpr std::size_t kMaxArOrder = 8;
class ArKalmanFilter {
 public:
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxArOrder, kMaxArOrder>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxArOrder, 1>;
  // phi: φ1..φp (1 ≤ p ≤ kMaxArOrder); q = σa²; r = R; P0 = p0·I; x̂0 = [Z0, Z0, …] by default.
  ArKalmanFilter(std::span<const double> phi, double q, double r, double p0 = 0.0);
  double update(double z);
  void reset();
  std::size_t order() const { return static_cast<std::size_t>(f_.rows()); }
  double gain() const { return k_(0); }  // gain on the first state

 private:
  Matrix f_;
  double q_, r_, p0_;
  bool initialised_ = false;
  Vector x_, k_, tmp_;
  Matrix p_, ptmp_;
};

}  // namespace gyrod::processing
