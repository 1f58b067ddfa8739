// 95 % intervals of the model check's named effects: a parametric bootstrap on the extended
// model's replicas (processing/model_check/intervals.hpp; docs/model-check.md, "Intervals").
#include "processing/model_check/intervals.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "processing/model_check/detail.hpp"

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

// I0(x)·e^{−x} for x ≥ 0: Abramowitz & Stegun 9.8.1 and 9.8.2 (relative error < 2e-7).
double scaledBesselI0(double x) {
  if (x <= 3.75) {
    const double t = (x / 3.75) * (x / 3.75);
    return (1.0 +
            t * (3.5156229 + t * (3.0899424 + t * (1.2067492 + t * (0.2659732 + t * (0.0360768 + t * 0.0045813)))))) *
           std::exp(-x);
  }
  const double t = 3.75 / x;
  return (0.39894228 +
          t * (0.01328592 +
               t * (0.00225319 +
                    t * (-0.00157565 +
                         t * (0.00916281 +
                              t * (-0.02057706 + t * (0.02635537 + t * (-0.01647633 + t * 0.00392377)))))))) /
         std::sqrt(x);
}

// t_{0.975, dof} by its Cornish–Fisher expansion about z (error < 1e-3 for dof ≥ 10).
double tQuantile975(double dof) {
  const double z = kZ95, z3 = z * z * z, z5 = z3 * z * z;
  return z + (z3 + z) / (4.0 * dof) + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * dof * dof);
}

// The ν in [lo, hi] where riceCdf(r, ν) (falling in ν) equals p, by bisection.
double riceNoncentralityAt(double r, double p, double lo, double hi) {
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (riceCdf(r, mid) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double riceCdf(double r, double nu) {
  // ∫₀^r ρ·e^{−(ρ² + ν²)/2}·I0(ρν) dρ, written with the scaled I0 so that nothing overflows;
  // the density is nil beyond 12 from ν. Simpson's rule, 200 intervals (step ≤ 0.12).
  constexpr double kReach = 12.0;
  constexpr int kIntervals = 200;
  const double from = std::max(0.0, nu - kReach), to = std::min(r, nu + kReach);
  if (!(to > from)) return r >= nu + kReach ? 1.0 : 0.0;
  const double h = (to - from) / kIntervals;
  auto density = [nu](double rho) { return rho * std::exp(-0.5 * (rho - nu) * (rho - nu)) * scaledBesselI0(rho * nu); };
  double sum = density(from) + density(to);
  for (int i = 1; i < kIntervals; ++i) sum += (i % 2 == 1 ? 4.0 : 2.0) * density(from + i * h);
  return std::clamp(sum * h / 3.0, 0.0, 1.0);
}

ParameterInterval sinusoidAmplitudeInterval(double amplitude, std::span<const double> replica_a,
                                            std::span<const double> replica_b) {
  std::vector<double> a, b;
  for (std::size_t i = 0; i < replica_a.size() && i < replica_b.size(); ++i)
    if (std::isfinite(replica_a[i]) && std::isfinite(replica_b[i])) {
      a.push_back(replica_a[i]);
      b.push_back(replica_b[i]);
    }
  if (a.size() < kMinReplicaEstimates || !(amplitude >= 0.0) || !std::isfinite(amplitude)) return {};
  auto squares_about_mean = [](const std::vector<double>& v) {
    double mean = 0.0;
    for (double x : v) mean += x;
    mean /= static_cast<double>(v.size());
    double ss = 0.0;
    for (double x : v) ss += (x - mean) * (x - mean);
    return ss;
  };
  const double dof = 2.0 * static_cast<double>(a.size()) - 2.0;
  const double s = std::sqrt((squares_about_mean(a) + squares_about_mean(b)) / dof) * tQuantile975(dof) / kZ95;
  if (!(s > 0.0) || !std::isfinite(s)) return {};
  const double r = amplitude / s;
  // Upper limit: P(R ≤ r | ν) = 2.5 %; lower: = 97.5 %, or 0 when even ν = 0 gives less.
  const double hi = riceNoncentralityAt(r, 0.025, 0.0, r + 12.0);
  const double lo = riceCdf(r, 0.0) <= 0.975 ? 0.0 : riceNoncentralityAt(r, 0.975, 0.0, r);
  return {true, s * lo, s * hi};
}

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
    : removal_(removal), n_(c.n), context_(c) {
  if (!removal.lines.empty()) line_estimates_.assign(replicas, {});
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
  if (p == first_effect_column_) {  // nothing linear named
    regressors_.clear();
    return;
  }
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
  if (columns_ > 0 && index < estimates_.size()) estimates_[index] = solve(x);
  if (index < line_estimates_.size()) measureLines(index, x);
}

void EffectIntervals::measureLines(std::size_t index, std::span<const double> x) {
  const Context& c = context_;
  const Periodogram p = hannPeriodogram(x);
  const double df = c.rate / static_cast<double>(p.nfft);
  const std::vector<double> bg = onesidedPsd(p, blockMedianBackground(p.power, c.line_background_block), c.rate);
  const std::vector<double> psd = onesidedPsd(p, c.rate);
  std::vector<double>& est = line_estimates_[index];
  for (const NarrowbandLine& l : removal_.lines) {
    const auto centre = static_cast<std::size_t>(std::lround(l.centre_hz / df));
    const auto width = std::max<std::size_t>(4, static_cast<std::size_t>(std::lround(l.width_hz / df)));
    const NarrowbandFit fit =
        fitNarrowbandLine(psd, bg, df, c.rate, centre, width, c.k_lo, c.k_hi, LineFitEffort::Refit);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    est.push_back(fit.fitted ? fit.centre_hz : nan);
    est.push_back(fit.fitted ? fit.width_hz : nan);
    est.push_back(fit.fitted ? fit.rms_dps : nan);
  }
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
          e.size_intervals.push_back(columns_ == 0 || j >= step_columns
                                         ? ParameterInterval{}
                                         : bootstrapInterval(e.sizes_dps[j], column(next_column + j)));
        break;
      case ModelEffect::Sinusoid:
        for (std::size_t s = 0; s < removal_.sinusoids.size() && columns_ > 0; ++s) {
          if (std::fabs(removal_.sinusoids[s].freq_hz - e.freq_hz) > 1e-9 * e.freq_hz) continue;
          e.amp_interval =
              sinusoidAmplitudeInterval(e.amp_dps, column(sine_first + 2 * s), column(sine_first + 2 * s + 1));
          break;
        }
        break;
      case ModelEffect::TemperatureBias:
        if (columns_ > 0 && removal_.temperature && temperature_column < columns_)
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
      case ModelEffect::NarrowbandLine:
        for (std::size_t j = 0; j < removal_.lines.size(); ++j) {
          if (std::fabs(removal_.lines[j].centre_hz - e.centre_hz) > 1e-9 * e.centre_hz) continue;
          std::vector<double> centre, width, rms;
          for (const std::vector<double>& r : line_estimates_) {
            if (r.size() != 3 * removal_.lines.size()) continue;
            centre.push_back(r[3 * j]);
            width.push_back(r[3 * j + 1]);
            rms.push_back(r[3 * j + 2]);
          }
          e.centre_interval = bootstrapInterval(e.centre_hz, centre);
          e.width_interval = logBootstrapInterval(e.width_hz, width);
          e.rms_interval = logBootstrapInterval(e.rms_dps, rms);
          break;
        }
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
