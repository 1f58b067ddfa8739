#include "processing/allan/noise_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace gyrod::processing {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kTermCount = static_cast<int>(kNoiseTermCount);
constexpr int kWeightPasses = 3;  // measured-value weights, then twice with model values

struct CurvePoint {
  double tau_s;
  double variance;  // σ̂², (°/s)²
  double edf;
  std::size_t index;  // in the curve
};

std::string describeTau(double tau_s) {
  std::ostringstream os;
  os << "tau = " << tau_s << " s";
  return os.str();
}

std::vector<CurvePoint> usablePoints(std::span<const AllanPoint> curve, std::size_t min_terms, bool need_edf,
                                     const char* where) {
  std::vector<CurvePoint> points;
  for (const AllanPoint& p : curve) {
    if (p.oadev_terms < min_terms || !std::isfinite(p.oadev)) continue;
    if (!(std::isfinite(p.tau_s) && p.tau_s > 0.0)) {
      throw std::invalid_argument(std::string(where) + " needs positive times; " + describeTau(p.tau_s) +
                                  " is not one");
    }
    if (!(p.oadev > 0.0)) {
      throw std::invalid_argument(std::string(where) + " needs an Allan deviation above 0; at " + describeTau(p.tau_s) +
                                  " it is 0 (a signal without noise, such as a constant one, has no terms to read)");
    }
    if (need_edf && !(std::isfinite(p.edf) && p.edf > 0.0)) {
      throw std::invalid_argument(std::string(where) +
                                  " needs degrees of freedom that are finite and > 0 (they weight the fit); at " +
                                  describeTau(p.tau_s) + " they are not");
    }
    double edf = p.edf;
    if (need_edf && p.m > 0) {
      // Never weight a point more than a frequency-noise (α ≤ 0) estimate at this (N, m)
      // could be: a phase-noise verdict from few averages (the lag-1 method's usual error at
      // long τ) would otherwise give a long-τ point the weight of thousands of degrees of
      // freedom. Real phase noise only loses weight (a conservative choice).
      const std::size_t phase_points = p.oadev_terms + 2 * p.m;
      double fm_edf = 0.0;
      for (int alpha : {0, -1, -2}) fm_edf = std::max(fm_edf, overlappingAllanEdf(alpha, phase_points, p.m));
      edf = std::min(edf, fm_edf);
    }
    points.push_back({p.tau_s, p.oadev * p.oadev, edf, static_cast<std::size_t>(&p - curve.data())});
  }
  if (points.empty()) {
    throw std::invalid_argument(std::string(where) + " has no usable point (each needs at least " +
                                std::to_string(min_terms) + " terms in its Allan deviation, and a finite one)");
  }
  return points;
}

// Term i's basis function at a point: τ^p, times the term's shape there when one is given.
double basisAt(const NoiseTermShapes* shapes, int i, const CurvePoint& p) {
  const double power = std::pow(p.tau_s, noiseTermVariancePower(kAllNoiseTerms[i]));
  if (!shapes) return power;
  const std::vector<double>& s = (*shapes)[static_cast<std::size_t>(i)];
  return s.empty() ? power : power * s[p.index];
}

double modelVariance(const Eigen::VectorXd& c, const CurvePoint& p, const NoiseTermShapes* shapes) {
  double v = 0.0;
  for (int i = 0; i < kTermCount; ++i) v += c(i) * basisAt(shapes, i, p);
  return v;
}

// Covariance (AᵀA)⁻¹ of the columns `cols` of A, computed on unit-norm columns (QR) and
// scaled back; empty when those columns are (numerically) dependent.
std::optional<Eigen::MatrixXd> covarianceOfColumns(const Eigen::MatrixXd& a, const std::vector<int>& cols) {
  const auto k = static_cast<Eigen::Index>(cols.size());
  if (k == 0 || k > a.rows()) return std::nullopt;
  Eigen::MatrixXd sub(a.rows(), k);
  Eigen::VectorXd norms(k);
  for (Eigen::Index j = 0; j < k; ++j) {
    norms(j) = a.col(cols[static_cast<std::size_t>(j)]).norm();
    if (!(norms(j) > 0.0)) return std::nullopt;
    sub.col(j) = a.col(cols[static_cast<std::size_t>(j)]) / norms(j);
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(sub);
  if (qr.rank() < k) return std::nullopt;
  const Eigen::MatrixXd r = qr.matrixR().topLeftCorner(k, k).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd r_inv = r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(k, k));
  const Eigen::MatrixXd permuted = r_inv * r_inv.transpose();
  const Eigen::MatrixXd scaled_cov = qr.colsPermutation() * permuted * qr.colsPermutation().transpose();
  return norms.cwiseInverse().asDiagonal() * scaled_cov * norms.cwiseInverse().asDiagonal();
}

}  // namespace

NonNegativeLeastSquares solveNonNegativeLeastSquares(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  const Eigen::Index n = a.cols();
  if (n < 1 || n > 16) {
    throw std::invalid_argument("the noise term fit needs 1..16 terms (got " + std::to_string(n) + ")");
  }
  if (a.rows() != b.size()) {
    throw std::invalid_argument("the noise term fit has " + std::to_string(a.rows()) + " rows of terms but " +
                                std::to_string(b.size()) + " Allan variances");
  }
  if (!a.allFinite() || !b.allFinite()) {
    throw std::invalid_argument("the noise term fit needs finite terms and Allan variances");
  }
  Eigen::VectorXd norms = a.colwise().norm().transpose();
  Eigen::MatrixXd scaled = a;
  for (Eigen::Index j = 0; j < n; ++j) {
    if (norms(j) > 0.0) scaled.col(j) /= norms(j);
  }

  const double b_norm2 = b.squaredNorm();
  const double tie = 1e-13 * b_norm2;
  Eigen::VectorXd best_y = Eigen::VectorXd::Zero(n);  // in scaled coordinates
  double best_r = b_norm2;                            // the empty support, x = 0
  Eigen::Index best_k = 0;

  std::vector<Eigen::Index> cols;
  for (unsigned mask = 1; mask < (1u << n); ++mask) {
    cols.clear();
    bool usable = true;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (mask & (1u << j)) {
        cols.push_back(j);
        usable = usable && norms(j) > 0.0;
      }
    }
    const auto k = static_cast<Eigen::Index>(cols.size());
    if (!usable || k > a.rows()) continue;
    Eigen::MatrixXd sub(a.rows(), k);
    for (Eigen::Index j = 0; j < k; ++j) sub.col(j) = scaled.col(cols[static_cast<std::size_t>(j)]);
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(sub);
    if (qr.rank() < k) continue;  // dependent columns: a smaller support covers it
    const Eigen::VectorXd y = qr.solve(b);
    if ((y.array() < 0.0).any()) continue;
    const double r = (sub * y - b).squaredNorm();
    if (r < best_r - tie || (r <= best_r + tie && k < best_k)) {
      best_r = r;
      best_k = k;
      best_y.setZero();
      for (Eigen::Index j = 0; j < k; ++j) best_y(cols[static_cast<std::size_t>(j)]) = y(j);
    }
  }
  NonNegativeLeastSquares result;
  result.x = Eigen::VectorXd::Zero(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    if (norms(j) > 0.0) result.x(j) = best_y(j) / norms(j);
  }
  result.residual_squared = best_r;
  return result;
}

NoiseTermFit fitNoiseTerms(std::span<const AllanPoint> curve, std::size_t min_terms) {
  return fitShapedNoiseTerms(curve, nullptr, {}, min_terms);
}

NoiseTermFit fitShapedNoiseTerms(std::span<const AllanPoint> curve, const NoiseTermShapes* shapes,
                                 std::span<const double> known_variance, std::size_t min_terms) {
  std::vector<CurvePoint> points = usablePoints(curve, min_terms, true, "the noise term fit");
  if (!known_variance.empty())
    for (CurvePoint& p : points) p.variance = std::max(p.variance - known_variance[p.index], 0.01 * p.variance);
  const auto n = static_cast<Eigen::Index>(points.size());

  // Row j of the weighted system is divided by the standard deviation of σ̂²_j,
  // sd = σ²_ref·√(2/edf_j) (χ² with edf degrees of freedom), so every row is O(1); column
  // scaling inside the solver takes care of τ^±2 spanning many decades.
  std::vector<double> reference(points.size());
  for (std::size_t j = 0; j < points.size(); ++j) reference[j] = points[j].variance;
  Eigen::MatrixXd a(n, kTermCount);
  Eigen::VectorXd b(n);
  NonNegativeLeastSquares solution;
  for (int pass = 0; pass < kWeightPasses; ++pass) {
    for (Eigen::Index j = 0; j < n; ++j) {
      const CurvePoint& p = points[static_cast<std::size_t>(j)];
      const double row_weight = std::sqrt(p.edf / 2.0) / reference[static_cast<std::size_t>(j)];
      for (int i = 0; i < kTermCount; ++i) {
        a(j, i) = basisAt(shapes, i, p) * row_weight;
      }
      b(j) = p.variance * row_weight;
    }
    solution = solveNonNegativeLeastSquares(a, b);
    if (pass + 1 == kWeightPasses) break;
    // Next pass weights from the model value. It is kept ≥ 1/10 of the measured value so
    // that a point the model misses badly cannot take over the fit.
    for (std::size_t j = 0; j < points.size(); ++j) {
      const double model = modelVariance(solution.x, points[j], shapes);
      reference[j] = std::max(model, 0.1 * points[j].variance);
    }
  }

  const Eigen::VectorXd& c = solution.x;
  std::vector<int> active;
  for (int i = 0; i < kTermCount; ++i) {
    if (c(i) > 0.0) active.push_back(i);
  }
  const Eigen::Index dof = n - static_cast<Eigen::Index>(active.size());
  NoiseTermFit fit;
  fit.points_used = points.size();
  fit.reduced_chi2 = dof > 0 ? solution.residual_squared / static_cast<double>(dof) : kNaN;
  // Scatter beyond what the edf predicts widens the errors; less scatter does not narrow them.
  const double scale = dof > 0 ? std::max(1.0, fit.reduced_chi2) : 1.0;

  // 1-σ of a coefficient from the covariance of `cols`, entry `index` within it; falls back
  // to the term's column alone when the set is dependent.
  auto coefficientSigma = [&](const std::vector<int>& cols, std::size_t index) {
    if (const auto cov = covarianceOfColumns(a, cols)) {
      const auto ii = static_cast<Eigen::Index>(index);
      return std::sqrt(scale * (*cov)(ii, ii));
    }
    return std::sqrt(scale) / a.col(cols[index]).norm();
  };

  for (int i = 0; i < kTermCount; ++i) {
    const NoiseTerm t = kAllNoiseTerms[i];
    const auto pos = std::find(active.begin(), active.end(), i);
    if (pos != active.end()) {
      const double sigma_c = coefficientSigma(active, static_cast<std::size_t>(pos - active.begin()));
      const double value = noiseTermFromCoefficient(t, c(i));
      // T ∝ √c ⇒ σ_T = σ_c·dT/dc = σ_c·T/(2c); the linearisation fails for c ≲ σ_c, where the
      // bound of an absent term (T at c = σ_c) is the honest size instead.
      const double linear = sigma_c * value / (2.0 * c(i));
      fit.value.set(t, value);
      fit.uncertainty.set(t, std::min(linear, noiseTermFromCoefficient(t, sigma_c)));
    } else {
      std::vector<int> with_term = active;
      with_term.push_back(i);
      const double sigma_c = coefficientSigma(with_term, with_term.size() - 1);
      fit.value.set(t, 0.0);
      fit.uncertainty.set(t, noiseTermFromCoefficient(t, sigma_c));
    }
  }
  return fit;
}

NoiseTerms readNoiseTermsFromSlopes(std::span<const AllanPoint> curve, std::size_t min_terms) {
  const std::vector<CurvePoint> points = usablePoints(curve, min_terms, false, "the noise terms read from the slopes");
  NoiseTerms terms;
  for (NoiseTerm t : kAllNoiseTerms) {
    const double s = noiseTermSlope(t);
    // The highest line ln σ = b + s·ln τ that stays on or below every point.
    double b = std::numeric_limits<double>::infinity();
    for (const CurvePoint& p : points) b = std::min(b, 0.5 * std::log(p.variance) - s * std::log(p.tau_s));
    terms.set(t, noiseTermFromCoefficient(t, std::exp(2.0 * b)));
  }
  return terms;
}

}  // namespace gyrod::processing
