// The replicas of the model check: series simulated from a fitted model (its terms perturbed
// by their uncertainty), on a small thread pool, each seeded from (seed, round, index) alone
// and stored by index, so the result does not depend on the number of threads. And the Allan
// band they draw around the measured curve.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>

#include "processing/base/detrend.hpp"
#include "processing/base/portable_random.hpp"
#include "processing/model_check/pipeline.hpp"

namespace gyrod::processing::model_check_detail {
namespace {

std::uint64_t replicaSeed(std::uint64_t seed, std::uint64_t round, std::uint64_t index) {
  SplitMix64 mix(seed ^ (0xD1B54A32D192ED03ULL * (round + 1)));
  std::uint64_t s = mix.next();
  SplitMix64 second(s + 0x9E3779B97F4A7C15ULL * (index + 1));
  return second.next();
}

// One replica of axis x of `model` (terms as the output shows them at long τ), n samples,
// through the acquisition chain of c, plus `added` (same length, or empty), detrended as the
// measured series is. The chain's white noise is drawn at the output rate with the chain's
// autocovariance (chain.cpp); the rounding adds white noise of its own, which
// the white term already holds, so that much is taken out of it.
std::vector<double> simulateReplica(const SimulationModel& model, const Context& c, std::uint64_t seed,
                                    std::span<const double> added) {
  const std::size_t n = c.n;
  SimulationModel pure = model;
  NoiseTerms& terms = pure.axes[0].terms;
  const double white = whiteCoefficientOf(terms);
  if (c.chain.dlpf_cfg)
    terms.set(NoiseTerm::AngleRandomWalk, 0.0);
  else if (c.chain.lsb_dps > 0.0)
    terms.set(NoiseTerm::AngleRandomWalk,
              noiseTermFromCoefficient(NoiseTerm::AngleRandomWalk, std::max(0.0, white - c.chain.quantisation_white)));
  // Through a DLPF the flicker (bias instability) is filtered too: drawn by a simulator of
  // its own (its own seed), through the chain's output-rate filter for flicker.
  const double flicker = terms.get(NoiseTerm::BiasInstability);
  const bool filter_flicker = c.chain.dlpf_cfg && !c.chain.flicker_ma.empty() && flicker > 0.0;
  if (filter_flicker) terms.set(NoiseTerm::BiasInstability, 0.0);
  NoiseSimulator sim(pure, static_cast<double>(n) / model.rate_hz, seed);
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = sim.next().rate_dps[0];
  if (filter_flicker) {
    SimulationModel flicker_only = pureModel(model.rate_hz, {});
    flicker_only.axes[0].terms.set(NoiseTerm::BiasInstability, flicker);
    const std::size_t padded = n + c.chain.flicker_ma.size() - 1;
    NoiseSimulator flicker_sim(flicker_only, static_cast<double>(padded) / model.rate_hz, seed ^ 0x7F4A7C159E3779B9ULL);
    std::vector<double> raw(padded);
    for (double& v : raw) v = flicker_sim.next().rate_dps[0];
    const std::vector<double> filtered = filterChainFlicker(raw, c.chain, n);
    for (std::size_t i = 0; i < n; ++i) x[i] += filtered[i];
  }
  if (c.chain.dlpf_cfg) addChainWhiteNoise(x, c.chain, white, seed);
  if (!added.empty())
    for (std::size_t i = 0; i < n; ++i) x[i] += added[i];
  quantiseLikeTheChip(x, c.chain, seed);
  removeLinearTrend(x, 1.0 / model.rate_hz);
  return x;
}

// body(i) for i in [0, count) on up to `threads` threads; the first exception is rethrown.
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

}  // namespace

// The statistical part of a fit's uncertainty: noise_fit scales the covariance by
// max(1, reduced χ²), which would let a model that fits the curve badly widen its own null
// and hide the misfit; that scale is taken out again (σ_c ∝ √scale, so a fitted term's
// σ_T ∝ √scale and a zero term's bound, T ∝ √σ_c, ∝ scale^¼).
NoiseTerms statisticalUncertainty(const NoiseTermFit& fit) {
  const double scale = std::isfinite(fit.reduced_chi2) ? std::max(1.0, fit.reduced_chi2) : 1.0;
  NoiseTerms u;
  for (NoiseTerm t : kAllNoiseTerms)
    u.set(t, fit.value.get(t) > 0.0 ? fit.uncertainty.get(t) / std::sqrt(scale)
                                    : fit.uncertainty.get(t) / std::pow(scale, 0.25));
  return u;
}

std::vector<SeriesStats> runReplicas(const SimulationModel& model, const NoiseTerms& uncertainty, const Context& c,
                                     std::span<const double> added, const ModelCheckOptions& o, std::uint64_t round,
                                     unsigned mask, const ReplicaSeriesHook& per_series) {
  std::vector<SeriesStats> out(o.replicas);
  parallelFor(o.replicas, o.threads, [&](std::size_t i) {
    const std::uint64_t seed = replicaSeed(o.seed, round, i);
    const std::vector<double> x = simulateReplica(replicaModel(model, uncertainty, seed), c, seed, added);
    out[i] = measureSeries(x, c, mask);
    if (per_series) per_series(i, x);
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

double maxAbsZ(const std::vector<double>& log_adev, const std::vector<double>& med, const std::vector<double>& spread,
               std::vector<double>* z_out) {
  double m = 0.0;
  if (z_out) z_out->assign(log_adev.size(), 0.0);
  for (std::size_t j = 0; j < log_adev.size(); ++j) {
    const double z = spread[j] > 0.0 ? (log_adev[j] - med[j]) / spread[j] : 0.0;
    if (z_out) (*z_out)[j] = z;
    m = std::max(m, std::fabs(z));
  }
  return m;
}

namespace {

// One τ's spread of the replicas in log ADEV, each side of the median on its own (the
// distribution of a log ADEV is skewed at long τ, where few clusters average).
struct LogSpread {
  double median = 0.0, below = 0.0, above = 0.0;
  double z(double v) const {
    const double w = v >= median ? above : below;
    return w > 0.0 ? (v - median) / w : (v == median ? 0.0 : std::numeric_limits<double>::infinity());
  }
};
LogSpread logSpread(const std::vector<double>& sorted) {
  LogSpread s;
  s.median = sortedQuantile(sorted, 0.5);
  s.below = s.median - sortedQuantile(sorted, 0.1587);
  s.above = sortedQuantile(sorted, 0.8413) - s.median;
  return s;
}

// AllanBand's simultaneous band (see model_check.hpp): every replica's |z| at every τ against
// the other replicas, their largest |z| per replica, and its 90 % quantile.
void jointAllanBand(const std::vector<SeriesStats>& reps, const std::vector<double>& measured_log, AllanBand& band) {
  const std::size_t n = reps.size(), k = measured_log.size();
  if (n < 4 || k == 0) return;
  std::vector<std::vector<double>> z(n, std::vector<double>(k));
  std::vector<LogSpread> all(k);
  std::vector<double> col(n), others;
  for (std::size_t j = 0; j < k; ++j) {
    for (std::size_t r = 0; r < n; ++r) col[r] = reps[r].log_adev[j];
    std::vector<double> sorted = col;
    std::sort(sorted.begin(), sorted.end());
    all[j] = logSpread(sorted);
    for (std::size_t r = 0; r < n; ++r) {
      others = sorted;
      others.erase(std::lower_bound(others.begin(), others.end(), col[r]));
      z[r][j] = std::fabs(logSpread(others).z(col[r]));
    }
  }
  std::vector<double> largest(n);
  for (std::size_t r = 0; r < n; ++r) largest[r] = *std::max_element(z[r].begin(), z[r].end());
  std::vector<double> sorted_largest = largest;
  std::sort(sorted_largest.begin(), sorted_largest.end());
  band.joint_z = sortedQuantile(sorted_largest, 0.9);
  for (std::size_t j = 0; j < k; ++j) {
    band.joint_lo.push_back(std::exp(all[j].median - band.joint_z * all[j].below));
    band.joint_hi.push_back(std::exp(all[j].median + band.joint_z * all[j].above));
  }
  for (std::size_t r = 0; r < n; ++r) {
    // Replica r against the others' band: their 90 % quantile of the largest |z|.
    others = sorted_largest;
    others.erase(std::lower_bound(others.begin(), others.end(), largest[r]));
    const double c = sortedQuantile(others, 0.9);
    const auto inside = std::count_if(z[r].begin(), z[r].end(), [c](double v) { return v <= c; });
    band.replica_in_joint_band.push_back(static_cast<double>(inside) / static_cast<double>(k));
  }
  std::size_t inside = 0;
  for (std::size_t j = 0; j < k; ++j) inside += std::fabs(all[j].z(measured_log[j])) <= band.joint_z ? 1 : 0;
  band.measured_in_joint_band = static_cast<double>(inside) / static_cast<double>(k);
}

}  // namespace

AllanNull allanNull(const std::vector<SeriesStats>& reps, const std::vector<double>& measured_log, const Context& c,
                    double alpha) {
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
  // Leave one out: replica r against the 5–95 % band of the others, τ by τ.
  std::vector<std::size_t> inside(reps.size(), 0);
  std::vector<double> others;
  for (std::size_t j = 0; j < k && reps.size() > 2; ++j) {
    for (std::size_t r = 0; r < reps.size(); ++r) col[r] = reps[r].log_adev[j];
    std::vector<double> sorted = col;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t r = 0; r < reps.size(); ++r) {
      others = sorted;
      others.erase(std::lower_bound(others.begin(), others.end(), col[r]));
      inside[r] += (col[r] >= sortedQuantile(others, 0.05) && col[r] <= sortedQuantile(others, 0.95)) ? 1 : 0;
    }
  }
  if (reps.size() > 2 && k > 0)
    for (std::size_t r = 0; r < reps.size(); ++r)
      a.band.replica_in_band.push_back(static_cast<double>(inside[r]) / static_cast<double>(k));
  jointAllanBand(reps, measured_log, a.band);
  std::vector<double> maxes(reps.size());
  for (std::size_t r = 0; r < reps.size(); ++r) maxes[r] = maxAbsZ(reps[r].log_adev, a.median_log, a.spread_log);
  a.max_z = summarizeNull(maxes, alpha, false);
  for (const SeriesStats& r : reps) {
    if (std::isfinite(r.whiteness_q)) a.whiteness_q.push_back(r.whiteness_q);
    if (std::isfinite(r.halves_colour_q)) a.halves_colour_q.push_back(r.halves_colour_q);
    if (std::isfinite(r.halves_spectrum_stat)) a.halves_spectrum_stat.push_back(r.halves_spectrum_stat);
  }
  return a;
}

}  // namespace gyrod::processing::model_check_detail
