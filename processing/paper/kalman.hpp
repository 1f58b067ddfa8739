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
  double a = 0.0;            // A = φ1
  double q = 0.0;            // Q = σa²
  double r = 0.0;            // R
  double p0 = 0.0;           // P0
  std::optional<double> x0;  // x̂0; empty → first measurement
};

class ScalarKalmanFilter {
 public:
  // Throws std::invalid_argument on non-finite a/q/r/p0/x0, q < 0, r ≤ 0 (R = 0 would be a
  // perfect measurement, for which P⁻ + R can vanish) or p0 < 0.
  explicit ScalarKalmanFilter(const ScalarKalmanParameters& p);
  // One measurement in, the updated estimate out. The first call with x0 empty
  // initialises x̂ = Z and returns it (P = P0, K = 0, innovation 0). With x0 set, every call,
  // the first included, predicts from the previous estimate and updates.
  // Throws std::invalid_argument for a non-finite z (state unchanged).
  double update(double z);
  // update() on every element of z in turn, each replaced by its estimate: the same bits and
  // the same state after, faster on long series. The covariance recursion does not depend
  // on the data, so once P repeats exactly (P after an update equal to P before it) every
  // later update has the same P⁻ and gain: from there only the estimate is stepped, with
  // update()'s own operations. Throws as update() at the first non-finite element, the
  // elements before it filtered and the state that of update() after them.
  void filterInPlace(std::span<double> z);
  // Back to the state after construction.
  void reset();
  double gain() const { return k_; }
  double covariance() const { return p_; }           // P after the last update
  double innovation() const { return innovation_; }  // Z − x̂⁻ of the last update
  const ScalarKalmanParameters& parameters() const { return params_; }

 private:
  ScalarKalmanParameters params_;
  bool initialised_ = false;
  double x_ = 0.0, p_ = 0.0, k_ = 0.0, innovation_ = 0.0;
};

// Steady-state a-priori covariance P⁻∞ of the scalar filter: the positive root of the
// discrete algebraic Riccati equation P⁻ = A²·P⁻R/(P⁻ + R) + Q, i.e. of
// P⁻² + (R(1 − A²) − Q)·P⁻ − QR = 0; the gain K∞ = P⁻∞/(P⁻∞ + R) and the a-posteriori
// P∞ = (1 − K∞)·P⁻∞ (the steady error variance of x̂ when the model is right).
// Throw std::invalid_argument on non-finite input, q < 0 or r ≤ 0.
double steadyStatePriorCovariance(double a, double q, double r);
double steadyStateGain(double a, double q, double r);
double steadyStatePosteriorCovariance(double a, double q, double r);

// The paper's scalar Kalman parameters identified from data (paper §4–5, gyrod's choices):
//  - A = φ1 and Q = σa² of the AR(1) Yule–Walker fit of the mean-filtered series, as the
//    paper does (its Table 3 AR(1) column);
//  - R = the variance of the raw (detrended) sample about the mean-filter output,
//    var(raw − mean_filtered) with the mean of the difference removed and divisor N. The
//    paper calls R "the variance of the estimation error of the sample data" and gives no
//    formula; gyrod reads the mean filter's output as the estimate of the sample data and
//    raw − estimate as its error.
//  - P0 = 0 and x̂0 empty (first measurement), as in the paper.
// phi_std_error is the asymptotic standard error of φ1, √((1 − φ1²)/N).
// Throws std::invalid_argument if the spans differ in length, have fewer than 2 samples,
// hold non-finite values, the mean-filtered series has zero variance, or raw equals the
// mean-filtered series (R would be 0).
struct KalmanIdentification {
  ScalarKalmanParameters params;
  double phi_std_error = 0.0;
};
KalmanIdentification identifyKalmanParameters(std::span<const double> raw_detrended,
                                              std::span<const double> mean_filtered);

// AR(p) in companion form: state s_k = [x_k, x_{k−1}, …, x_{k−p+1}], F = companion(φ),
// G = e1 (noise enters the first state), H = e1ᵀ. Storage is fixed at construction;
// update() allocates nothing (all matrices have compile-time maximum sizes, so Eigen keeps
// them and every temporary inline, and products are coefficient-based). Maximum order
// kMaxArOrder.
inline constexpr std::size_t kMaxArOrder = 8;
class ArKalmanFilter {
 public:
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxArOrder, kMaxArOrder>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxArOrder, 1>;
  // phi: φ1..φp (1 ≤ p ≤ kMaxArOrder); q = σa²; r = R; P0 = p0·I; x̂0 = [Z0, Z0, …] by default.
  // Throws std::invalid_argument on a bad order, non-finite values, q < 0, r ≤ 0 or p0 < 0.
  ArKalmanFilter(std::span<const double> phi, double q, double r, double p0 = 0.0);
  // As ScalarKalmanFilter::update: the first call initialises x̂ = [Z, …, Z], P = P0 and
  // returns Z; later calls predict and update. Returns the first state, the estimate of x_k.
  double update(double z);
  void reset();
  std::size_t order() const { return static_cast<std::size_t>(f_.rows()); }
  double gain() const { return k_(0); }           // gain on the first state
  double covariance() const { return p_(0, 0); }  // a-posteriori variance of the first state

 private:
  Matrix f_;
  double q_, r_, p0_;
  bool initialised_ = false;
  Vector x_, k_, tmp_;
  Matrix p_, ptmp_;
};

}  // namespace gyrod::processing
