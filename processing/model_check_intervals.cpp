// 95 % intervals of the model check's named effects: a parametric bootstrap on the extended
// model's replicas (processing/model_check_intervals.hpp; docs/model-check.md, "Intervals").
#include "processing/model_check_intervals.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "processing/model_check_detail.hpp"

namespace gyrod::processing {
namespace {

constexpr double kZ95 = 1.959964;
constexpr std::size_t kMinReplicaEstimates = 8;

// Half the 15.9–84.1 % spread of the finite values (1 σ for a normal), NaN with too few.
double robustSpread(std::span<const double> values) {
  std::vector<double> v;
  for (double x : values)
    if (std::isfinite(x)) v.push_back(x);
  if (v.size() < kMinReplicaEstimates) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  return 0.5 * (model_check_detail::sortedQuantile(v, 0.8413) - model_check_detail::sortedQuantile(v, 0.1587));
}

// The regularised incomplete gamma P(a, x) by its series (x < a + 1) or continued fraction.
double gammaP(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double log_front = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int k = 1; k < 1000 && std::fabs(term) > 1e-16 * std::fabs(sum); ++k) {
      term *= x / (a + k);
      sum += term;
    }
    return std::exp(log_front) * sum;
  }
  // Lentz's continued fraction for Q(a, x).
  double b = x + 1.0 - a, c = 1e300, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    d = std::fabs(d) < 1e-300 ? 1e-300 : d;
    c = b + an / c;
    c = std::fabs(c) < 1e-300 ? 1e-300 : c;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < 1e-15) break;
  }
  return 1.0 - std::exp(log_front) * h;
}

// The x where P(a, x) = p, by bisection (P rises in x).
double gammaPInverse(double a, double p) {
  double lo = 0.0, hi = a + 20.0 * std::sqrt(a) + 20.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (gammaP(a, mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

ParameterInterval bootstrapInterval(double estimate, std::span<const double> replica_estimates) {
  const double s = robustSpread(replica_estimates);
  if (!std::isfinite(s) || !std::isfinite(estimate)) return {};
  return {true, estimate - kZ95 * s, estimate + kZ95 * s};
}

ParameterInterval logBootstrapInterval(double estimate, std::span<const double> replica_estimates) {
  if (!(estimate > 0.0)) return {};
  std::vector<double> logs;
  logs.reserve(replica_estimates.size());
  for (double v : replica_estimates)
    if (std::isfinite(v)) logs.push_back(v > 0.0 ? std::log(v) : std::log(estimate) - 50.0);
  const double s = robustSpread(logs);
  if (!std::isfinite(s)) return {};
  return {true, estimate * std::exp(-kZ95 * s), estimate * std::exp(kZ95 * s)};
}

ParameterInterval poissonInterval(std::size_t count) {
  // Garwood: [½χ²(0.025; 2k), ½χ²(0.975; 2k + 2)], i.e. the gamma quantiles of shape k, k + 1.
  const auto k = static_cast<double>(count);
  const double lo = count == 0 ? 0.0 : gammaPInverse(k, 0.025);
  return {true, lo, gammaPInverse(k + 1.0, 0.975)};
}

}  // namespace gyrod::processing

namespace gyrod::processing::model_check_detail {

EffectIntervals::EffectIntervals(const Removal& removal, const Context& c,
                                 const std::vector<double>& temperature_regressor, std::size_t replicas)
    : removal_(removal), n_(c.n) {
  // A line first (the series are detrended; it keeps the estimates free of that), then the
  // effects in a fixed order: steps, each sinusoid's sine and cosine parts, temperature.
  std::vector<double> ones(n_, 1.0), line(n_);
  for (std::size_t i = 0; i < n_; ++i) line[i] = 2.0 * static_cast<double>(i) / static_cast<double>(n_) - 1.0;
  regressors_.push_back(std::move(ones));
  regressors_.push_back(std::move(line));
  for (std::size_t step : removal.step_samples) {
    std::vector<double> col(n_, 0.0);
    for (std::size_t i = step; i < n_; ++i) col[i] = 1.0;
    regressors_.push_back(std::move(col));
  }
  for (const SinusoidFit& s : removal.sinusoids) {
    std::vector<double> sine(n_), cosine(n_);
    const double w = 2.0 * std::numbers::pi * s.freq_hz / c.rate;
    for (std::size_t i = 0; i < n_; ++i) {
      sine[i] = std::sin(w * static_cast<double>(i));
      cosine[i] = std::cos(w * static_cast<double>(i));
    }
    regressors_.push_back(std::move(sine));
    regressors_.push_back(std::move(cosine));
  }
  if (removal.temperature && temperature_regressor.size() == n_) regressors_.push_back(temperature_regressor);
  const std::size_t p = regressors_.size();
  if (p == first_effect_column_) return;  // nothing linear named
  Eigen::MatrixXd gram(static_cast<Eigen::Index>(p), static_cast<Eigen::Index>(p));
  for (std::size_t a = 0; a < p; ++a)
    for (std::size_t b = a; b < p; ++b) {
      double s = 0.0;
      for (std::size_t i = 0; i < n_; ++i) s += regressors_[a][i] * regressors_[b][i];
      gram(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) = s;
      gram(static_cast<Eigen::Index>(b), static_cast<Eigen::Index>(a)) = s;
    }
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(gram);
  const Eigen::MatrixXd inverse = cod.pseudoInverse();
  gram_inverse_.assign(inverse.data(), inverse.data() + p * p);
  columns_ = p;
  estimates_.assign(replicas, {});
}

std::vector<double> EffectIntervals::solve(std::span<const double> x) const {
  std::vector<double> xty(columns_, 0.0);
  for (std::size_t a = 0; a < columns_; ++a) {
    const std::vector<double>& col = regressors_[a];
    double s = 0.0;
    for (std::size_t i = 0; i < n_ && i < x.size(); ++i) s += col[i] * x[i];
    xty[a] = s;
  }
  std::vector<double> beta(columns_, 0.0);
  for (std::size_t a = 0; a < columns_; ++a)
    for (std::size_t b = 0; b < columns_; ++b) beta[a] += gram_inverse_[b * columns_ + a] * xty[b];
  return beta;
}

void EffectIntervals::measureReplica(std::size_t index, std::span<const double> x) {
  if (empty() || index >= estimates_.size()) return;
  estimates_[index] = solve(x);
}

void EffectIntervals::measureGaussMarkov(const std::vector<SeriesStats>& reps, const Context& c) {
  for (const SeriesStats& r : reps) {
    if (r.log_adev.size() != c.taus.size()) continue;
    std::vector<double> v(r.log_adev.size());
    for (std::size_t j = 0; j < v.size(); ++j) v[j] = std::exp(2.0 * r.log_adev[j]);
    const GaussMarkovCurveFit fit = fitGaussMarkovToAllan(c.taus, v, c.edf, c.t_grid);
    gm_tau_.push_back(fit.sigma_dps > 0.0 ? fit.tau_s : 0.0);
    gm_sigma_.push_back(fit.sigma_dps);
  }
  // T is fitted on a grid, and the replicas are made at the grid point found, so their T̂ land
  // on it: they cannot show that a true T between two grid points goes to either neighbour
  // (seen: T = 1.24 and 1.40 s both fitted as 0.95 s, with the next point at 1.51 s).
  if (c.t_grid.size() > 1) gm_tau_grid_step_ = std::log(c.t_grid[1] / c.t_grid[0]);
}

void EffectIntervals::state(AxisModelCheck& out, std::span<const double> cleaned) const {
  // The replicas' estimates of column k, each less the value the replicas were made with (the
  // fitted one), so that only the spread matters.
  auto column = [&](std::size_t k) {
    std::vector<double> v;
    for (const std::vector<double>& e : estimates_)
      if (e.size() == columns_) v.push_back(e[k]);
    return v;
  };
  std::size_t next_column = first_effect_column_;
  const std::size_t step_columns = removal_.step_samples.size();
  const std::size_t sine_first = next_column + step_columns;
  const std::size_t temperature_column = sine_first + 2 * removal_.sinusoids.size();
  for (DetectedEffect& e : out.effects) {
    switch (e.effect) {
      case ModelEffect::BiasSteps:
        e.size_intervals.clear();
        for (std::size_t j = 0; j < e.sizes_dps.size(); ++j)
          e.size_intervals.push_back(empty() || j >= step_columns
                                         ? ParameterInterval{}
                                         : bootstrapInterval(e.sizes_dps[j], column(next_column + j)));
        break;
      case ModelEffect::Sinusoid:
        for (std::size_t s = 0; s < removal_.sinusoids.size() && !empty(); ++s) {
          if (std::fabs(removal_.sinusoids[s].freq_hz - e.freq_hz) > 1e-9 * e.freq_hz) continue;
          const std::vector<double> a = column(sine_first + 2 * s), b = column(sine_first + 2 * s + 1);
          std::vector<double> amp(a.size());
          for (std::size_t r = 0; r < a.size(); ++r) amp[r] = std::hypot(a[r], b[r]);
          e.amp_interval = bootstrapInterval(e.amp_dps, amp);
          e.amp_interval.lo = std::max(0.0, e.amp_interval.lo);
          break;
        }
        break;
      case ModelEffect::TemperatureBias:
        if (!empty() && removal_.temperature && temperature_column < columns_)
          e.k_interval = bootstrapInterval(e.k_dps_per_c, column(temperature_column));
        break;
      case ModelEffect::GaussMarkov:
        e.tau_interval = logBootstrapInterval(e.tau_s, gm_tau_);
        if (e.tau_interval.stated) {
          e.tau_interval.lo *= std::exp(-gm_tau_grid_step_);
          e.tau_interval.hi *= std::exp(gm_tau_grid_step_);
        }
        e.sigma_interval = logBootstrapInterval(e.sigma_dps, gm_sigma_);
        break;
      case ModelEffect::Outliers: {
        e.count_interval = poissonInterval(e.count);
        // Each excursion is the spike plus the noise under it: the median's standard error is
        // 1.2533·σ/√count, σ the cleaned series' sample-to-sample noise (robust).
        std::vector<double> diffs;
        for (std::size_t i = 1; i < cleaned.size(); ++i) diffs.push_back(std::fabs(cleaned[i] - cleaned[i - 1]));
        if (!diffs.empty() && e.count > 0) {
          std::nth_element(diffs.begin(), diffs.begin() + static_cast<std::ptrdiff_t>(diffs.size() / 2), diffs.end());
          const double sigma = 1.4826 * diffs[diffs.size() / 2] / std::sqrt(2.0);
          const double se = 1.2533 * sigma / std::sqrt(static_cast<double>(e.count));
          e.outlier_amplitude_interval = {true, std::max(0.0, e.outlier_median_amplitude_dps - kZ95 * se),
                                          e.outlier_median_amplitude_dps + kZ95 * se};
        }
        break;
      }
      default: break;
    }
  }
}

}  // namespace gyrod::processing::model_check_detail
