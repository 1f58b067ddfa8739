// The live check against the board's baseline (live_check.hpp, docs/live-check.md).
#include "processing/model_check/live_check.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <unsupported/Eigen/FFT>
#include <utility>

#include "processing/base/distributions.hpp"
#include "processing/model_check/model_check.hpp"

namespace gyrod::processing {

namespace {

constexpr double kSecondsPerWeek = 7.0 * 86400.0;
constexpr std::size_t kLiveDetectors = 4;  // lines, outlier bursts, bias steps, temperature couplings
constexpr std::size_t kOutlierHalfWindow = 10;
// The lowest bins are left out of the line search: below ~0.5 Hz a board's slow noise
// (flicker, random walk) moves the power from one interval to the next more than Welch's
// degrees of freedom allow, and a fan or motor line sits higher.
constexpr double kLowestLineHz = 0.5;
// A line's run extends to its neighbours above this tail (its edges and the window's spread).
constexpr double kRunEdgeAlpha = 1e-3;
// An effect is gone when its bins (or its outlier count) are no longer significant at this.
constexpr double kGoneAlpha = 0.01;
// The baseline's own lines are looked for at this family alpha per interval.
constexpr double kBaselineLineAlpha = 1e-3;
// Two lines closer than their half widths plus this are one.
constexpr double kSameLineHz = 0.1;
// A run of at most this many bins is a steady sinusoid's Hann main lobe (4 bins wide, one more
// for the run's edges).
constexpr std::size_t kSinusoidRunBins = 6;

// Equivalent degrees of freedom of a Welch estimate of K Hann segments at 50 % overlap
// (Percival & Walden 1993, eq. 292b).
double welchDof(std::size_t segments) {
  const double k = static_cast<double>(segments);
  return 36.0 * k * k / (19.0 * k - 1.0);
}

std::string formatSeconds(double s) { return std::to_string(static_cast<long long>(std::llround(s))) + " s"; }
std::string formatHz(double f) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g Hz", f);
  return buf;
}
std::string formatRatio(double r) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", r);
  return buf;
}

std::string formatDps(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g deg/s", v);
  return buf;
}

// Means of consecutive blocks of `block` samples (a last, partial block left out).
std::vector<double> blockMeans(std::span<const double> x, std::size_t block) {
  std::vector<double> out;
  if (block == 0) return out;
  out.reserve(x.size() / block);
  for (std::size_t s = 0; s + block <= x.size(); s += block) {
    double sum = 0.0;
    for (std::size_t i = s; i < s + block; ++i) sum += x[i];
    out.push_back(sum / static_cast<double>(block));
  }
  return out;
}

double meanOf(const std::vector<double>& y, std::size_t from, std::size_t to) {
  double sum = 0.0;
  for (std::size_t j = from; j < to; ++j) sum += y[j];
  return sum / static_cast<double>(to - from);
}

// The residual sum of squares of one step fitted to y[first, n) at each boundary c (the mean
// before it and the mean after it); infinity where no step fits.
std::vector<double> oneStepRss(const std::vector<double>& y, std::size_t first) {
  const std::size_t n = y.size();
  std::vector<double> rss(n, std::numeric_limits<double>::infinity());
  for (std::size_t c = first + 1; c < n; ++c) {
    const double a = meanOf(y, first, c), b = meanOf(y, c, n);
    double sum = 0.0;
    for (std::size_t j = first; j < n; ++j) sum += (y[j] - (j < c ? a : b)) * (y[j] - (j < c ? a : b));
    rss[c] = sum;
  }
  return rss;
}

// Two-sided P(|T| > |t|) for Student's t with `dof` degrees of freedom.
double twoSidedT(double t, double dof) { return 2.0 * studentTUpperTail(std::fabs(t), dof); }

// P(N ≥ c) for N ~ Poisson(mu).
double poissonUpperTail(std::size_t c, double mu) {
  if (c == 0) return 1.0;
  double term = std::exp(-mu), below = 0.0;
  for (std::size_t k = 0; k < c; ++k) {
    below += term;
    term *= mu / static_cast<double>(k + 1);
  }
  return std::max(0.0, 1.0 - below);
}

double hannSumOfSquares(std::size_t seg) {
  double s = 0.0;
  for (std::size_t i = 0; i < seg; ++i) {
    const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(seg));
    s += w * w;
  }
  return s;
}

// Hann-windowed periodogram of x (mean removed) at every Fourier bin 0..n/2, and Σw².
std::vector<double> hannPeriodogram(std::span<const double> x, double* sum_w2) {
  const std::size_t n = x.size();
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  std::vector<double> in(n);
  double w2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n));
    in[i] = w * (x[i] - mean);
    w2 += w * w;
  }
  std::vector<std::complex<double>> spec;
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  fft.fwd(spec, in);
  std::vector<double> p(n / 2 + 1);
  for (std::size_t k = 0; k <= n / 2; ++k) p[k] = std::norm(spec[k]);
  *sum_w2 = w2;
  return p;
}

// The f with P(F > f) = p for F ~ F(2, d2), whose tail is exactly (1 + 2f/d2)^(−d2/2): a
// periodogram bin (χ²(2)/2) over a Welch level of d2 degrees of freedom.
double f2UpperQuantile(double p, double d2) { return 0.5 * d2 * (std::pow(p, -2.0 / d2) - 1.0); }

// A line's onset in the window x (data time t0 at its first sample): x demodulated at the
// line's centre in blocks of 10 s, and a step fitted to the blocks' complex sums by least
// squares (0 before it, their mean after it: a steady line keeps its phase from block to
// block, so the fit gains on every block it spans, where the blocks' power alone would not).
// The 95 % interval holds the onsets whose cost is within 3.84 of the best in units of a
// block's noise (`sigma2` is the white variance the baseline's level stands for there); a
// line there from the window's first block may have begun as early as `earliest_t` (the start of
// the interval examined before the window: a weak line can hide in one interval). Returns the
// amplitude after the onset, its 95 % half-width, for the rms.
std::pair<double, double> estimateLineOnset(std::span<const double> x, double centre_hz, double sigma2, double t0,
                                            double rate_hz, double earliest_t, LiveEffect& e) {
  const auto block = static_cast<std::size_t>(std::max(1.0, std::round(10.0 * rate_hz)));
  const std::size_t m = x.size() / block;
  if (m < 2 || !(sigma2 > 0.0)) return {0.0, 0.0};
  const double w = 2.0 * std::numbers::pi * centre_hz / rate_hz;
  std::vector<std::complex<double>> z(m);
  for (std::size_t j = 0; j < m; ++j) {
    std::complex<double> sum = 0.0;
    for (std::size_t i = j * block; i < (j + 1) * block; ++i)
      sum += x[i] * std::polar(1.0, -w * static_cast<double>(i));
    z[j] = sum;
  }
  const double noise = static_cast<double>(block) * sigma2;  // E|sum|² of the noise in a block
  std::vector<double> cost(m, 0.0);
  for (std::size_t c = 0; c < m; ++c) {
    double before = 0.0, after_sq = 0.0;
    std::complex<double> after_sum = 0.0;
    for (std::size_t j = 0; j < c; ++j) before += std::norm(z[j]);
    for (std::size_t j = c; j < m; ++j) {
      after_sum += z[j];
      after_sq += std::norm(z[j]);
    }
    cost[c] = (before + after_sq - std::norm(after_sum) / static_cast<double>(m - c)) / noise;
  }
  const auto best = static_cast<std::size_t>(std::min_element(cost.begin(), cost.end()) - cost.begin());
  std::size_t c_lo = best, c_hi = best;
  for (std::size_t c = 0; c < m; ++c)
    if (cost[c] - cost[best] <= 3.84) {
      c_lo = std::min(c_lo, c);
      c_hi = std::max(c_hi, c);
    }
  const auto at = [&](std::size_t c) { return t0 + static_cast<double>(c * block) / rate_hz; };
  e.onset_t = at(best);
  e.onset_95 = {c_lo == 0 ? std::min(at(0), earliest_t) : at(c_lo), at(c_hi) + static_cast<double>(block) / rate_hz};
  std::complex<double> mean = 0.0;
  for (std::size_t j = best; j < m; ++j) mean += z[j];
  const double after = static_cast<double>(m - best);
  mean /= after;
  // A sinusoid of amplitude A sums to A·block/2 in a block; the mean's noise is
  // noise/after in |.|², half of it along the mean's direction.
  const double bias_free = std::sqrt(std::max(0.0, std::norm(mean) - noise / after));
  const double half = 1.96 * std::sqrt(noise / (2.0 * after));
  return {2.0 * bias_free / static_cast<double>(block), 2.0 * half / static_cast<double>(block)};
}

}  // namespace

LiveMotionRule::LiveMotionRule(double rate_hz)
    : limit_(std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(kLiveMotionBreakS * rate_hz)))) {}

LiveMotionRule::Verdict LiveMotionRule::next(bool still) {
  moving_ = still ? 0 : moving_ + 1;
  if (moving_ < limit_) return Verdict::Keep;
  return moving_ == limit_ ? Verdict::Break : Verdict::Skip;
}

const char* liveEffectName(LiveEffectKind kind) {
  switch (kind) {
    case LiveEffectKind::Line: return "line";
    case LiveEffectKind::OutlierBurst: return "outlier_burst";
    case LiveEffectKind::BiasStep: return "bias_step";
    case LiveEffectKind::TemperatureBias: return "temperature_bias";
  }
  return "?";
}

std::vector<double> welchPowerSum(std::span<const double> x, std::size_t seg, std::size_t* segments) {
  std::vector<double> power(seg / 2 + 1, 0.0);
  std::vector<double> w(seg), in(seg);
  for (std::size_t i = 0; i < seg; ++i)
    w[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(seg));
  std::vector<std::complex<double>> spec;
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::size_t count = 0;
  for (std::size_t s = 0; s + seg <= x.size(); s += seg / 2, ++count) {
    double mean = 0.0;
    for (std::size_t i = 0; i < seg; ++i) mean += x[s + i];
    mean /= static_cast<double>(seg);
    for (std::size_t i = 0; i < seg; ++i) in[i] = w[i] * (x[s + i] - mean);
    fft.fwd(spec, in);
    for (std::size_t k = 0; k <= seg / 2; ++k) power[k] += std::norm(spec[k]);
  }
  if (segments != nullptr) *segments = count;
  return power;
}

double fUpperTail(double f, double d1, double d2) {
  if (!(f > 0.0)) return 1.0;
  // Paulson: z = ((1 − 2/(9d2))·f^(1/3) − (1 − 2/(9d1))) / √(2/(9d2)·f^(2/3) + 2/(9d1)).
  const double a = 2.0 / (9.0 * d1), b = 2.0 / (9.0 * d2), c = std::cbrt(f);
  const double z = ((1.0 - b) * c - (1.0 - a)) / std::sqrt(b * c * c + a);
  return 1.0 - normalCdf(z);
}

double fUpperQuantile(double p, double d1, double d2) {
  double lo = std::log(1e-6), hi = std::log(1e6);
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (fUpperTail(std::exp(mid), d1, d2) > p ? lo : hi) = mid;
  }
  return std::exp(0.5 * (lo + hi));
}

LiveCheck::LiveCheck(const LiveCheckSettings& settings) : settings_(settings) {
  if (!(settings.rate_hz > 0.0) || !std::isfinite(settings.rate_hz))
    throw std::invalid_argument("live check: rate_hz must be > 0");
  if (!(settings.interval_s > 0.0) || !std::isfinite(settings.interval_s))
    throw std::invalid_argument("live check: interval_s must be > 0");
  if (!(settings.baseline_s >= settings.interval_s) || !std::isfinite(settings.baseline_s))
    throw std::invalid_argument("live check: baseline_s must be >= interval_s");
  if (!(settings.false_alarms_per_week > 0.0) || !std::isfinite(settings.false_alarms_per_week))
    throw std::invalid_argument("live check: false_alarms_per_week must be > 0");
  interval_samples_ = static_cast<std::size_t>(std::llround(settings.interval_s * settings.rate_hz));
  if (interval_samples_ < 8 * 64)
    throw std::invalid_argument("live check: interval_s must hold at least 512 samples at the rate");
  segment_ = 64;
  while (segment_ * 2 <= interval_samples_ / 16 && segment_ < 1024) segment_ *= 2;
  segment_w2_ = hannSumOfSquares(segment_);
  baseline_needed_ = static_cast<std::size_t>(std::ceil(settings.baseline_s / settings.interval_s - 1e-9));
  for (double k : settings.temperature_coefficient_dps_per_c)
    if (!std::isfinite(k)) throw std::invalid_argument("live check: temperature_coefficient_dps_per_c must be finite");
  block_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(kLiveBlockS * settings.rate_hz)));
  blocks_ = interval_samples_ / block_;
  if (blocks_ >= 2) {
    for (std::size_t s = 1; s <= blocks_ / 2; s *= 2) scales_.push_back(s);
    if (scales_.back() != blocks_ / 2) scales_.push_back(blocks_ / 2);
    scales_.push_back(blocks_);
  }
  for (AllanPool& p : pool_) {
    p.sum_half_d2.assign(scales_.size(), 0.0);
    p.terms.assign(scales_.size(), 0.0);
    p.dof.assign(scales_.size(), 0.0);
  }
  level_since_t_.fill(-std::numeric_limits<double>::infinity());
  const double intervals_per_week = kSecondsPerWeek / settings.interval_s;
  alpha_ =
      settings.false_alarms_per_week / (intervals_per_week * static_cast<double>(kLiveDetectors * baseline_.size()));
}

LiveCheck::AxisInterval LiveCheck::prepare(std::span<const double> x) const {
  AxisInterval in;
  in.scores = localOutlierScores(x, kOutlierHalfWindow);
  in.cleaned.assign(x.begin(), x.end());
  // An outlier spreads its power over every bin: it is the burst detector's, not a line.
  for (std::size_t i = 0; i < x.size(); ++i)
    if (std::fabs(in.scores[i]) > kLiveOutlierZ)
      in.cleaned[i] = (i > 0 && i + 1 < x.size()) ? 0.5 * (x[i - 1] + x[i + 1]) : (i > 0 ? x[i - 1] : x[i + 1]);
  in.power = welchPowerSum(in.cleaned, segment_, &in.segments);
  for (double& p : in.power) p /= static_cast<double>(std::max<std::size_t>(1, in.segments));
  return in;
}

double LiveCheck::outlierRate(std::size_t axis) const {
  const AxisBaseline& b = baseline_[axis];
  return (b.outliers + 0.5) / std::max(1.0, b.samples);  // half an outlier: no zero rate
}

// The baseline's level at frequency f, in |X|² of a Hann window with Σw² = sum_w2 (linear
// between its Welch bins).
double LiveCheck::baselineLevel(std::size_t axis, double f_hz, double sum_w2) const {
  const std::vector<double>& bg = baseline_[axis].background;
  const double pos = f_hz / (settings_.rate_hz / static_cast<double>(segment_));
  const auto k = std::min(static_cast<std::size_t>(pos), bg.size() - 2);
  const double frac = pos - static_cast<double>(k);
  return ((1.0 - frac) * bg[k] + frac * bg[k + 1]) / segment_w2_ * sum_w2;
}

void LiveCheck::finishBaseline() {
  const double length_s = static_cast<double>(interval_samples_) / settings_.rate_hz;
  for (std::size_t a = 0; a < baseline_.size(); ++a) {
    AxisBaseline& b = baseline_[a];
    const std::size_t bins = b.power.size();
    b.background.assign(bins, 0.0);
    for (std::size_t k = 0; k < bins; ++k) {
      const std::size_t lo = k >= 4 ? k - 4 : 0, hi = std::min(bins - 1, k + 4);
      std::vector<double> near(b.power.begin() + static_cast<std::ptrdiff_t>(lo),
                               b.power.begin() + static_cast<std::ptrdiff_t>(hi + 1));
      std::nth_element(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(near.size() / 2), near.end());
      // The median of a bin's χ²(ν)/ν neighbours sits below their mean by about 1 − 2/(3ν)·…;
      // with ν in the hundreds that is under 1 %, left as it is.
      b.background[k] = near[near.size() / 2] / static_cast<double>(b.segments);
    }
    // The lines the board already has, found in each baseline interval as a new one would be,
    // at a looser alpha (missing one here costs a false alarm later).
    for (std::size_t i = 0; i < b.intervals.size(); ++i)
      for (const LiveEffect& e :
           findLines(a, b.intervals[i], static_cast<double>(i) * length_s, 0.0, kBaselineLineAlpha)) {
        auto same = std::find_if(b.lines.begin(), b.lines.end(), [&e](const BaselineLine& l) {
          return std::fabs(l.centre_hz - e.centre_hz) <= 0.5 * (l.width_hz + e.width_hz) + kSameLineHz;
        });
        if (same == b.lines.end()) {
          b.lines.push_back({e.centre_hz, e.width_hz, e.rms_dps_95.hi});
        } else {
          // One line found at two frequencies (a line that wanders): it covers both.
          same->rms_dps = std::max(same->rms_dps, e.rms_dps_95.hi);
          const double lo = std::min(same->centre_hz - 0.5 * same->width_hz, e.centre_hz - 0.5 * e.width_hz);
          const double hi = std::max(same->centre_hz + 0.5 * same->width_hz, e.centre_hz + 0.5 * e.width_hz);
          same->centre_hz = 0.5 * (lo + hi);
          same->width_hz = hi - lo;
        }
      }
    std::vector<std::vector<double>>().swap(b.intervals);
  }
}

const LiveCheck::BaselineLine* LiveCheck::baselineLine(std::size_t axis, const LiveEffect& e) const {
  for (const BaselineLine& l : baseline_[axis].lines)
    if (std::fabs(l.centre_hz - e.centre_hz) <= 0.5 * (l.width_hz + e.width_hz) + kSameLineHz) return &l;
  return nullptr;
}

std::vector<LiveEffect> LiveCheck::findLines(std::size_t axis, std::span<const double> window, double t0,
                                             double earliest_t, double alpha) const {
  std::vector<LiveEffect> found;
  const std::size_t n = window.size();
  double w2 = 0.0;
  const std::vector<double> p = hannPeriodogram(window, &w2);
  const double df = settings_.rate_hz / static_cast<double>(n);
  const auto first = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(kLowestLineHz / df)));
  const std::size_t last = n / 2 - 1;
  if (last <= first) return found;
  const double nu_b = welchDof(baseline_[axis].segments);
  const double threshold = f2UpperQuantile(alpha / static_cast<double>(last - first + 1), nu_b);
  const double edge = f2UpperQuantile(kRunEdgeAlpha, nu_b);
  std::vector<double> level(last + 1, 0.0), ratio(last + 1, 0.0);
  for (std::size_t k = first; k <= last; ++k) {
    level[k] = baselineLevel(axis, static_cast<double>(k) * df, w2);
    ratio[k] = level[k] > 0.0 ? p[k] / level[k] : 0.0;
  }
  const double scale = 2.0 / (static_cast<double>(n) * w2);  // |X|² → (°/s)² in the bin
  for (std::size_t k = first; k <= last;) {
    if (ratio[k] <= threshold) {
      ++k;
      continue;
    }
    std::size_t lo = k, hi = k;
    while (hi + 1 <= last && ratio[hi + 1] > edge) ++hi;
    while (lo > first && ratio[lo - 1] > edge) --lo;
    LiveEffect e;
    e.kind = LiveEffectKind::Line;
    e.axis = axis;
    double excess = 0.0, weighted = 0.0, sd_excess = 0.0, peak = 0.0, level_sum = 0.0;
    for (std::size_t j = lo; j <= hi; ++j) {
      const double d = std::max(0.0, p[j] - level[j]);
      excess += d;
      weighted += d * static_cast<double>(j) * df;
      sd_excess += std::sqrt(2.0 * d * level[j] + level[j] * level[j]);  // |s + noise|²: 2|s|²σ² + σ⁴
      peak = std::max(peak, ratio[j]);
      level_sum += level[j];
    }
    e.centre_hz = excess > 0.0 ? weighted / excess : static_cast<double>(k) * df;
    e.width_hz = static_cast<double>(hi - lo + 1) * df;
    e.power_ratio = peak;
    // The run's bins share the window's main lobe: their errors add as fully correlated.
    const double var = excess * scale, half = 1.96 * sd_excess * scale;
    // The white variance the baseline's level stands for there (E|X|² = σ²Σw²), and
    // Cramér–Rao for a sinusoid's frequency in it: var(ω) = 12σ²/(A²n³), A² = 2·rms².
    const double sigma2 = level_sum / static_cast<double>(hi - lo + 1) / w2;
    const double nn = static_cast<double>(n);
    const double sd_f =
        var > 0.0 ? settings_.rate_hz / (2.0 * std::numbers::pi) * std::sqrt(12.0 * sigma2 / (2.0 * var * nn * nn * nn))
                  : df;
    const double half_f = std::max(1.96 * sd_f, 0.5 * df);
    e.centre_hz_95 = {e.centre_hz - half_f, e.centre_hz + half_f};
    e.evidence = "periodogram over the last " + formatSeconds(nn / settings_.rate_hz) + " at " + formatHz(e.centre_hz) +
                 " stands " + formatRatio(peak) + " x the baseline's level (threshold " + formatRatio(threshold) + ")";
    const auto [amp, amp_half] = estimateLineOnset(window, e.centre_hz, sigma2, t0, settings_.rate_hz, earliest_t, e);
    if (hi - lo + 1 <= kSinusoidRunBins) {
      // Narrow as a steady sinusoid's main lobe: its amplitude from the demodulated blocks
      // after the onset (the window's spectrum holds it only for the part it spans).
      e.rms_dps = amp / std::sqrt(2.0);
      e.rms_dps_95 = {std::max(0.0, amp - amp_half) / std::sqrt(2.0), (amp + amp_half) / std::sqrt(2.0)};
    } else {
      // Wider (a line whose frequency wanders): its power above the baseline in the run,
      // averaged over the window.
      e.rms_dps = std::sqrt(var);
      e.rms_dps_95 = {std::sqrt(std::max(0.0, var - half)), std::sqrt(var + half)};
    }
    found.push_back(e);
    k = hi + 1;
  }
  return found;
}

std::optional<LiveEffect> LiveCheck::findOutlierBurst(std::size_t axis, const AxisInterval& in, double t0,
                                                      bool contiguous) const {
  std::size_t count = 0, first = 0;
  double largest = 0.0;
  for (std::size_t i = 0; i < in.scores.size(); ++i)
    if (std::fabs(in.scores[i]) > kLiveOutlierZ) {
      if (count++ == 0) first = i;
      largest = std::max(largest, std::fabs(in.scores[i]));
    }
  const double expected = outlierRate(axis) * static_cast<double>(in.scores.size());
  const double p = poissonUpperTail(count, expected);
  if (count == 0 || p >= alpha_) return std::nullopt;
  LiveEffect e;
  e.kind = LiveEffectKind::OutlierBurst;
  e.axis = axis;
  e.t = t0 + static_cast<double>(interval_samples_) / settings_.rate_hz;
  e.count = count;
  e.expected = expected;
  e.largest_z = largest;
  // It began after the last interval without outliers ended and by the first outlier; an
  // outlier in the interval before (too few to name) may have been its start.
  e.onset_t = t0 + static_cast<double>(first) / settings_.rate_hz;
  e.onset_95 = {t0, e.onset_t};
  if (contiguous && std::isfinite(previous_first_outlier_t_[axis])) {
    e.onset_95.lo = previous_t0_;
    e.onset_t = previous_first_outlier_t_[axis];
  }
  e.evidence = std::to_string(count) + " samples beyond robust z " + formatRatio(kLiveOutlierZ) +
               " where the baseline's rate expects " + formatRatio(expected) + " (Poisson p " + formatRatio(p) + ")";
  return e;
}

double LiveCheck::knownCoupling(std::size_t axis) const { return settings_.temperature_coefficient_dps_per_c[axis]; }

// The window's middle boundaries: blocks_/2 .. blocks_/2 + blocks_ − 1 of its 2·blocks_, so
// that successive windows (one interval apart) judge each boundary once, each with half an
// interval of data or more on both sides.
std::vector<std::pair<std::size_t, double>> LiveCheck::middleDifferences(const std::vector<double>& y,
                                                                         std::size_t first, std::size_t s) const {
  std::vector<std::pair<std::size_t, double>> out;
  const std::size_t lo = blocks_ / 2;
  for (std::size_t c = lo; c < lo + blocks_; ++c)
    if (c >= first + s && c + s <= y.size()) out.emplace_back(c, meanOf(y, c, c + s) - meanOf(y, c - s, c));
  return out;
}

void LiveCheck::addToPool(std::size_t axis, const std::vector<double>& y, std::size_t first) {
  const std::size_t m = blocks_;
  for (std::size_t i = 0; i < scales_.size(); ++i) {
    const std::size_t s = scales_[i];
    double sum = 0.0, count = 0.0;
    for (const auto& [c, d] : middleDifferences(y, first, s)) {
      sum += 0.5 * d * d;
      count += 1.0;
    }
    if (count == 0.0) continue;
    AllanPool& p = pool_[axis];
    p.sum_half_d2[i] += sum;
    p.terms[i] += count;
    // Differences 2s blocks apart are independent; overlapping ones add about half as much
    // again (the overlapping estimator's gain on white noise), hence 0.75 per s blocks spanned.
    p.dof[i] += 0.75 * std::min(count, static_cast<double>(m) / static_cast<double>(s));
  }
}

std::optional<LiveEffect> LiveCheck::findStep(std::size_t axis, const std::vector<double>& y, std::size_t first,
                                              double window_t0) const {
  const AllanPool& p = pool_[axis];
  const double block_s = static_cast<double>(block_) / settings_.rate_hz;
  struct Best {
    double p = 2.0, d = 0.0, z = 0.0, sd = 0.0;
    std::size_t c = 0, i = 0;
  } best;
  std::size_t tests = 0;
  for (std::size_t i = 0; i + 1 < scales_.size(); ++i) {  // the last scale (a whole interval) is the coupling's
    if (!p.ready(i)) continue;
    const double sd = p.differenceSd(i);
    for (const auto& [c, d] : middleDifferences(y, first, scales_[i])) {
      const double pv = twoSidedT(d / sd, p.dof[i]);
      ++tests;
      if (pv < best.p) best = {pv, d, d / sd, sd, c, i};
    }
  }
  if (tests == 0 || !(best.p * static_cast<double>(tests) < alpha_)) return std::nullopt;
  // Where it is: one step fitted to all the window's blocks since `first` by least squares (the
  // detection judged the middle boundaries only; a step near the window's end shows there
  // too, a block or more early). The 95 % interval holds the boundaries whose cost is within
  // 3.84 of the best in units of a block mean's variance (σA² at one block), widened by a
  // block on each side.
  const double block_var = p.sum_half_d2[0] / p.terms[0];
  const std::size_t n = y.size();
  std::vector<double> cost = oneStepRss(y, first);
  for (double& c : cost) c /= block_var;
  const auto at_best = std::min_element(cost.begin(), cost.end());
  const auto c_best = static_cast<std::size_t>(at_best - cost.begin());
  std::size_t c_lo = c_best, c_hi = c_best;
  for (std::size_t c = first + 1; c < n; ++c)
    if (cost[c] - *at_best <= 3.84) {
      c_lo = std::min(c_lo, c);
      c_hi = std::max(c_hi, c);
    }
  // Its size at the detection's scale, or the largest that fits, from the blocks clear of the
  // onset's interval on both sides (the block the step fell in holds part of it).
  const std::size_t before_end = c_lo - 1, after_start = std::min(n, c_hi + 1);
  std::size_t i = best.i;
  while (i > 0 && (before_end < first + scales_[i] || after_start + scales_[i] > n)) --i;
  const std::size_t s = scales_[i];
  const bool fits = before_end >= first + s && after_start + s <= n;
  const double sd = fits ? p.differenceSd(i) : best.sd;
  const double size = fits ? meanOf(y, after_start, after_start + s) - meanOf(y, before_end - s, before_end) : best.d;
  const auto at = [&](std::size_t c) { return window_t0 + static_cast<double>(c) * block_s; };
  LiveEffect e;
  e.kind = LiveEffectKind::BiasStep;
  e.axis = axis;
  e.onset_t = at(c_best);
  e.onset_95 = {at(c_lo - 1), at(std::min(n, c_hi + 1))};
  e.size_dps = size;
  e.size_dps_95 = {size - 1.96 * sd, size + 1.96 * sd};
  e.scale_s = static_cast<double>(s) * block_s;
  e.z = best.z;
  e.evidence = "the mean of the " + formatSeconds(static_cast<double>(scales_[best.i]) * block_s) +
               " after a boundary differs from the same before it by " + formatDps(best.d) + ", " +
               formatRatio(std::fabs(best.z)) + " x the board's own sqrt(2)*Allan deviation there (t p " +
               formatRatio(best.p) + " over " + std::to_string(tests) + " tests, family threshold " +
               formatRatio(alpha_) + ")";
  return e;
}

std::optional<LiveEffect> LiveCheck::findCoupling(std::size_t axis, const std::vector<double>& y,
                                                  const std::vector<double>& temp, double window_t0) const {
  const std::size_t m = blocks_, n = y.size();
  if (scales_.empty() || temp.size() != n || n != 2 * m) return std::nullopt;
  const double dt = meanOf(temp, m, n) - meanOf(temp, 0, m);
  if (!(std::fabs(dt) >= kLiveMinTemperatureChangeC)) return std::nullopt;
  const AllanPool& p = pool_[axis];
  const std::size_t last = scales_.size() - 1;
  if (!p.ready(last)) return std::nullopt;
  const double k0 = knownCoupling(axis);
  const double sd = p.differenceSd(last);
  const double dy = meanOf(y, m, n) - meanOf(y, 0, m) - k0 * dt;
  const double pv = twoSidedT(dy / sd, p.dof[last]);
  if (!(pv < alpha_)) return std::nullopt;
  // What the temperature's shape explains against what the best single step explains.
  const double t_mean = meanOf(temp, 0, n);
  double stt = 0.0, sty = 0.0;
  std::vector<double> r(n);
  for (std::size_t j = 0; j < n; ++j) r[j] = y[j] - k0 * temp[j];
  const double r_mean = meanOf(r, 0, n);
  for (std::size_t j = 0; j < n; ++j) {
    stt += (temp[j] - t_mean) * (temp[j] - t_mean);
    sty += (temp[j] - t_mean) * (r[j] - r_mean);
  }
  const double slope = sty / stt;
  double rss_t = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    const double e = r[j] - r_mean - slope * (temp[j] - t_mean);
    rss_t += e * e;
  }
  const std::vector<double> step_rss = oneStepRss(r, 0);
  const double rss_step = *std::min_element(step_rss.begin(), step_rss.end());
  if (!(rss_t < rss_step)) return std::nullopt;
  LiveEffect e;
  e.kind = LiveEffectKind::TemperatureBias;
  e.axis = axis;
  const double block_s = static_cast<double>(block_) / settings_.rate_hz;
  e.onset_t = window_t0;
  e.onset_95 = {window_t0, window_t0 + static_cast<double>(n) * block_s};
  e.coefficient_dps_per_c = k0 + slope;
  const double half = 1.96 * sd / std::fabs(dt);
  e.coefficient_dps_per_c_95 = {e.coefficient_dps_per_c - half, e.coefficient_dps_per_c + half};
  e.baseline_coefficient_dps_per_c = k0;
  e.temperature_change_c = dt;
  e.evidence = "the temperature moved " + formatRatio(dt) + " C between the last two intervals and their means by " +
               formatDps(dy) + " more than the known coupling explains, " + formatRatio(std::fabs(dy / sd)) +
               " x the board's own sqrt(2)*Allan deviation at one interval (t p " + formatRatio(pv) +
               "); the temperature's shape fits the blocks better than any one step";
  return e;
}

bool LiveCheck::couplingStillShows(const LiveEffect& e, const std::vector<double>& y,
                                   const std::vector<double>& temp) const {
  const std::size_t m = blocks_, n = y.size();
  if (scales_.empty() || temp.size() != n || n != 2 * m) return true;
  const AllanPool& p = pool_[e.axis];
  const std::size_t last = scales_.size() - 1;
  if (!(p.sum_half_d2[last] > 0.0)) return true;
  const double sd = p.differenceSd(last);
  const double dt = meanOf(temp, m, n) - meanOf(temp, 0, m);
  const double k0 = knownCoupling(e.axis);
  // Only a window where the named coupling would stand out (3 × the noise) can show it gone.
  if (std::fabs((e.coefficient_dps_per_c - k0) * dt) < 3.0 * sd) return true;
  const double dy = meanOf(y, m, n) - meanOf(y, 0, m) - k0 * dt;
  return std::fabs(dy) >= 1.96 * sd;
}

bool LiveCheck::lineShowsIn(const LiveEffect& e, std::span<const double> x) const {
  if (e.baseline_rms_dps > 0.0) {
    // A grown baseline line: still over kLiveLineGrowth times its old rms.
    for (const LiveEffect& now : findLines(e.axis, x, 0.0, 0.0, kGoneAlpha))
      if (std::fabs(now.centre_hz - e.centre_hz) <= 0.5 * (now.width_hz + e.width_hz) + kSameLineHz &&
          now.rms_dps_95.hi > kLiveLineGrowth * e.baseline_rms_dps)
        return true;
    return false;
  }
  // A new line: the periodogram still stands out at its bins (kGoneAlpha over those bins
  // alone: a line the check named once is not said gone on a weak interval).
  double w2 = 0.0;
  const std::vector<double> p = hannPeriodogram(x, &w2);
  const double df = settings_.rate_hz / static_cast<double>(x.size());
  const double half = std::max(0.5 * e.width_hz, 3.0 * df);
  const auto lo = std::max<std::size_t>(1, static_cast<std::size_t>(std::floor((e.centre_hz - half) / df)));
  const auto hi = std::min(p.size() - 2, static_cast<std::size_t>(std::ceil((e.centre_hz + half) / df)));
  if (hi < lo) return false;
  const double threshold =
      f2UpperQuantile(kGoneAlpha / static_cast<double>(hi - lo + 1), welchDof(baseline_[e.axis].segments));
  for (std::size_t k = lo; k <= hi; ++k) {
    const double level = baselineLevel(e.axis, static_cast<double>(k) * df, w2);
    if (level > 0.0 && p[k] / level > threshold) return true;
  }
  return false;
}

bool LiveCheck::stillShows(const LiveEffect& e, const AxisInterval& in, const std::vector<double>* both) const {
  if (e.kind == LiveEffectKind::OutlierBurst) {
    std::size_t count = 0;
    for (double z : in.scores) count += std::fabs(z) > kLiveOutlierZ ? 1 : 0;
    return poissonUpperTail(count, outlierRate(e.axis) * static_cast<double>(in.scores.size())) < kGoneAlpha;
  }
  // A line is gone when neither the last interval nor the last two show it: a weak line's one
  // weak interval does not end it (at the cost of saying it an interval later).
  return lineShowsIn(e, in.cleaned) || (both != nullptr && lineShowsIn(e, *both));
}

LiveCheck::LevelWindow LiveCheck::levelWindow(const std::array<std::vector<double>, 3>& blocks,
                                              const std::vector<double>& temp_blocks, bool contiguous) const {
  LevelWindow w;
  w.ok = contiguous && !scales_.empty() && previous_blocks_[0].size() == blocks_;
  if (!w.ok) return w;
  w.t0 = previous_t0_;
  for (std::size_t a = 0; a < blocks.size(); ++a) {
    w.y[a] = previous_blocks_[a];
    w.y[a].insert(w.y[a].end(), blocks[a].begin(), blocks[a].end());
  }
  if (temp_blocks.size() == blocks_ && previous_temperature_blocks_.size() == blocks_) {
    w.temp = previous_temperature_blocks_;
    w.temp.insert(w.temp.end(), temp_blocks.begin(), temp_blocks.end());
  }
  return w;
}

std::size_t LiveCheck::firstBlock(std::size_t axis, double window_t0) const {
  const double since = (level_since_t_[axis] - window_t0) / (static_cast<double>(block_) / settings_.rate_hz);
  return since <= 0.0 ? 0 : static_cast<std::size_t>(std::ceil(since - 1e-9));
}

std::vector<double> LiveCheck::corrected(const LevelWindow& w, std::size_t axis, double k) {
  std::vector<double> y = w.y[axis];
  if (!w.temp.empty())
    for (std::size_t j = 0; j < y.size(); ++j) y[j] -= k * (w.temp[j] - w.temp[0]);
  return y;
}

const LiveEffect* LiveCheck::currentEffect(LiveEffectKind kind, std::size_t axis) const {
  for (const LiveEffect& c : current_)
    if (c.kind == kind && c.axis == axis) return &c;
  return nullptr;
}

void LiveCheck::findLevelChanges(std::size_t axis, const LevelWindow& w, std::vector<LiveEffect>& found) {
  // A coupling first (a warm-up's bias drift is its, not a step's), then steps in what the
  // coupling in force leaves; a window with neither adds to the board's Allan pool.
  const std::size_t first = firstBlock(axis, w.t0);
  bool named = false;
  double k = knownCoupling(axis);
  const LiveEffect* named_coupling = currentEffect(LiveEffectKind::TemperatureBias, axis);
  if (named_coupling != nullptr) k = named_coupling->coefficient_dps_per_c;
  if (!w.temp.empty() && first == 0 && named_coupling == nullptr)
    if (auto c = findCoupling(axis, w.y[axis], w.temp, w.t0)) {
      k = c->coefficient_dps_per_c;
      found.push_back(*c);
      named = true;
    }
  const std::vector<double> y = corrected(w, axis, k);
  if (auto step = findStep(axis, y, first, w.t0)) {
    level_since_t_[axis] = step->onset_95.hi;
    found.push_back(*step);
    named = true;
  }
  if (!named) addToPool(axis, y, first);
}

std::vector<LiveEffect> LiveCheck::examine(const std::array<std::span<const double>, 3>& axes,
                                           std::span<const double> temperature_c, double t0) {
  std::vector<LiveEffect> changes;
  for (const auto& x : axes)
    if (x.size() != interval_samples_) return changes;
  if (!temperature_c.empty() && temperature_c.size() != interval_samples_) return changes;
  std::array<AxisInterval, 3> in;
  for (std::size_t a = 0; a < axes.size(); ++a) in[a] = prepare(axes[a]);
  const double length_s = static_cast<double>(interval_samples_) / settings_.rate_hz;
  const bool contiguous = have_previous_ && std::fabs(previous_t0_ + length_s - t0) < 0.5 / settings_.rate_hz;
  std::array<std::vector<double>, 3> blocks;
  for (std::size_t a = 0; a < axes.size(); ++a) blocks[a] = blockMeans(in[a].cleaned, block_);
  const std::vector<double> temp_blocks = blockMeans(temperature_c, block_);
  const LevelWindow window = levelWindow(blocks, temp_blocks, contiguous);
  const auto keep = [&] {
    for (std::size_t a = 0; a < axes.size(); ++a) previous_blocks_[a] = blocks[a];
    previous_temperature_blocks_ = temp_blocks;
    before_previous_t0_ = previous_t0_;
    have_before_previous_ = have_previous_;
    for (std::size_t a = 0; a < axes.size(); ++a) {
      previous_[a] = in[a].cleaned;
      previous_first_outlier_t_[a] = std::numeric_limits<double>::quiet_NaN();
      for (std::size_t i = 0; i < in[a].scores.size(); ++i)
        if (std::fabs(in[a].scores[i]) > kLiveOutlierZ) {
          previous_first_outlier_t_[a] = t0 + static_cast<double>(i) / settings_.rate_hz;
          break;
        }
    }
    previous_t0_ = t0;
    have_previous_ = true;
  };
  if (!baselineReady()) {
    for (std::size_t a = 0; a < axes.size(); ++a) {
      AxisBaseline& b = baseline_[a];
      if (b.power.empty()) b.power.assign(in[a].power.size(), 0.0);
      for (std::size_t k = 0; k < b.power.size(); ++k)
        b.power[k] += in[a].power[k] * static_cast<double>(in[a].segments);
      b.segments += in[a].segments;
      for (double z : in[a].scores) b.outliers += std::fabs(z) > kLiveOutlierZ ? 1.0 : 0.0;
      b.samples += static_cast<double>(in[a].scores.size());
      b.intervals.push_back(in[a].cleaned);
    }
    if (window.ok)
      for (std::size_t a = 0; a < axes.size(); ++a)
        addToPool(a, corrected(window, a, knownCoupling(a)), firstBlock(a, window.t0));
    if (++baseline_intervals_ == baseline_needed_) finishBaseline();
    keep();
    return changes;
  }
  const double t_end = t0 + length_s;
  std::erase_if(recently_gone_, [t0](const LiveEffect& e) { return e.t < t0 - 1e-6; });
  std::array<std::vector<double>, 3> both;  // the last two intervals, when contiguous
  if (contiguous)
    for (std::size_t a = 0; a < axes.size(); ++a) {
      both[a] = previous_[a];
      both[a].insert(both[a].end(), in[a].cleaned.begin(), in[a].cleaned.end());
    }
  for (auto it = current_.begin(); it != current_.end();) {
    bool shows = false;  // a bias step is an event: the level after it is the board's from now on
    if (it->kind == LiveEffectKind::TemperatureBias) {
      shows = !window.ok || window.temp.empty() || firstBlock(it->axis, window.t0) != 0 ||
              couplingStillShows(*it, window.y[it->axis], window.temp);
    } else if (it->kind != LiveEffectKind::BiasStep) {
      shows = stillShows(*it, in[it->axis], contiguous ? &both[it->axis] : nullptr);
    }
    if (shows) {
      ++it;
      continue;
    }
    LiveEffect gone = *it;
    gone.gone = true;
    gone.t = t_end;
    changes.push_back(gone);
    recently_gone_.push_back(gone);
    it = current_.erase(it);
  }
  const auto known = [this](const LiveEffect& e) {
    return std::any_of(current_.begin(), current_.end(), [&e](const LiveEffect& c) {
      if (c.axis != e.axis || c.kind != e.kind || e.kind == LiveEffectKind::BiasStep) return false;
      return e.kind != LiveEffectKind::Line ||
             std::fabs(c.centre_hz - e.centre_hz) <= 0.5 * (c.width_hz + e.width_hz) + 0.1;
    });
  };
  for (std::size_t a = 0; a < axes.size(); ++a) {
    std::vector<LiveEffect> found;
    // Two windows, each at half the family's alpha: the last two intervals (a line that began
    // in the one before shows over both) and the last one.
    if (contiguous) {
      found = findLines(a, both[a], previous_t0_, have_before_previous_ ? before_previous_t0_ : previous_t0_ - length_s,
                        alpha_ / 2);
      std::erase_if(found, [&](const LiveEffect& e) {
        return std::any_of(recently_gone_.begin(), recently_gone_.end(), [&](const LiveEffect& g) {
          return g.axis == a && g.kind == e.kind &&
                 std::fabs(g.centre_hz - e.centre_hz) <= 0.5 * (g.width_hz + e.width_hz) + kSameLineHz;
        });
      });
    }
    for (LiveEffect& e : findLines(a, in[a].cleaned, t0, have_previous_ ? previous_t0_ : t0 - length_s,
                                   contiguous ? alpha_ / 2 : alpha_))
      found.push_back(e);
    if (auto burst = findOutlierBurst(a, in[a], t0, contiguous)) found.push_back(*burst);
    if (window.ok) findLevelChanges(a, window, found);
    for (LiveEffect& e : found) {
      e.t = t_end;
      if (known(e)) continue;
      if (e.kind == LiveEffectKind::Line) {
        if (const BaselineLine* had = baselineLine(a, e)) {
          // The board had it: named only when it grew.
          if (!(e.rms_dps_95.lo > kLiveLineGrowth * had->rms_dps)) continue;
          e.baseline_rms_dps = had->rms_dps;
          e.evidence += "; the baseline had it at " + formatRatio(had->rms_dps) + " deg/s rms or less, now " +
                        formatRatio(e.rms_dps) + " (more than " + formatRatio(kLiveLineGrowth) + " x)";
        }
      }
      current_.push_back(e);
      changes.push_back(e);
    }
  }
  keep();
  return changes;
}

}  // namespace gyrod::processing
