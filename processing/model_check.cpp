// The model check of one axis: base fit → replicas → statistics against their nulls →
// named causes → extended model → replicas again → gain. See model_check.hpp and
// docs/model-check.md.
#include "processing/model_check.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <mutex>
#include <optional>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "processing/ar_model.hpp"
#include "processing/detrend.hpp"
#include "processing/kalman.hpp"
#include "processing/model_check_detail.hpp"
#include "processing/portable_random.hpp"

namespace gyrod::processing {
namespace {

using namespace model_check_detail;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kMaxSinusoids = 3;
constexpr double kSameLineBins = 3.0;  // peaks closer than this (periodogram bins) are one line
constexpr std::size_t kMaxSteps = 8;
constexpr std::size_t kOutlierHalfWindow = 10;
constexpr std::size_t kMaxBlocks = 8192;
constexpr std::size_t kAllanPerDecade = 5;
constexpr std::size_t kPsdBands = 48;

std::string formatValue(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

// ---- what every replica (and the measured series) is measured by ----------------------

struct Context {
  std::size_t n = 0;
  double rate = 0.0, tau0 = 0.0;
  std::vector<std::size_t> ms;
  std::vector<double> taus, edf;
  std::vector<double> t_grid;           // Gauss–Markov correlation times tried
  std::size_t block = 1, blocks = 0;    // block length [samples], number of blocks
  std::vector<double> temp_blocks;      // detrended block means of temperature (empty: none)
  std::vector<std::size_t> scales;      // Haar scales [blocks]
  std::size_t k_lo = 0, k_hi = 0;       // periodogram bins searched for a sinusoid
  std::vector<double> psd_edges;
};

enum StatMask : unsigned {
  kStatAllan = 1u, kStatOutliers = 2u, kStatSpectrum = 4u, kStatTemperature = 8u, kStatSteps = 16u,
  kStatGaussMarkov = 32u, kStatPsd = 64u, kStatAll = 127u,
};

struct SeriesStats {
  std::vector<double> log_adev;  // ln σ per m
  double outlier_max_z = kNaN;
  double spectral_log_ratio = kNaN;
  std::size_t spectral_bin = 0;
  double temp_slope = kNaN;
  double step_stat = kNaN;       // stepStatistic of the low-passed residual
  double gm_statistic = kNaN;
  std::vector<double> psd, psd_max;
};

double temperatureSlope(const std::vector<double>& y, const std::vector<double>& tb) {
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    sxy += y[i] * tb[i];
    sxx += tb[i] * tb[i];
  }
  return sxx > 0.0 ? sxy / sxx : 0.0;
}

// The Gauss–Markov statistic: √(χ² gain) of the Allan fit. The gain's null has a tail heavier
// than exponential (the Allan points' weights are approximate, so the gain is a scale mixture
// of χ²), and a Gumbel fitted to its median and 90 % point under-extrapolates it; on the
// square root the tail is exponential or lighter and the Gumbel threshold holds.
double gaussMarkovStatistic(const GaussMarkovCurveFit& fit) { return std::sqrt(std::max(0.0, fit.improvement)); }

std::vector<double> lowPassedResidual(std::span<const double> x, const Context& c) {
  std::vector<double> y = blockMeans(x, c.block);
  removeLineInPlace(y);
  return y;
}

// max over scales W and positions t of |D_W(t)| / σ̂_W, σ̂_W = median|D_W|/0.6745 over the
// positions of the same series: a robust scale that a few sparse steps hardly move, so the
// statistic does not depend on how much slow noise the fitted model has (only on its shape).
double stepStatistic(const std::vector<double>& y, const Context& c, std::size_t* t_out, std::size_t* w_out,
                     double* d_out) {
  double best = 0.0;
  for (std::size_t w : c.scales) {
    const HaarScan h = haarScan(y, w);
    const double sigma = h.median_abs / 0.6745;
    const double v = sigma > 0.0 ? h.max_abs / sigma : 0.0;
    if (v > best) {
      best = v;
      if (t_out) *t_out = h.argmax;
      if (w_out) *w_out = w;
      if (d_out) *d_out = h.value_at_max;
    }
  }
  return best;
}

SeriesStats measureSeries(std::span<const double> xd, const Context& c, unsigned mask) {
  SeriesStats s;
  if (mask & (kStatAllan | kStatGaussMarkov)) {
    const std::vector<double> v = overlappingAllanVariances(xd, c.ms);
    s.log_adev.resize(v.size());
    for (std::size_t j = 0; j < v.size(); ++j) s.log_adev[j] = 0.5 * std::log(v[j]);
    if (mask & kStatGaussMarkov) s.gm_statistic = gaussMarkovStatistic(fitGaussMarkovToAllan(c.taus, v, c.edf, c.t_grid));
  }
  if (mask & kStatOutliers) {
    const std::vector<double> z = localOutlierScores(xd, kOutlierHalfWindow);
    double m = 0.0;
    for (double v : z) m = std::max(m, std::fabs(v));
    s.outlier_max_z = m;
  }
  if (mask & (kStatSpectrum | kStatPsd)) {
    const Periodogram p = hannPeriodogram(xd);
    if (mask & kStatSpectrum) {
      const SpectralPeak peak = largestSpectralPeak(p.power, spectralBackground(p.power), c.k_lo, c.k_hi);
      s.spectral_log_ratio = std::log(peak.ratio);
      s.spectral_bin = peak.bin;
    }
    if (mask & kStatPsd) s.psd = bandAveragedPsd(p, c.rate, c.psd_edges, &s.psd_max);
  }
  if (mask & (kStatTemperature | kStatSteps)) {
    const std::vector<double> y = lowPassedResidual(xd, c);
    if ((mask & kStatTemperature) && !c.temp_blocks.empty()) s.temp_slope = temperatureSlope(y, c.temp_blocks);
    if (mask & kStatSteps) s.step_stat = stepStatistic(y, c, nullptr, nullptr, nullptr);
  }
  return s;
}

// ---- replicas --------------------------------------------------------------------------

std::uint64_t replicaSeed(std::uint64_t seed, std::uint64_t round, std::uint64_t index) {
  SplitMix64 mix(seed ^ (0xD1B54A32D192ED03ULL * (round + 1)));
  std::uint64_t s = mix.next();
  SplitMix64 second(s + 0x9E3779B97F4A7C15ULL * (index + 1));
  return second.next();
}

// One replica of axis x of `model`, n samples, plus `added` (same length, or empty),
// detrended as the measured series is.
std::vector<double> simulateReplica(const SimulationModel& model, std::size_t n, std::uint64_t seed,
                                    std::span<const double> added) {
  NoiseSimulator sim(model, static_cast<double>(n) / model.rate_hz, seed);
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = sim.next().rate_dps[0] + (added.empty() ? 0.0 : added[i]);
  removeLinearTrend(x, 1.0 / model.rate_hz);
  return x;
}

template <class Body>
void parallelFor(std::size_t count, std::size_t threads, Body&& body) {
  threads = std::max<std::size_t>(1, std::min(threads, count));
  if (threads == 1) {
    for (std::size_t i = 0; i < count; ++i) body(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  std::vector<std::thread> pool;
  for (std::size_t t = 0; t < threads; ++t) {
    pool.emplace_back([&] {
      for (std::size_t i = next++; i < count; i = next++) {
        try {
          body(i);
        } catch (...) {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
        }
      }
    });
  }
  for (std::thread& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

// The model a replica is drawn from: the fitted terms, each perturbed by its 1-σ
// uncertainty (max(0, value + u·n), n ~ N(0, 1) from the replica's own seed). The null then
// carries the uncertainty of the fit as well as the noise of a realisation (a posterior-
// predictive check): without it, a long-τ term fitted to 0 by chance (rate random walk
// is poorly seen in one record) makes every replica quieter at low frequency than the data
// and the low-frequency statistics fire on clean data.
SimulationModel replicaModel(const SimulationModel& fitted, const NoiseTerms& uncertainty, std::uint64_t seed) {
  SimulationModel m = fitted;
  NormalGenerator perturb(seed ^ 0x5851F42D4C957F2DULL);
  for (NoiseTerm t : kAllNoiseTerms) {
    if (t == NoiseTerm::RateRamp) continue;  // removed with the linear trend anyway
    const double v = m.axes[0].terms.get(t) + uncertainty.get(t) * perturb.next();
    m.axes[0].terms.set(t, std::max(0.0, v));
  }
  return m;
}

// The statistical part of a fit's uncertainty: noise_fit scales the covariance by
// max(1, reduced χ²), which would let a model that fits the curve badly widen its own null
// and hide the misfit; that scale is taken out again (σ_c ∝ √scale, so a fitted term's
// σ_T ∝ √scale and a zero term's bound, T ∝ √σ_c, ∝ scale^¼).
NoiseTerms statisticalUncertainty(const NoiseTermFit& fit) {
  const double scale = std::isfinite(fit.reduced_chi2) ? std::max(1.0, fit.reduced_chi2) : 1.0;
  NoiseTerms u;
  for (NoiseTerm t : kAllNoiseTerms)
    u.set(t, fit.value.get(t) > 0.0 ? fit.uncertainty.get(t) / std::sqrt(scale) : fit.uncertainty.get(t) / std::pow(scale, 0.25));
  return u;
}

std::vector<SeriesStats> runReplicas(const SimulationModel& model, const NoiseTerms& uncertainty, const Context& c,
                                     std::span<const double> added, const ModelCheckOptions& o, std::uint64_t round,
                                     unsigned mask) {
  std::vector<SeriesStats> out(o.replicas);
  parallelFor(o.replicas, o.threads, [&](std::size_t i) {
    const std::uint64_t seed = replicaSeed(o.seed, round, i);
    const std::vector<double> x = simulateReplica(replicaModel(model, uncertainty, seed), c.n, seed, added);
    out[i] = measureSeries(x, c, mask);
  });
  return out;
}

SimulationModel pureModel(double rate, const NoiseTerms& terms) {
  SimulationModel m;
  m.rate_hz = rate;
  m.axes[0].terms = terms;
  return m;
}

// ---- Allan band ------------------------------------------------------------------------

struct AllanNull {
  AllanBand band;
  std::vector<double> median_log, spread_log;
  NullSummary max_z;
};

double maxAbsZ(const std::vector<double>& log_adev, const std::vector<double>& med, const std::vector<double>& spread,
               std::vector<double>* z_out = nullptr) {
  double m = 0.0;
  if (z_out) z_out->assign(log_adev.size(), 0.0);
  for (std::size_t j = 0; j < log_adev.size(); ++j) {
    const double z = spread[j] > 0.0 ? (log_adev[j] - med[j]) / spread[j] : 0.0;
    if (z_out) (*z_out)[j] = z;
    m = std::max(m, std::fabs(z));
  }
  return m;
}

AllanNull allanNull(const std::vector<SeriesStats>& reps, const std::vector<double>& measured_log,
                    const Context& c, double alpha) {
  AllanNull a;
  const std::size_t k = c.ms.size();
  a.band.tau_s = c.taus;
  a.median_log.resize(k);
  a.spread_log.resize(k);
  std::vector<double> col(reps.size());
  for (std::size_t j = 0; j < k; ++j) {
    for (std::size_t r = 0; r < reps.size(); ++r) col[r] = reps[r].log_adev[j];
    std::sort(col.begin(), col.end());
    a.median_log[j] = sortedQuantile(col, 0.5);
    a.spread_log[j] = 0.5 * (sortedQuantile(col, 0.8413) - sortedQuantile(col, 0.1587));
    a.band.median.push_back(std::exp(a.median_log[j]));
    a.band.lo.push_back(std::exp(sortedQuantile(col, 0.05)));
    a.band.hi.push_back(std::exp(sortedQuantile(col, 0.95)));
    a.band.measured.push_back(std::exp(measured_log[j]));
  }
  std::vector<double> maxes(reps.size());
  for (std::size_t r = 0; r < reps.size(); ++r) maxes[r] = maxAbsZ(reps[r].log_adev, a.median_log, a.spread_log);
  a.max_z = summarizeNull(maxes, alpha, false);
  return a;
}

void bandFigures(const AllanBand& b, double& log_error, double& in_band) {
  double err = 0.0;
  std::size_t inside = 0;
  for (std::size_t j = 0; j < b.tau_s.size(); ++j) {
    err += std::fabs(std::log10(b.measured[j] / b.median[j]));
    inside += (b.measured[j] >= b.lo[j] && b.measured[j] <= b.hi[j]) ? 1 : 0;
  }
  log_error = err / static_cast<double>(b.tau_s.size());
  in_band = static_cast<double>(inside) / static_cast<double>(b.tau_s.size());
}

// ---- steps and temperature on the low-passed residual ------------------------------------

struct StepNull {
  NullSummary max;  // of stepStatistic over the replicas
};

struct BlockStep {
  std::size_t block = 0;  // the step is between block−1 and block
  std::size_t scale = 0;
  double size = 0.0;
};

// Steps one at a time: the largest standardised Haar difference while it passes the null,
// each removed (y[t:] −= D) before looking for the next.
std::vector<BlockStep> findBlockSteps(std::vector<double> y, const Context& c, const StepNull& null) {
  std::vector<BlockStep> steps;
  while (steps.size() < kMaxSteps) {
    std::size_t t = 0, w = 0;
    double d = 0.0;
    const double s = stepStatistic(y, c, &t, &w, &d);
    if (!null.max.fires(s)) break;
    steps.push_back({t, w, d});
    for (std::size_t i = t; i < y.size(); ++i) y[i] -= d;
  }
  std::sort(steps.begin(), steps.end(), [](const BlockStep& a, const BlockStep& b) { return a.block < b.block; });
  return steps;
}

// Least squares of y on [1, index, (temperature), (a unit step at each block)], returning
// the coefficients after the first two and the residual sum of squares.
std::vector<double> blockRegression(const std::vector<double>& y, const std::vector<double>* temp,
                                    const std::vector<BlockStep>& steps, double& rss) {
  const auto n = static_cast<Eigen::Index>(y.size());
  const Eigen::Index cols = 2 + (temp ? 1 : 0) + static_cast<Eigen::Index>(steps.size());
  Eigen::MatrixXd a(n, cols);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto u = static_cast<std::size_t>(i);
    Eigen::Index col = 0;
    a(i, col++) = 1.0;
    a(i, col++) = static_cast<double>(i) / static_cast<double>(n);
    if (temp) a(i, col++) = (*temp)[u];
    for (const BlockStep& s : steps) a(i, col++) = u >= s.block ? 1.0 : 0.0;
    b(i) = y[u];
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  rss = (a * x - b).squaredNorm();
  return std::vector<double>(x.data() + 2, x.data() + cols);
}

std::vector<double> column(const std::vector<SeriesStats>& reps, double SeriesStats::*field) {
  std::vector<double> v;
  v.reserve(reps.size());
  for (const SeriesStats& s : reps) v.push_back(s.*field);
  return v;
}

struct LowFrequencyNulls {
  NullSummary temp;
  StepNull steps;
};

LowFrequencyNulls lowFrequencyNulls(const std::vector<SeriesStats>& reps, double alpha, bool temp,
                                    bool steps) {
  LowFrequencyNulls n;
  if (temp) n.temp = summarizeNull(column(reps, &SeriesStats::temp_slope), alpha, true);
  if (!steps) return n;
  std::vector<double> maxes;
  for (const SeriesStats& r : reps) maxes.push_back(r.step_stat);
  n.steps.max = summarizeNull(maxes, alpha, false);
  return n;
}

// ---- effects removed from a series ---------------------------------------------------

struct Removal {
  std::vector<SinusoidFit> sinusoids;
  double k = 0.0;
  bool temperature = false;
  std::vector<std::size_t> step_samples;
  std::vector<double> step_sizes;
};

// The deterministic part of the named effects, per sample.
std::vector<double> deterministicPart(const Removal& r, std::size_t n, double rate, const std::vector<double>& temp_detrended) {
  std::vector<double> d(n, 0.0);
  for (const SinusoidFit& s : r.sinusoids) {
    const double w = 2.0 * std::numbers::pi * s.freq_hz / rate;
    for (std::size_t i = 0; i < n; ++i) d[i] += s.amp_dps * std::sin(w * static_cast<double>(i) + s.phase_rad);
  }
  if (r.temperature)
    for (std::size_t i = 0; i < n; ++i) d[i] += r.k * temp_detrended[i];
  for (std::size_t j = 0; j < r.step_samples.size(); ++j)
    for (std::size_t i = r.step_samples[j]; i < n; ++i) d[i] += r.step_sizes[j];
  return d;
}

// The sample where a step found at block resolution is: the split within ±1 block that
// maximises the difference of the means of `half` samples on each side.
std::size_t refineStepSample(std::span<const double> r, std::size_t block_start, std::size_t block, std::size_t half) {
  const std::size_t n = r.size();
  std::vector<double> prefix(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + r[i];
  const std::size_t lo = block_start > block ? block_start - block : 1;
  const std::size_t hi = std::min(n - 1, block_start + block);
  std::size_t best = block_start;
  double best_d = -1.0;
  for (std::size_t i = std::max<std::size_t>(lo, 1); i <= hi; ++i) {
    const std::size_t w = std::min({half, i, n - i});
    if (w == 0) continue;
    const double d = std::fabs((prefix[i + w] - prefix[i]) - (prefix[i] - prefix[i - w])) / static_cast<double>(w);
    if (d > best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

double medianOf(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return sortedQuantile(v, 0.5);
}

void validate(const AxisModelCheckInput& in, const ModelCheckOptions& o) {
  if (!(std::isfinite(in.rate_hz) && in.rate_hz > 0.0))
    throw std::invalid_argument("model check: rate_hz must be finite and > 0, got " + formatValue("%g", in.rate_hz));
  if (in.rate_dps.size() < kModelCheckMinSamples)
    throw std::invalid_argument("model check: " + std::to_string(in.rate_dps.size()) + " samples are too few (need at least " +
                                std::to_string(kModelCheckMinSamples) + ")");
  for (std::size_t i = 0; i < in.rate_dps.size(); ++i)
    if (!std::isfinite(in.rate_dps[i]))
      throw std::invalid_argument("model check: rate sample " + std::to_string(i) + " is not finite");
  if (!in.temperature_c.empty()) {
    if (in.temperature_c.size() != in.rate_dps.size())
      throw std::invalid_argument("model check: the temperature channel has " + std::to_string(in.temperature_c.size()) +
                                  " samples, the rate " + std::to_string(in.rate_dps.size()));
    for (std::size_t i = 0; i < in.temperature_c.size(); ++i)
      if (!std::isfinite(in.temperature_c[i]))
        throw std::invalid_argument("model check: temperature sample " + std::to_string(i) + " is not finite");
  }
  if (!in.time_s.empty() && in.time_s.size() != in.rate_dps.size())
    throw std::invalid_argument("model check: the time channel has " + std::to_string(in.time_s.size()) +
                                " samples, the rate " + std::to_string(in.rate_dps.size()));
  if (o.replicas < 8) throw std::invalid_argument("model check: replicas must be >= 8, got " + std::to_string(o.replicas));
  if (!(o.false_alarm > 0.0 && o.false_alarm < 0.5))
    throw std::invalid_argument("model check: false_alarm must be in (0, 0.5), got " + formatValue("%g", o.false_alarm));
  if (o.ljung_box_lags < 1) throw std::invalid_argument("model check: ljung_box_lags must be >= 1");
  if (o.max_ar_order < 1 || o.max_ar_order > kMaxArOrder)
    throw std::invalid_argument("model check: max_ar_order must be 1.." + std::to_string(kMaxArOrder));
}

Context makeContext(const AxisModelCheckInput& in, std::span<const double> xd, std::vector<AllanPoint>& curve) {
  Context c;
  c.n = xd.size();
  c.rate = in.rate_hz;
  c.tau0 = 1.0 / in.rate_hz;
  // τ up to 1/8 of the record: beyond, a handful of differences make every curve agree.
  for (std::size_t m : denseClusterSizes(c.n, kAllanPerDecade))
    if (m <= c.n / 8) c.ms.push_back(m);
  curve = allanDeviationTable(xd, c.tau0, c.ms);
  for (const AllanPoint& p : curve) {
    c.taus.push_back(p.tau_s);
    // As noise_fit weighs a point: never more than a frequency-noise estimate could be.
    const std::size_t phase_points = p.oadev_terms + 2 * p.m;
    double fm = 0.0;
    for (int alpha : {0, -1, -2}) fm = std::max(fm, overlappingAllanEdf(alpha, phase_points, p.m));
    c.edf.push_back(std::isfinite(p.edf) && p.edf > 0.0 ? std::min(p.edf, fm) : fm);
  }
  const double duration = static_cast<double>(c.n) * c.tau0;
  for (double t = 3.0 * c.tau0; t <= duration / 15.0; t *= std::pow(10.0, 1.0 / 5.0)) c.t_grid.push_back(t);
  if (c.t_grid.empty()) c.t_grid.push_back(3.0 * c.tau0);

  c.block = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(in.rate_hz)));
  if (c.n / c.block > kMaxBlocks) c.block = (c.n + kMaxBlocks - 1) / kMaxBlocks;
  c.blocks = c.n / c.block;
  // Haar scales up to 1/16 of the record, so that a few steps leave most positions of every
  // scale untouched and the median scale of stepStatistic stays that of the noise.
  for (std::size_t w = 2; 16 * w <= c.blocks; w *= 2) c.scales.push_back(w);

  const std::size_t nfft = fftLength(c.n);
  // At least 10 cycles in the record, and clear of the lowest bins where the background
  // (random walk, flicker) changes too fast for a local median.
  c.k_lo = std::max<std::size_t>(64, static_cast<std::size_t>(std::ceil(10.0 * static_cast<double>(nfft) / static_cast<double>(c.n))));
  // Up to 98 % of Nyquist: a line at the very top of the band cannot be told from aliasing,
  // and there the background has bins on one side only.
  c.k_hi = nfft / 2 - std::max<std::size_t>(2, nfft / 100);
  const double f_lo = 2.0 / duration, f_hi = 0.5 * in.rate_hz;
  for (std::size_t j = 0; j <= kPsdBands; ++j)
    c.psd_edges.push_back(f_lo * std::pow(f_hi / f_lo, static_cast<double>(j) / static_cast<double>(kPsdBands)));
  return c;
}


CheckStatistic makeStatistic(const std::string& name, double value, const NullSummary& null) {
  return {name, value, null.median, null.two_sided ? null.median + null.threshold : null.threshold, null.fires(value)};
}

std::string nullText(const NullSummary& null, std::size_t replicas) {
  return "threshold " + formatValue("%.4g", null.two_sided ? null.threshold : null.threshold) + " from " +
         std::to_string(replicas) + " base-model replicas (median " + formatValue("%.4g", null.median) + ")";
}

}  // namespace

AxisModelCheck checkAxisModel(const AxisModelCheckInput& input, const ModelCheckOptions& options_in) {
  validate(input, options_in);
  ModelCheckOptions o = options_in;
  if (o.threads == 0) o.threads = std::max(1u, std::thread::hardware_concurrency());
  const double rate = input.rate_hz;
  const double tau0 = 1.0 / rate;

  AxisModelCheck out;
  out.samples = input.rate_dps.size();
  std::vector<double> xd(input.rate_dps.begin(), input.rate_dps.end());
  removeLinearTrend(xd, tau0);

  std::vector<AllanPoint> curve;
  Context c = makeContext(input, xd, curve);
  out.base_fit = fitNoiseTerms(curve);

  // Temperature, detrended like the rate (a linear temperature drift is a rate ramp to any
  // static analysis, and the ramp is already in the base model).
  std::vector<double> temp_detrended;
  std::vector<double> temp_blocks_raw;
  if (!input.temperature_c.empty()) {
    temp_detrended.assign(input.temperature_c.begin(), input.temperature_c.end());
    removeLinearTrend(temp_detrended, tau0);
    std::vector<double> tb = blockMeans(temp_detrended, c.block);
    removeLineInPlace(tb);
    double ss = 0.0;
    for (double v : tb) ss += v * v;
    // A channel that does not move (beyond 1 mK rms of its line) carries no evidence.
    if (tb.size() >= 8 && std::sqrt(ss / static_cast<double>(tb.size())) > 1e-3) c.temp_blocks = std::move(tb);
    temp_blocks_raw = blockMeans(input.temperature_c, c.block);
  }

  // ---- sample timing (no replicas needed: a regular sampler never leaves a 1.5·τ0 gap) --
  if (!input.time_s.empty()) {
    const SampleTiming timing = analyzeSampleTiming(input.time_s);
    out.statistics.push_back({"sample_gaps", static_cast<double>(timing.gaps), 0.0, 0.5, timing.gaps > 0});
    if (timing.gaps > 0) {
      DetectedEffect e;
      e.effect = ModelEffect::SampleGaps;
      e.count = timing.gaps;
      e.lost = timing.lost;
      e.evidence = std::to_string(timing.gaps) + " intervals in t longer than 1.5 x the median spacing " +
                   formatValue("%.6g", timing.median_spacing_s) + " s, " + std::to_string(timing.lost) +
                   " samples missing; timing jitter " + formatValue("%.3g", timing.jitter) + " of a spacing";
      out.effects.push_back(e);
    }
  }

  // ---- round 1: replicas of the base model ----------------------------------------------
  const SimulationModel base_model = pureModel(rate, out.base_fit.value);
  const std::vector<SeriesStats> base_reps = runReplicas(base_model, statisticalUncertainty(out.base_fit), c, {}, o, 1, kStatAll);
  out.replicas_simulated += o.replicas;
  const SeriesStats measured = measureSeries(xd, c, kStatAllan | kStatPsd);
  AllanNull base_allan = allanNull(base_reps, measured.log_adev, c, o.false_alarm);
  out.allan_base = base_allan.band;
  out.statistics.push_back(makeStatistic("allan_band_max_z_base", maxAbsZ(measured.log_adev, base_allan.median_log,
                                                                          base_allan.spread_log), base_allan.max_z));

  // Plots: spectrum of the measured series and the replicas' median per band.
  {
    out.spectrum_measured = measured.psd;
    out.spectrum_measured_peak = measured.psd_max;
    for (std::size_t j = 0; j + 1 < c.psd_edges.size(); ++j) {
      out.spectrum_freq_hz.push_back(std::sqrt(c.psd_edges[j] * c.psd_edges[j + 1]));
      std::vector<double> col;
      for (const SeriesStats& r : base_reps)
        if (std::isfinite(r.psd[j])) col.push_back(r.psd[j]);
      out.spectrum_base_median.push_back(col.empty() ? kNaN : medianOf(col));
    }
  }

  const NullSummary outlier_null = summarizeNull(column(base_reps, &SeriesStats::outlier_max_z), o.false_alarm, false);
  const NullSummary spectral_null = summarizeNull(column(base_reps, &SeriesStats::spectral_log_ratio), o.false_alarm, false);

  std::vector<double> xc = xd;  // the measured series with the named effects removed
  Removal removal;
  bool deterministic_found = false;

  // ---- outliers -------------------------------------------------------------------------
  std::size_t outlier_count = 0;
  double outlier_amplitude = 0.0;
  {
    const std::vector<double> z = localOutlierScores(xc, kOutlierHalfWindow);
    double zmax = 0.0;
    for (double v : z) zmax = std::max(zmax, std::fabs(v));
    out.statistics.push_back(makeStatistic("outliers_max_robust_z", zmax, outlier_null));
    if (outlier_null.fires(zmax)) {
      std::vector<std::size_t> at;
      for (std::size_t i = 0; i < z.size(); ++i)
        if (std::fabs(z[i]) > outlier_null.threshold) at.push_back(i);
      // Replace each by the mean of its neighbours that are not outliers themselves.
      std::vector<double> amplitudes;
      for (std::size_t i : at) {
        const std::size_t lo = i >= kOutlierHalfWindow ? i - kOutlierHalfWindow : 0;
        const std::size_t hi = std::min(xc.size(), i + kOutlierHalfWindow + 1);
        double s = 0.0;
        std::size_t k = 0;
        for (std::size_t j = lo; j < hi; ++j)
          if (!std::binary_search(at.begin(), at.end(), j)) {
            s += xd[j];
            ++k;
          }
        const double local = k > 0 ? s / static_cast<double>(k) : 0.0;
        amplitudes.push_back(std::fabs(xd[i] - local));
        xc[i] = local;
      }
      outlier_count = at.size();
      outlier_amplitude = medianOf(amplitudes);
      DetectedEffect e;
      e.effect = ModelEffect::Outliers;
      e.count = outlier_count;
      e.outlier_median_amplitude_dps = outlier_amplitude;
      e.evidence = "largest robust z " + formatValue("%.3g", zmax) + " against its neighbours; " + nullText(outlier_null, o.replicas) +
                   "; " + std::to_string(outlier_count) + " samples beyond it, median excursion " +
                   formatValue("%.3g", outlier_amplitude) + " deg/s";
      out.effects.push_back(e);
      deterministic_found = true;
    }
  }

  // ---- sinusoids ------------------------------------------------------------------------
  {
    bool first = true;
    for (std::size_t s = 0; s < kMaxSinusoids; ++s) {
      const Periodogram p = hannPeriodogram(xc);
      const SpectralPeak peak = largestSpectralPeak(p.power, spectralBackground(p.power), c.k_lo, c.k_hi);
      const double stat = std::log(peak.ratio);
      if (first) out.statistics.push_back(makeStatistic("spectral_peak_log_ratio", stat, spectral_null));
      first = false;
      if (!spectral_null.fires(stat)) break;
      // Frequency: the maximum of the least-squares amplitude within ±1 bin (golden section).
      const double df = rate / static_cast<double>(p.nfft);
      double a = (static_cast<double>(peak.bin) - 1.0) * df, b = (static_cast<double>(peak.bin) + 1.0) * df;
      const double g = 0.5 * (std::sqrt(5.0) - 1.0);
      double x1 = b - g * (b - a), x2 = a + g * (b - a);
      double f1 = fitSinusoidAt(xc, rate, x1).amp_dps, f2 = fitSinusoidAt(xc, rate, x2).amp_dps;
      for (int it = 0; it < 40 && (b - a) > 1e-6 * df; ++it) {
        if (f1 > f2) {
          b = x2; x2 = x1; f2 = f1; x1 = b - g * (b - a); f1 = fitSinusoidAt(xc, rate, x1).amp_dps;
        } else {
          a = x1; x1 = x2; f1 = f2; x2 = a + g * (b - a); f2 = fitSinusoidAt(xc, rate, x2).amp_dps;
        }
      }
      const SinusoidFit fit = fitSinusoidAt(xc, rate, 0.5 * (a + b));
      const double w = 2.0 * std::numbers::pi * fit.freq_hz / rate;
      for (std::size_t i = 0; i < xc.size(); ++i) xc[i] -= fit.amp_dps * std::sin(w * static_cast<double>(i) + fit.phase_rad);
      removal.sinusoids.push_back(fit);
      // A second peak within a few bins of one already named is the same line: a fixed
      // sinusoid did not take it out because its amplitude or phase wanders over the record
      // (or gaps in the record shifted its phase). Both components stay in the extended model;
      // the report names one line, its frequency power-weighted and its amplitude the rms sum.
      DetectedEffect* same_line = nullptr;
      for (DetectedEffect& prev : out.effects)
        if (prev.effect == ModelEffect::Sinusoid && std::fabs(prev.freq_hz - fit.freq_hz) <= kSameLineBins * df)
          same_line = &prev;
      if (same_line) {
        const double p0 = same_line->amp_dps * same_line->amp_dps, p1 = fit.amp_dps * fit.amp_dps;
        same_line->evidence += "; a second component " + formatValue("%.3g", fit.amp_dps) + " deg/s at " +
                               formatValue("%.5g", fit.freq_hz) + " Hz remains once it is removed (peak " +
                               formatValue("%.3g", peak.ratio) + " x the background): the line's amplitude or phase " +
                               "wanders over the record";
        same_line->freq_hz = (p0 * same_line->freq_hz + p1 * fit.freq_hz) / (p0 + p1);
        same_line->amp_dps = std::sqrt(p0 + p1);
        continue;
      }
      DetectedEffect e;
      e.effect = ModelEffect::Sinusoid;
      e.freq_hz = fit.freq_hz;
      e.amp_dps = fit.amp_dps;
      e.phase_rad = fit.phase_rad;
      e.evidence = "narrow spectral peak " + formatValue("%.3g", peak.ratio) + " x the local background at " +
                   formatValue("%.5g", fit.freq_hz) + " Hz (log ratio " + formatValue("%.3g", stat) + "; " +
                   nullText(spectral_null, o.replicas) + ")";
      out.effects.push_back(e);
      deterministic_found = true;
    }
  }

  // ---- temperature against bias steps, on the low-passed residual -----------------------
  const bool have_temp = !c.temp_blocks.empty();
  const bool have_steps = !c.scales.empty();
  LowFrequencyNulls lf = lowFrequencyNulls(base_reps, o.false_alarm, have_temp, have_steps);
  bool second_look = false;
  {
    // Further looks when a low-frequency statistic is suggestive (beyond 2 spreads of its
    // null): a temperature response or steps in the data inflate the fitted rate random walk
    // and ramp, and so widen the very null they are tested against. Refit the base model on
    // the series with the suggestive candidates removed (a regression and a few steps: a few
    // degrees of freedom of the slow noise) and test again against replicas of that fit;
    // repeat while the candidates change (at most 3 looks). Clean data rarely get here,
    // and then the refit changes little.
    std::size_t previous_signature = 0;
    for (std::size_t look = 0; look < 3; ++look) {
      const std::vector<double> y = lowPassedResidual(xc, c);
      const double k = have_temp ? temperatureSlope(y, c.temp_blocks) : 0.0;
      const bool temp_suggestive = have_temp && lf.temp.excess(k) > 2.0;
      std::vector<BlockStep> candidates;
      if (have_steps) {
        StepNull lowered = lf.steps;
        lowered.max.threshold = lowered.max.median + 2.0 * lowered.max.spread;
        std::vector<double> r = y;
        if (temp_suggestive)
          for (std::size_t i = 0; i < r.size(); ++i) r[i] -= k * c.temp_blocks[i];
        candidates = findBlockSteps(r, c, lowered);
      }
      const std::size_t signature = (temp_suggestive ? 1 : 0) + 2 * (candidates.size() + 1);
      if (!temp_suggestive && candidates.empty()) break;
      if (signature == previous_signature) break;
      previous_signature = signature;
      std::vector<double> alt = xc;
      if (temp_suggestive)
        for (std::size_t i = 0; i < alt.size(); ++i) alt[i] -= k * temp_detrended[i];
      for (const BlockStep& st : candidates)
        for (std::size_t i = st.block * c.block; i < alt.size(); ++i) alt[i] -= st.size;
      removeLinearTrend(alt, tau0);
      const NoiseTermFit alt_fit = fitNoiseTerms(allanDeviationTable(alt, tau0, c.ms));
      const std::vector<SeriesStats> reps = runReplicas(pureModel(rate, alt_fit.value), statisticalUncertainty(alt_fit), c, {}, o,
                                                        4 + look, kStatTemperature | kStatSteps);
      out.replicas_simulated += o.replicas;
      lf = lowFrequencyNulls(reps, o.false_alarm, have_temp, have_steps);
      second_look = true;
    }
  }
  const NullSummary* temp_null = have_temp ? &lf.temp : nullptr;
  const StepNull& step_null = lf.steps;
  {
    const std::vector<double> y0 = lowPassedResidual(xc, c);
    out.block_residual_dps = y0;
    out.block_temperature_c = temp_blocks_raw;
    out.block_temperature_c.resize(std::min(temp_blocks_raw.size(), y0.size()));
    auto tempFires = [&](const std::vector<double>& y) {
      return have_temp && temp_null->fires(temperatureSlope(y, c.temp_blocks));
    };
    auto stepsFire = [&](const std::vector<double>& y) {
      return have_steps && step_null.max.fires(stepStatistic(y, c, nullptr, nullptr, nullptr));
    };
    auto minusTemperature = [&](const std::vector<double>& y) {
      std::vector<double> r = y;
      const double k = temperatureSlope(y, c.temp_blocks);
      for (std::size_t i = 0; i < r.size(); ++i) r[i] -= k * c.temp_blocks[i];
      return r;
    };
    auto minusSteps = [&](const std::vector<double>& y, const std::vector<BlockStep>& steps) {
      double rss = 0.0;
      const std::vector<double> sizes = blockRegression(y, nullptr, steps, rss);
      std::vector<double> r = y;
      for (std::size_t j = 0; j < steps.size(); ++j)
        for (std::size_t i = steps[j].block; i < r.size(); ++i) r[i] -= sizes[j];
      return r;
    };

    const double t_stat = have_temp ? temperatureSlope(y0, c.temp_blocks) : kNaN;
    const double s_stat = have_steps ? stepStatistic(y0, c, nullptr, nullptr, nullptr) : kNaN;
    const std::string look = second_look ? " (second look)" : "";
    if (have_temp) out.statistics.push_back(makeStatistic("temperature_slope_dps_per_c" + look, t_stat, *temp_null));
    if (have_steps) out.statistics.push_back(makeStatistic("step_haar_max_z" + look, s_stat, step_null.max));
    const bool a = tempFires(y0), b = stepsFire(y0);
    bool use_t = false;
    std::vector<BlockStep> steps;
    std::string decision;
    if (a && !b) {
      use_t = true;
      const std::vector<double> r = minusTemperature(y0);
      if (stepsFire(r)) steps = findBlockSteps(r, c, step_null);
      decision = steps.empty() ? "the residual follows temperature; no step once it is removed"
                               : "the residual follows temperature, and steps remain once it is removed";
    } else if (!a && b) {
      steps = findBlockSteps(y0, c, step_null);
      use_t = !steps.empty() && tempFires(minusSteps(y0, steps));
      decision = use_t ? "abrupt steps, and a temperature response remains once they are removed"
                       : "abrupt steps in the bias; no temperature response";
    } else if (a && b) {
      // Both explanations fit: remove each and see whether the other still holds.
      const std::vector<double> r_t = minusTemperature(y0);
      const bool steps_after_t = stepsFire(r_t);
      const std::vector<BlockStep> steps0 = findBlockSteps(y0, c, step_null);
      const bool temp_after_s = !steps0.empty() && tempFires(minusSteps(y0, steps0));
      if (steps_after_t && temp_after_s) {
        use_t = true;
        steps = findBlockSteps(r_t, c, step_null);
        decision = "steps and a temperature response: each remains when the other is removed";
      } else if (steps_after_t) {
        steps = steps0;
        decision = "the temperature correlation vanishes once the steps are removed, the steps do not once the temperature fit is";
      } else if (temp_after_s) {
        use_t = true;
        decision = "the steps vanish once the temperature response is removed, not the other way round";
      } else {
        // Each explains the other away: the penalised likelihood (BIC) of the two models of
        // the low-passed residual decides; a step is abrupt, a temperature response smooth.
        double rss_t = 0.0, rss_s = 0.0;
        blockRegression(y0, &c.temp_blocks, {}, rss_t);
        blockRegression(y0, nullptr, steps0, rss_s);
        const double nb = static_cast<double>(y0.size());
        const double bic_t = nb * std::log(rss_t / nb) + 1.0 * std::log(nb);
        const double bic_s = nb * std::log(rss_s / nb) + 2.0 * static_cast<double>(steps0.size()) * std::log(nb);
        if (bic_t <= bic_s) {
          use_t = true;
        } else {
          steps = steps0;
        }
        decision = "either explains the other away; BIC of the low-passed residual: temperature " +
                   formatValue("%.1f", bic_t) + ", steps " + formatValue("%.1f", bic_s);
      }
    }
    if (use_t || !steps.empty()) {
      double rss = 0.0;
      const std::vector<double> coef = blockRegression(y0, use_t ? &c.temp_blocks : nullptr, steps, rss);
      std::size_t next = 0;
      if (use_t) {
        removal.temperature = true;
        removal.k = coef[next++];
      }
      for (BlockStep& s : steps) s.size = coef[next++];
      // Each step's sample, from the series with the temperature part and the other steps removed.
      std::vector<double> r = xc;
      if (use_t)
        for (std::size_t i = 0; i < r.size(); ++i) r[i] -= removal.k * temp_detrended[i];
      for (const BlockStep& s : steps)
        for (std::size_t i = s.block * c.block; i < r.size(); ++i) r[i] -= s.size;
      for (const BlockStep& s : steps) {
        for (std::size_t i = s.block * c.block; i < r.size(); ++i) r[i] += s.size;  // this one back
        const std::size_t at = refineStepSample(r, s.block * c.block, c.block, s.scale * c.block);
        for (std::size_t i = at; i < r.size(); ++i) r[i] -= s.size;
        removal.step_samples.push_back(at);
        removal.step_sizes.push_back(s.size);
      }
      if (use_t) {
        DetectedEffect e;
        e.effect = ModelEffect::TemperatureBias;
        e.k_dps_per_c = removal.k;
        e.evidence = "low-passed residual against the detrended temperature: slope " + formatValue("%.4g", t_stat) +
                     " deg/s/C, " + nullText(*temp_null, o.replicas) + " (two-sided on the distance); " + decision;
        out.effects.push_back(e);
      }
      if (!steps.empty()) {
        DetectedEffect e;
        e.effect = ModelEffect::BiasSteps;
        e.count = steps.size();
        for (std::size_t j = 0; j < removal.step_samples.size(); ++j) {
          const std::size_t i = removal.step_samples[j];
          e.times_s.push_back(input.time_s.empty() ? static_cast<double>(i) * tau0 : input.time_s[i]);
          e.sizes_dps.push_back(removal.step_sizes[j]);
        }
        e.evidence = "largest standardised Haar difference of the low-passed residual " + formatValue("%.3g", s_stat) + ", " +
                     nullText(step_null.max, o.replicas) + "; " + decision;
        out.effects.push_back(e);
      }
      const std::vector<double> d = deterministicPart({{}, removal.k, removal.temperature, removal.step_samples,
                                                       removal.step_sizes}, xc.size(), rate, temp_detrended);
      for (std::size_t i = 0; i < xc.size(); ++i) xc[i] -= d[i];
      deterministic_found = true;
    }
  }
  removeLinearTrend(xc, tau0);

  // ---- Gauss–Markov: a bump in the Allan curve of what is left --------------------------
  std::vector<AllanPoint> clean_curve = deterministic_found ? allanDeviationTable(xc, tau0, c.ms) : curve;
  const NoiseTermFit clean_fit = deterministic_found ? fitNoiseTerms(clean_curve) : out.base_fit;
  std::vector<double> clean_var;
  for (const AllanPoint& p : clean_curve) clean_var.push_back(p.oadev * p.oadev);
  const GaussMarkovCurveFit gm_fit = fitGaussMarkovToAllan(c.taus, clean_var, c.edf, c.t_grid);
  std::vector<double> gm_null_values;
  if (deterministic_found) {
    // The null of a model fitted to the cleaned series (the base fit also carried the effects).
    const std::vector<SeriesStats> reps = runReplicas(pureModel(rate, clean_fit.value), statisticalUncertainty(clean_fit), c, {}, o, 2, kStatGaussMarkov);
    out.replicas_simulated += o.replicas;
    gm_null_values = column(reps, &SeriesStats::gm_statistic);
  } else {
    gm_null_values = column(base_reps, &SeriesStats::gm_statistic);
  }
  const NullSummary gm_null = summarizeNull(gm_null_values, o.false_alarm, false);
  const double gm_stat = gaussMarkovStatistic(gm_fit);
  out.statistics.push_back(makeStatistic("gauss_markov_sqrt_chi2_gain", gm_stat, gm_null));
  const bool gm_found = gm_null.fires(gm_stat) && gm_fit.sigma_dps > 0.0;
  NoiseTerms extended_terms = clean_fit.value;
  if (gm_found) {
    extended_terms = gm_fit.terms_with_gm;
    DetectedEffect e;
    e.effect = ModelEffect::GaussMarkov;
    e.tau_s = gm_fit.tau_s;
    e.sigma_dps = gm_fit.sigma_dps;
    e.evidence = "a Gauss-Markov term in the Allan fit lowers the weighted residual by " +
                 formatValue("%.4g", gm_fit.improvement) + " (from " + formatValue("%.4g", gm_fit.chi2_base) +
                 "), " + nullText(gm_null, o.replicas);
    out.effects.push_back(e);
  }
  out.extended_fit = clean_fit;
  out.extended_fit.value = extended_terms;

  // ---- extended model and its replicas ----------------------------------------------------
  const bool any_model_effect = deterministic_found || gm_found;
  AllanNull ext_allan = base_allan;
  if (any_model_effect) {
    SimulationModel ext = pureModel(rate, extended_terms);
    AxisExtraEffects& extra = ext.axes[0].extra;
    for (const SinusoidFit& s : removal.sinusoids) extra.sinusoids.push_back({s.freq_hz, s.amp_dps, s.phase_rad});
    for (std::size_t j = 0; j < removal.step_samples.size(); ++j)
      extra.bias_steps.push_back({static_cast<double>(removal.step_samples[j]) * tau0, removal.step_sizes[j]});
    if (gm_found) {
      extra.gauss_markov_tau_s = gm_fit.tau_s;
      extra.gauss_markov_sigma_dps = gm_fit.sigma_dps;
    }
    extra.outlier_count = outlier_count;
    extra.outlier_amplitude_dps = outlier_amplitude;
    // The measured temperature drives the replicas' temperature term: the simulator's own
    // warm-up curve is not the recording's.
    std::vector<double> added;
    if (removal.temperature) {
      added.resize(c.n);
      for (std::size_t i = 0; i < c.n; ++i) added[i] = removal.k * temp_detrended[i];
    }
    const std::vector<SeriesStats> reps = runReplicas(ext, statisticalUncertainty(clean_fit), c, added, o, 3, kStatAllan);
    out.replicas_simulated += o.replicas;
    ext_allan = allanNull(reps, measured.log_adev, c, o.false_alarm);
  }
  out.allan_extended = ext_allan.band;
  std::vector<double> z_ext;
  const double ext_max_z = maxAbsZ(measured.log_adev, ext_allan.median_log, ext_allan.spread_log, &z_ext);
  out.statistics.push_back(makeStatistic("allan_band_max_z_extended", ext_max_z, ext_allan.max_z));
  if (ext_allan.max_z.fires(ext_max_z)) {
    DetectedEffect e;
    e.effect = ModelEffect::Unexplained;
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    for (std::size_t j = 0; j < z_ext.size(); ++j)
      if (std::fabs(z_ext[j]) >= std::min(3.0, ext_max_z)) {
        lo = std::min(lo, c.taus[j]);
        hi = std::max(hi, c.taus[j]);
      }
    e.where_lo = lo;
    e.where_hi = hi;
    e.evidence = "the measured Allan deviation leaves the " + std::string(any_model_effect ? "extended" : "base") +
                 " model's replicas at tau " + formatValue("%.4g", lo) + " to " + formatValue("%.4g", hi) +
                 " s (largest |z| " + formatValue("%.3g", ext_max_z) + ", threshold " +
                 formatValue("%.3g", ext_allan.max_z.threshold) + "); no catalogued effect accounts for it";
    out.effects.push_back(e);
  }

  // ---- gain --------------------------------------------------------------------------------
  bandFigures(out.allan_base, out.gain.adev_log_error_base, out.gain.in_band_base);
  bandFigures(out.allan_extended, out.gain.adev_log_error_extended, out.gain.in_band_extended);

  const std::size_t max_order = std::min(o.max_ar_order, xd.size() / 10);
  const std::vector<ArModel> ar_base = yuleWalker(xd, max_order);
  const ArModel& base_ar = ar_base[orderByAic(ar_base) - 1];
  out.ar_order = base_ar.order();
  const InnovationStats inn_base = kalmanInnovations(xd, base_ar.phi, base_ar.noise_var, 0.0, 0.0, false);
  out.gain.innovation_var_base = inn_base.variance;
  out.gain.ljung_box_p_base = ljungBoxTest(inn_base.innovations, o.ljung_box_lags, base_ar.order()).p_value;

  if (any_model_effect) {
    // Measured series minus the deterministic effects (regressors); the AR part refitted on the
    // cleaned series, with the Gauss–Markov autocovariance σ²ρ^k taken out of it when named.
    std::vector<double> z = xd;
    const std::vector<double> d = deterministicPart(removal, z.size(), rate, temp_detrended);
    for (std::size_t i = 0; i < z.size(); ++i) z[i] -= d[i];
    removeLinearTrend(z, tau0);
    const std::vector<ArModel> ar_clean = yuleWalker(xc, max_order);
    const ArModel& clean_ar = ar_clean[orderByAic(ar_clean) - 1];
    std::vector<double> phi = clean_ar.phi;
    double noise_var = clean_ar.noise_var;
    double gm_decay = 0.0, gm_q = 0.0;
    if (gm_found) {
      const double rho = std::exp(-tau0 / gm_fit.tau_s);
      std::vector<double> gamma = autocovariance(xc, clean_ar.order());
      double var_gm = gm_fit.sigma_dps * gm_fit.sigma_dps;
      // Keep what is left positive definite: shrink the GM share if it takes too much.
      for (int attempt = 0; attempt < 20; ++attempt, var_gm *= 0.8) {
        std::vector<double> adj = gamma;
        for (std::size_t k = 0; k < adj.size(); ++k) adj[k] -= var_gm * std::pow(rho, static_cast<double>(k));
        std::vector<double> phi_adj;
        double v_adj = 0.0;
        if (levinsonFromAutocovariance(adj, clean_ar.order(), phi_adj, v_adj)) {
          phi = phi_adj;
          noise_var = v_adj;
          gm_decay = rho;
          gm_q = var_gm * (1.0 - rho * rho);
          break;
        }
      }
    }
    const InnovationStats inn_ext = kalmanInnovations(z, phi, noise_var, gm_decay, gm_q, outlier_count > 0);
    out.gain.innovation_var_extended = inn_ext.variance;
    out.gain.ljung_box_p_extended =
        ljungBoxTest(inn_ext.innovations, o.ljung_box_lags, phi.size() + (gm_q > 0.0 ? 2 : 0)).p_value;
  } else {
    out.gain.innovation_var_extended = out.gain.innovation_var_base;
    out.gain.ljung_box_p_extended = out.gain.ljung_box_p_base;
  }
  return out;
}

}  // namespace gyrod::processing
