// Kalman innovations for the model check's whiteness and innovation-variance figures.
//
// State s_k = [x_k, x_{k−1}, …, x_{k−p+1} | g_k]: the AR(p) part in companion form (as
// kalman.hpp's ArKalmanFilter) and, when given, one Gauss–Markov state g_k = ρ·g_{k−1} + w.
// Measurement z_k = x_k + g_k, without a further white term: AR(p) already carries the
// white part of the noise (its a_k), so R = 0 and S = H·P⁻·Hᵀ > 0 through Q.
#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

#include "processing/model_check/detail.hpp"
#include "processing/paper/kalman.hpp"

namespace gyrod::processing::model_check_detail {
namespace {

constexpr std::size_t kMaxStates = kMaxArOrder + 1 + 2 * kMaxInnovationLines;
using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxStates, kMaxStates>;
using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxStates, 1>;
constexpr std::size_t kBurnIn = 100;
// Gross-error gate on the normalised innovation, as the paper's mean filter rejects
// samples far from their neighbours: 5 σ is never reached by Gaussian noise in practice
// (p ≈ 6e-7 per sample).
constexpr double kRejectSigmas = 5.0;

}  // namespace

InnovationStats kalmanInnovations(std::span<const double> z, std::span<const double> phi, double ar_noise_var,
                                  double gm_decay, double gm_noise_var, bool robust,
                                  std::span<const NarrowbandLineRecursion> lines) {
  const std::size_t p = phi.size();
  const bool gm = gm_noise_var > 0.0;
  if (p == 0 || p > kMaxArOrder)
    throw std::invalid_argument("the Kalman innovations need an AR order of 1.." + std::to_string(kMaxArOrder) +
                                ", got " + std::to_string(p));
  if (!(ar_noise_var > 0.0) || !std::isfinite(ar_noise_var))
    throw std::invalid_argument("the Kalman innovations need an AR noise variance > 0, got " +
                                std::to_string(ar_noise_var));
  if (z.size() <= kBurnIn + 10)
    throw std::invalid_argument("the Kalman innovations need more than " + std::to_string(kBurnIn + 10) +
                                " samples, got " + std::to_string(z.size()));
  if (lines.size() > kMaxInnovationLines)
    throw std::invalid_argument("the Kalman innovations take at most " + std::to_string(kMaxInnovationLines) +
                                " narrowband lines, got " + std::to_string(lines.size()));
  const auto d = static_cast<Eigen::Index>(p + (gm ? 1 : 0) + 2 * lines.size());
  const auto pi = static_cast<Eigen::Index>(p);

  Matrix f = Matrix::Zero(d, d), q = Matrix::Zero(d, d), pm(d, d), pp(d, d);
  for (Eigen::Index i = 0; i < pi; ++i) f(0, i) = phi[static_cast<std::size_t>(i)];
  for (Eigen::Index i = 1; i < pi; ++i) f(i, i - 1) = 1.0;
  q(0, 0) = ar_noise_var;
  if (gm) {
    f(pi, pi) = gm_decay;
    q(pi, pi) = gm_noise_var;
  }
  Vector h = Vector::Zero(d);
  h(0) = 1.0;
  if (gm) h(pi) = 1.0;
  for (std::size_t j = 0; j < lines.size(); ++j) {
    const auto at = static_cast<Eigen::Index>(p + (gm ? 1 : 0) + 2 * j);
    f(at, at) = lines[j].a1;
    f(at, at + 1) = lines[j].a2;
    f(at + 1, at) = 1.0;
    q(at, at) = lines[j].drive_var;
    h(at) = 1.0;
  }

  double var_z = 0.0;
  for (double v : z) var_z += v * v;
  var_z /= static_cast<double>(z.size());
  pp = Matrix::Identity(d, d) * std::max(var_z, ar_noise_var);
  Vector x = Vector::Zero(d), xp(d), k(d), ph(d);

  InnovationStats out;
  out.innovations.reserve(z.size() - kBurnIn);
  bool frozen = false;
  double s = 0.0;
  double sum_sq = 0.0;
  for (std::size_t n = 0; n < z.size(); ++n) {
    xp.noalias() = f * x;
    if (!frozen) {
      pm.noalias() = f * pp * f.transpose();
      pm += q;
      ph.noalias() = pm * h;
      s = h.dot(ph);
      k = ph / s;
    }
    const double e = z[n] - h.dot(xp);
    const bool reject = robust && n >= kBurnIn && std::fabs(e) > kRejectSigmas * std::sqrt(s);
    if (reject) {
      x = xp;  // the prediction stands in for the gross error
      ++out.rejected;
      out.rejected_samples.push_back(n);
      if (!frozen) pp = pm;
      continue;
    }
    x = xp + k * e;
    if (!frozen) {
      const Matrix previous = pp;
      pp = pm - k * ph.transpose();
      // Steady state reached: keep the gain (the Riccati recursion no longer moves).
      if (n > 4 * p + 10 && (pp - previous).norm() <= 1e-12 * pp.norm()) frozen = true;
    }
    if (n >= kBurnIn) {
      out.innovations.push_back(e);
      sum_sq += e * e;
    }
  }
  out.variance = out.innovations.empty() ? 0.0 : sum_sq / static_cast<double>(out.innovations.size());
  return out;
}

}  // namespace gyrod::processing::model_check_detail
