// Statistics of the model check: null summaries, spectrum, Haar step scan, the
// Gauss–Markov Allan fit, sample timing, Ljung–Box, sinusoid and outlier scores.
#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/FFT>

#include "processing/base/distributions.hpp"
#include "processing/model_check/detail.hpp"
#include "processing/model_check/model_check.hpp"

namespace gyrod::processing {

namespace model_check_detail {

double sortedQuantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return std::numeric_limits<double>::quiet_NaN();
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  const double f = pos - static_cast<double>(lo);
  return sorted[lo] + f * (sorted[hi] - sorted[lo]);
}

NullSummary summarizeNull(std::vector<double> values, double alpha, bool two_sided) {
  if (values.size() < 2)
    throw std::invalid_argument("the null distribution needs at least 2 replica values, got " +
                                std::to_string(values.size()));
  if (!(alpha > 0.0 && alpha < 0.5))
    throw std::invalid_argument("the null distribution needs a level alpha in (0, 0.5), got " + std::to_string(alpha));
  std::sort(values.begin(), values.end());
  NullSummary s;
  s.two_sided = two_sided;
  s.median = sortedQuantile(values, 0.5);
  if (two_sided) {
    s.spread = 0.5 * (sortedQuantile(values, 0.8413) - sortedQuantile(values, 0.1587));
    s.largest = std::max(std::fabs(values.front() - s.median), std::fabs(values.back() - s.median));
    s.threshold = std::max(s.largest, normalQuantile(1.0 - 0.5 * alpha) * s.spread);
  } else {
    // Gumbel: q = μ + β·(−ln(−ln p)); q50 − μ = 0.3665β, q90 − μ = 2.2504β.
    s.spread = (sortedQuantile(values, 0.9) - s.median) / (2.2504 - 0.3665);
    s.largest = values.back();
    s.threshold = std::max(s.largest, s.median + s.spread * (-std::log(-std::log1p(-alpha)) - 0.3665));
  }
  return s;
}

bool NullSummary::fires(double value) const {
  if (!std::isfinite(value)) return false;
  return two_sided ? std::fabs(value - median) > threshold : value > threshold;
}

double NullSummary::excess(double value) const {
  const double d = two_sided ? std::fabs(value - median) : value - median;
  return spread > 0.0 ? d / spread : (d > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
}

std::vector<double> blockMeans(std::span<const double> x, std::size_t length) {
  if (length == 0) throw std::invalid_argument("the block means need a block length of at least 1 sample, got 0");
  std::vector<double> out(x.size() / length);
  for (std::size_t b = 0; b < out.size(); ++b) {
    double s = 0.0;
    for (std::size_t i = 0; i < length; ++i) s += x[b * length + i];
    out[b] = s / static_cast<double>(length);
  }
  return out;
}

void removeLineInPlace(std::span<double> x) {
  const std::size_t n = x.size();
  if (n < 2) {
    if (n == 1) x[0] = 0.0;
    return;
  }
  // Centred index c = i − (n−1)/2, so the intercept is the mean and the slope Σc·x/Σc².
  const double mid = 0.5 * static_cast<double>(n - 1);
  double mean = 0.0, sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean += x[i];
  mean /= static_cast<double>(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double c = static_cast<double>(i) - mid;
    sxy += c * (x[i] - mean);
    sxx += c * c;
  }
  const double slope = sxy / sxx;
  for (std::size_t i = 0; i < n; ++i) x[i] -= mean + slope * (static_cast<double>(i) - mid);
}

std::size_t fftLength(std::size_t n) {
  // The smallest multiple of 4 ≥ n whose other factors are 2, 3 and 5 (the radices the FFT
  // handles fast; a multiple of 4 takes its real-input path): little zero padding.
  for (std::size_t m = (n + 3) / 4 * 4;; m += 4) {
    std::size_t r = m;
    for (std::size_t f : {2u, 3u, 5u})
      while (r % f == 0) r /= f;
    if (r == 1) return m;
  }
}

Periodogram hannPeriodogram(std::span<const double> x) {
  const std::size_t n = x.size();
  if (n < 4) throw std::invalid_argument("the periodogram needs at least 4 samples, got " + std::to_string(n));
  const std::size_t nfft = fftLength(n);
  // The windows of the last lengths this thread used (every replica of a round has the
  // record's length, and the narrowband scan also takes its halves; the cosines were ~4 % of a
  // check when made per call).
  struct HannWindow {
    std::vector<double> w;
    double power = 0.0;
  };
  thread_local std::array<HannWindow, 3> windows;
  thread_local std::size_t next_slot = 0;
  auto cached = std::find_if(windows.begin(), windows.end(), [n](const HannWindow& h) { return h.w.size() == n; });
  if (cached == windows.end()) {
    cached = windows.begin() + static_cast<std::ptrdiff_t>(next_slot);
    next_slot = (next_slot + 1) % windows.size();
    cached->w.resize(n);
    cached->power = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      cached->w[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n - 1));
      cached->power += cached->w[i] * cached->w[i];
    }
  }
  const std::vector<double>& window = cached->w;
  const double window_power = cached->power;
  // The FFT's buffers too: a fresh pair per call cost its page faults and zero fill (~3 % of a
  // check, whose base round takes three periodograms per replica).
  thread_local std::vector<double> in;
  thread_local std::vector<std::complex<double>> out;
  in.assign(nfft, 0.0);
  for (std::size_t i = 0; i < n; ++i) in[i] = window[i] * x[i];
  const double wp = window_power;
  // One per thread: its plan (the twiddles, ~3 % of a check when made per call) is cached
  // inside it, and that cache is not safe to share between threads.
  thread_local Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  fft.fwd(out, in);
  Periodogram p;
  p.nfft = nfft;
  p.window_power = wp;
  p.power.resize(nfft / 2 + 1);
  for (std::size_t k = 0; k <= nfft / 2; ++k) p.power[k] = std::norm(out[k]);
  return p;
}

std::vector<double> blockMedianLevels(const std::vector<double>& power,
                                      const std::function<std::size_t(std::size_t)>& width_at,
                                      std::size_t shortest_last) {
  const std::size_t n = power.size();
  std::vector<double> centres, levels;
  std::vector<double> scratch;
  std::size_t k = 1;
  while (k < n) {
    std::size_t end = std::min(n, k + width_at(k));
    if (n - end < shortest_last) end = n;  // no short last block: a median of a few bins is too noisy
    scratch.assign(power.begin() + static_cast<std::ptrdiff_t>(k), power.begin() + static_cast<std::ptrdiff_t>(end));
    const auto mid = scratch.begin() + static_cast<std::ptrdiff_t>(scratch.size() / 2);
    std::nth_element(scratch.begin(), mid, scratch.end());
    centres.push_back(0.5 * static_cast<double>(k + end - 1));
    levels.push_back(std::max(*mid, std::numeric_limits<double>::min()) / std::numbers::ln2);
    k = end;
  }
  // Interpolated geometrically: the logs once per block, not twice per bin (they were a few
  // per cent of a check).
  std::vector<double> log_levels(levels.size());
  for (std::size_t b = 0; b < levels.size(); ++b) log_levels[b] = std::log(levels[b]);
  std::vector<double> bg(n, levels.front());
  std::size_t j = 0;
  // Between two centres the level is exp(a + b·i): one exp where a segment begins, then a
  // product per bin (an exp per bin was several per cent of a check; the product's rounding
  // over a block of at most a few thousand bins stays below 1e-12 of the level).
  std::size_t segment = std::numeric_limits<std::size_t>::max();
  double level = 0.0, step = 1.0;
  for (std::size_t i = 1; i < n; ++i) {
    const double f = static_cast<double>(i);
    while (j + 1 < centres.size() && centres[j + 1] < f) ++j;
    if (f <= centres.front()) {
      bg[i] = levels.front();
    } else if (j + 1 >= centres.size()) {
      bg[i] = levels.back();
    } else {
      const double slope = (log_levels[j + 1] - log_levels[j]) / (centres[j + 1] - centres[j]);
      if (segment != j) {
        segment = j;
        level = std::exp(log_levels[j] + slope * (f - centres[j]));
        step = std::exp(slope);
      } else {
        level *= step;
      }
      bg[i] = level;
    }
  }
  return bg;
}

std::vector<double> spectralBackground(const std::vector<double>& power) {
  return blockMedianLevels(
      power, [](std::size_t k) { return std::clamp<std::size_t>(k / 8, 16, 128); }, 16);
}

SpectralPeak largestSpectralPeak(const std::vector<double>& power, const std::vector<double>& background,
                                 std::size_t k_lo, std::size_t k_hi) {
  SpectralPeak best;
  k_hi = std::min(k_hi, power.size() - 1);
  for (std::size_t k = k_lo; k <= k_hi; ++k) {
    const double r = power[k] / background[k];
    if (r > best.ratio) {
      best.ratio = r;
      best.bin = k;
    }
  }
  return best;
}

std::vector<double> bandAveragedPsd(const Periodogram& p, double rate_hz, std::span<const double> edges_hz,
                                    std::vector<double>* band_max) {
  std::vector<double> psd;
  if (band_max) band_max->clear();
  const double df = rate_hz / static_cast<double>(p.nfft);
  // One-sided density: 2|X_k|²/(fs·Σw²) (Hann window, Σw² its power).
  const double scale = 2.0 / (rate_hz * p.window_power);
  for (std::size_t j = 0; j + 1 < edges_hz.size(); ++j) {
    const auto lo = static_cast<std::size_t>(std::ceil(edges_hz[j] / df));
    const auto hi = std::min(p.power.size(), static_cast<std::size_t>(std::ceil(edges_hz[j + 1] / df)));
    double s = 0.0, m = 0.0;
    std::size_t c = 0;
    for (std::size_t k = std::max<std::size_t>(lo, 1); k < hi; ++k, ++c) {
      s += p.power[k];
      m = std::max(m, p.power[k]);
    }
    psd.push_back(c > 0 ? scale * s / static_cast<double>(c) : std::numeric_limits<double>::quiet_NaN());
    if (band_max) band_max->push_back(c > 0 ? scale * m : std::numeric_limits<double>::quiet_NaN());
  }
  return psd;
}

HaarScan haarScan(std::span<const double> y, std::size_t w) {
  HaarScan s;
  const std::size_t n = y.size();
  if (w == 0 || 2 * w > n) return s;
  std::vector<double> prefix(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + y[i];
  const double inv = 1.0 / static_cast<double>(w);
  std::vector<double> abs_d;
  abs_d.reserve(n - 2 * w + 1);
  for (std::size_t t = w; t + w <= n; ++t) {
    const double d = (prefix[t + w] - prefix[t]) * inv - (prefix[t] - prefix[t - w]) * inv;
    abs_d.push_back(std::fabs(d));
    s.sum_squares += d * d;
    ++s.count;
    if (std::fabs(d) > s.max_abs) {
      s.max_abs = std::fabs(d);
      s.argmax = t;
      s.value_at_max = d;
    }
  }
  const auto mid = abs_d.begin() + static_cast<std::ptrdiff_t>(abs_d.size() / 2);
  std::nth_element(abs_d.begin(), mid, abs_d.end());
  s.median_abs = *mid;
  return s;
}

namespace {

// Weighted NNLS of `variance` on the given columns (each a function of τ), rows scaled by
// √(edf/2)/ref. Returns the residual and the coefficients.
NonNegativeLeastSquares weightedCurveFit(const Eigen::MatrixXd& basis, std::span<const double> variance,
                                         std::span<const double> edf, const std::vector<double>& ref) {
  const Eigen::Index n = basis.rows();
  Eigen::MatrixXd a = basis;
  Eigen::VectorXd b(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const auto u = static_cast<std::size_t>(j);
    const double w = std::sqrt(edf[u] / 2.0) / ref[u];
    a.row(j) *= w;
    b(j) = variance[u] * w;
  }
  return solveNonNegativeLeastSquares(a, b);
}

}  // namespace

GaussMarkovCurveFit fitGaussMarkovToAllan(std::span<const double> tau_s, std::span<const double> variance,
                                          std::span<const double> edf, std::span<const double> t_grid) {
  const auto n = static_cast<Eigen::Index>(tau_s.size());
  if (tau_s.size() != variance.size() || tau_s.size() != edf.size() || n < 7 || t_grid.empty())
    throw std::invalid_argument(
        "the Gauss-Markov fit to the Allan curve needs at least 7 points with a variance and edf, and a grid of "
        "correlation times");
  Eigen::MatrixXd five(n, static_cast<Eigen::Index>(kNoiseTermCount));
  for (Eigen::Index j = 0; j < n; ++j)
    for (std::size_t i = 0; i < kNoiseTermCount; ++i)
      five(j, static_cast<Eigen::Index>(i)) =
          std::pow(tau_s[static_cast<std::size_t>(j)], noiseTermVariancePower(kAllNoiseTerms[i]));
  Eigen::MatrixXd six(n, static_cast<Eigen::Index>(kNoiseTermCount) + 1);
  six.leftCols(static_cast<Eigen::Index>(kNoiseTermCount)) = five;

  auto setGmColumn = [&](double t) {
    for (Eigen::Index j = 0; j < n; ++j)
      six(j, static_cast<Eigen::Index>(kNoiseTermCount)) =
          gaussMarkovAllanVariance(tau_s[static_cast<std::size_t>(j)], t, 1.0);
  };
  auto bestOverGrid = [&](const std::vector<double>& ref, double& best_t) {
    NonNegativeLeastSquares best;
    best.residual_squared = std::numeric_limits<double>::infinity();
    for (double t : t_grid) {
      setGmColumn(t);
      NonNegativeLeastSquares s = weightedCurveFit(six, variance, edf, ref);
      if (s.residual_squared < best.residual_squared) {
        best = std::move(s);
        best_t = t;
      }
    }
    return best;
  };

  std::vector<double> ref(variance.begin(), variance.end());
  double t_best = t_grid[0];
  NonNegativeLeastSquares first = bestOverGrid(ref, t_best);
  setGmColumn(t_best);
  const Eigen::VectorXd model = six * first.x;
  for (std::size_t j = 0; j < ref.size(); ++j)
    ref[j] = std::max(model(static_cast<Eigen::Index>(j)), 0.1 * variance[j]);

  GaussMarkovCurveFit fit;
  fit.chi2_base = weightedCurveFit(five, variance, edf, ref).residual_squared;
  const NonNegativeLeastSquares second = bestOverGrid(ref, t_best);
  fit.chi2_with_gm = std::min(second.residual_squared, fit.chi2_base);
  fit.improvement = fit.chi2_base - fit.chi2_with_gm;
  fit.tau_s = t_best;
  fit.sigma_dps = std::sqrt(std::max(0.0, second.x(static_cast<Eigen::Index>(kNoiseTermCount))));
  for (std::size_t i = 0; i < kNoiseTermCount; ++i)
    fit.terms_with_gm.set(kAllNoiseTerms[i],
                          noiseTermFromCoefficient(kAllNoiseTerms[i], second.x(static_cast<Eigen::Index>(i))));
  return fit;
}

bool levinsonFromAutocovariance(std::span<const double> gamma, std::size_t order, std::vector<double>& phi,
                                double& noise_var) {
  if (gamma.size() < order + 1 || !(gamma[0] > 0.0)) return false;
  phi.assign(order, 0.0);
  std::vector<double> prev(order, 0.0);
  double v = gamma[0];
  for (std::size_t k = 1; k <= order; ++k) {
    double acc = gamma[k];
    for (std::size_t i = 1; i < k; ++i) acc -= prev[i - 1] * gamma[k - i];
    const double kappa = acc / v;
    if (!(std::fabs(kappa) < 1.0)) return false;
    phi[k - 1] = kappa;
    for (std::size_t i = 1; i < k; ++i) phi[i - 1] = prev[i - 1] - kappa * prev[k - i - 1];
    v *= 1.0 - kappa * kappa;
    std::copy(phi.begin(), phi.begin() + static_cast<std::ptrdiff_t>(k), prev.begin());
  }
  noise_var = v;
  return v > 0.0;
}

}  // namespace model_check_detail

using namespace model_check_detail;

std::string_view modelEffectName(ModelEffect e) {
  switch (e) {
    case ModelEffect::TemperatureBias: return "temperature_bias";
    case ModelEffect::Sinusoid: return "sinusoid";
    case ModelEffect::GaussMarkov: return "gauss_markov";
    case ModelEffect::BiasSteps: return "bias_steps";
    case ModelEffect::Outliers: return "outliers";
    case ModelEffect::SampleGaps: return "sample_gaps";
    case ModelEffect::NarrowbandLine: return "narrowband_line";
    case ModelEffect::Unexplained: return "unexplained";
  }
  throw std::invalid_argument("unknown model effect");
}

double gaussMarkovAllanVariance(double tau_s, double correlation_time_s, double sigma_dps) {
  if (!(tau_s > 0.0) || !(correlation_time_s > 0.0) || !std::isfinite(sigma_dps))
    throw std::invalid_argument("the Gauss-Markov Allan variance needs tau and T > 0 and a finite sigma");
  const double x = tau_s / correlation_time_s;
  // bracket = 1 − (3 − 4e^{−x} + e^{−2x})/(2x); below x = 0.01 its series
  // x²/3 − x³/4 + 7x⁴/60 − x⁵/24 avoids the cancellation.
  double bracket;
  if (x < 0.01) {
    bracket = x * x * (1.0 / 3.0 - x * (0.25 - x * (7.0 / 60.0 - x / 24.0)));
  } else {
    bracket = 1.0 - (-4.0 * std::expm1(-x) + std::expm1(-2.0 * x)) / (2.0 * x);
  }
  const double qc = 2.0 * sigma_dps * sigma_dps / correlation_time_s;
  return qc * correlation_time_s * correlation_time_s / tau_s * bracket;
}

SampleTiming analyzeSampleTiming(std::span<const double> t) {
  SampleTiming s;
  if (t.size() < 3)
    throw std::invalid_argument("the sample timing check needs at least 3 times, got " + std::to_string(t.size()));
  std::vector<double> dt(t.size() - 1);
  for (std::size_t i = 0; i + 1 < t.size(); ++i) {
    dt[i] = t[i + 1] - t[i];
    if (!std::isfinite(dt[i]) || !(dt[i] > 0.0))
      throw std::invalid_argument("the sample timing check needs finite, increasing times (at index " +
                                  std::to_string(i + 1) + ")");
  }
  std::vector<double> sorted = dt;
  std::sort(sorted.begin(), sorted.end());
  s.median_spacing_s = sortedQuantile(sorted, 0.5);
  std::vector<double> regular;
  for (std::size_t i = 0; i < dt.size(); ++i) {
    if (dt[i] > 1.5 * s.median_spacing_s) {
      ++s.gaps;
      const double missing = std::round(dt[i] / s.median_spacing_s) - 1.0;
      s.lost += static_cast<std::size_t>(std::max(0.0, missing));
      s.gap_times_s.push_back(t[i]);
    } else {
      regular.push_back(dt[i]);
    }
  }
  std::sort(regular.begin(), regular.end());
  if (regular.size() >= 4)
    s.jitter = 0.5 * (sortedQuantile(regular, 0.8413) - sortedQuantile(regular, 0.1587)) / s.median_spacing_s;
  return s;
}

LjungBox ljungBoxTest(std::span<const double> x, std::size_t lags, std::size_t fitted_parameters) {
  const std::size_t n = x.size();
  if (lags == 0 || n <= lags + 1)
    throw std::invalid_argument("the Ljung-Box test needs at least 1 lag and more samples than lags + 1 (" +
                                std::to_string(lags) + " lags, " + std::to_string(n) + " samples)");
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  double c0 = 0.0;
  for (double v : x) c0 += (v - mean) * (v - mean);
  LjungBox lb;
  if (!(c0 > 0.0))
    throw std::invalid_argument("the Ljung-Box test needs a series that varies; this one is constant (every value " +
                                std::to_string(mean) + ")");
  const double nn = static_cast<double>(n);
  for (std::size_t k = 1; k <= lags; ++k) {
    double ck = 0.0;
    for (std::size_t i = k; i < n; ++i) ck += (x[i] - mean) * (x[i - k] - mean);
    const double rho = ck / c0;
    lb.q += rho * rho / (nn - static_cast<double>(k));
  }
  lb.q *= nn * (nn + 2.0);
  lb.dof = lags > fitted_parameters ? lags - fitted_parameters : 1;
  lb.p_value = 1.0 - chiSquareCdf(lb.q, static_cast<double>(lb.dof));
  return lb;
}

SinusoidFit fitSinusoidAt(std::span<const double> x, double rate_hz, double freq_hz) {
  // Normal equations of [sin, cos] (2×2), exact for any length (no orthogonality assumed).
  double ss = 0.0, cc = 0.0, sc = 0.0, xs = 0.0, xc = 0.0;
  const double w = 2.0 * std::numbers::pi * freq_hz / rate_hz;
  // The sin/cos of w·i by rotation, resynchronised every 1024 samples against drift.
  double s = 0.0, c = 1.0;
  const double sw = std::sin(w), cw = std::cos(w);
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (i % 1024 == 0) {
      s = std::sin(w * static_cast<double>(i));
      c = std::cos(w * static_cast<double>(i));
    }
    ss += s * s;
    cc += c * c;
    sc += s * c;
    xs += x[i] * s;
    xc += x[i] * c;
    const double s_next = s * cw + c * sw;
    c = c * cw - s * sw;
    s = s_next;
  }
  const double det = ss * cc - sc * sc;
  SinusoidFit f;
  f.freq_hz = freq_hz;
  if (!(std::fabs(det) > 0.0)) return f;
  const double a = (xs * cc - xc * sc) / det;
  const double b = (xc * ss - xs * sc) / det;
  f.amp_dps = std::hypot(a, b);
  f.phase_rad = std::atan2(b, a);
  return f;
}

std::vector<double> localOutlierScores(std::span<const double> x, std::size_t h) {
  const std::size_t n = x.size();
  if (h == 0 || n < 2 * h + 2)
    throw std::invalid_argument("the outlier scores need at least " + std::to_string(2 * h + 2) +
                                " samples for a half-window of " + std::to_string(h) + ", got " + std::to_string(n));
  std::vector<double> prefix(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + x[i];
  std::vector<double> d(n);
  for (std::size_t i = 0; i < n; ++i) {
    // h neighbours on each side; at the ends, the 2h nearest on one side.
    std::size_t lo = i >= h ? i - h : 0;
    std::size_t hi = std::min(n, lo + 2 * h + 1);
    if (hi == n) lo = n - (2 * h + 1);
    const double sum = prefix[hi] - prefix[lo] - x[i];
    d[i] = x[i] - sum / static_cast<double>(2 * h);
  }
  std::vector<double> a(n);
  for (std::size_t i = 0; i < n; ++i) a[i] = std::fabs(d[i]);
  const auto mid = a.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(a.begin(), mid, a.end());
  // The differences are centred (their mean over the window is ~0), so |d| about 0 is the MAD.
  const double scale = 1.4826 * *mid;
  for (double& v : d) v = scale > 0.0 ? v / scale : 0.0;
  return d;
}

}  // namespace gyrod::processing
