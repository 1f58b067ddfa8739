// The model check of one axis: base fit → replicas → statistics against their nulls →
// named causes → extended model → replicas again → gain. See model_check.hpp and
// docs/model-check.md; the stages are in pipeline.hpp.
#include "processing/model_check/model_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <thread>

#include "processing/base/detrend.hpp"
#include "processing/model_check/pipeline.hpp"
#include "processing/paper/kalman.hpp"
#include "processing/simulation/sensor_model.hpp"

namespace gyrod::processing {
namespace {

using namespace model_check_detail;

std::string formatValue(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

void validateChannels(const AxisModelCheckInput& in) {
  if (!(std::isfinite(in.rate_hz) && in.rate_hz > 0.0))
    throw std::invalid_argument("model check: rate_hz must be finite and > 0, got " + formatValue("%g", in.rate_hz));
  if (in.rate_dps.size() < kModelCheckMinSamples)
    throw std::invalid_argument("model check: " + std::to_string(in.rate_dps.size()) +
                                " samples are too few (need at least " + std::to_string(kModelCheckMinSamples) + ")");
  for (std::size_t i = 0; i < in.rate_dps.size(); ++i)
    if (!std::isfinite(in.rate_dps[i]))
      throw std::invalid_argument("model check: rate sample " + std::to_string(i) + " is not finite");
  if (!in.temperature_c.empty()) {
    if (in.temperature_c.size() != in.rate_dps.size())
      throw std::invalid_argument("model check: the temperature channel has " +
                                  std::to_string(in.temperature_c.size()) + " samples, the rate " +
                                  std::to_string(in.rate_dps.size()));
    for (std::size_t i = 0; i < in.temperature_c.size(); ++i)
      if (!std::isfinite(in.temperature_c[i]))
        throw std::invalid_argument("model check: temperature sample " + std::to_string(i) + " is not finite");
  }
  try {
    if (in.chain.dlpf_cfg) sampleRateDivisor(*in.chain.dlpf_cfg, in.rate_hz);
    if (in.chain.fs_sel) gyroSensitivityLsbPerDps(*in.chain.fs_sel);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("model check: acquisition chain: ") + e.what());
  }
  if (!in.time_s.empty() && in.time_s.size() != in.rate_dps.size())
    throw std::invalid_argument("model check: the time channel has " + std::to_string(in.time_s.size()) +
                                " samples, the rate " + std::to_string(in.rate_dps.size()));
}

void validateOptions(const ModelCheckOptions& o) {
  if (o.replicas < 8)
    throw std::invalid_argument("model check: replicas must be >= 8, got " + std::to_string(o.replicas));
  if (!(o.false_alarm > 0.0 && o.false_alarm < 0.5))
    throw std::invalid_argument("model check: false_alarm must be in (0, 0.5), got " +
                                formatValue("%g", o.false_alarm));
  if (o.ljung_box_lags < 1) throw std::invalid_argument("model check: ljung_box_lags must be >= 1");
  if (o.max_ar_order < 1 || o.max_ar_order > kMaxArOrder)
    throw std::invalid_argument("model check: max_ar_order must be 1.." + std::to_string(kMaxArOrder));
}

// Temperature, detrended like the rate (a linear temperature drift is a rate ramp to any
// static analysis, and the ramp is already in the base model); its block means go into
// c.temp_blocks when the channel moves.
TemperatureChannel prepareTemperature(std::span<const double> temperature_c, Context& c) {
  TemperatureChannel t;
  if (temperature_c.empty()) return t;
  t.detrended.assign(temperature_c.begin(), temperature_c.end());
  removeLinearTrend(t.detrended, c.tau0);
  std::vector<double> tb = blockMeans(t.detrended, c.block);
  removeLineInPlace(tb);
  double ss = 0.0;
  for (double v : tb) ss += v * v;
  // A channel that does not move (beyond 1 mK rms of its line) carries no evidence.
  if (tb.size() >= 8 && std::sqrt(ss / static_cast<double>(tb.size())) > 1e-3) c.temp_blocks = std::move(tb);
  t.raw_blocks = blockMeans(temperature_c, c.block);
  t.smoothed.resize(t.detrended.size());
  std::vector<double> prefix(t.detrended.size() + 1, 0.0);
  for (std::size_t i = 0; i < t.detrended.size(); ++i) prefix[i + 1] = prefix[i] + t.detrended[i];
  const std::size_t half = c.block / 2;
  for (std::size_t i = 0; i < t.detrended.size(); ++i) {
    const std::size_t lo = i >= half ? i - half : 0, hi = std::min(t.detrended.size(), i + half + 1);
    t.smoothed[i] = (prefix[hi] - prefix[lo]) / static_cast<double>(hi - lo);
  }
  return t;
}

// Plots: spectrum of the measured series and the replicas' median per band.
void spectrumForPlots(const SeriesStats& measured, const std::vector<SeriesStats>& base_reps, const Context& c,
                      AxisModelCheck& out) {
  out.spectrum_measured = measured.psd;
  out.spectrum_measured_peak = measured.psd_max;
  for (std::size_t j = 0; j + 1 < c.psd_edges.size(); ++j) {
    out.spectrum_freq_hz.push_back(std::sqrt(c.psd_edges[j] * c.psd_edges[j + 1]));
    std::vector<double> col;
    for (const SeriesStats& r : base_reps)
      if (std::isfinite(r.psd[j])) col.push_back(r.psd[j]);
    out.spectrum_base_median.push_back(col.empty() ? kNaN : medianOf(col));
    out.spectrum_base_max.push_back(col.empty() ? kNaN : *std::max_element(col.begin(), col.end()));
  }
}

// The Gauss–Markov stage fits the cleaned series' Allan curve as it is; through a DLPF the
// terms (and a Gauss–Markov process named) are refitted to the curve with the chain's shape.
void refitThroughChain(std::span<const double> xc, const Context& c, bool deterministic_found, GaussMarkovFound& gm,
                       AxisModelCheck& out) {
  if (!c.chain.dlpf_cfg) return;
  const std::vector<AllanPoint> clean_curve = allanDeviationTable(xc, c.tau0, c.ms);
  gm.clean_fit = deterministic_found ? fitChainTerms(clean_curve, c) : out.base_fit;
  gm.extended_terms = gm.clean_fit.value;
  if (!gm.found) return;
  std::vector<double> variance;
  variance.reserve(clean_curve.size());
  for (const AllanPoint& p : clean_curve) variance.push_back(p.oadev * p.oadev);
  NoiseTerms terms = gm.clean_fit.value;
  for (int pass = 0; pass < 4; ++pass) {
    const std::vector<double> corrected = chainCorrectedVariances(variance, c, terms);
    const std::vector<double> t_fixed{gm.fit.tau_s};
    const GaussMarkovCurveFit refit = fitGaussMarkovToAllan(c.taus, corrected, c.edf, t_fixed);
    terms = refit.terms_with_gm;
    gm.fit.sigma_dps = refit.sigma_dps;
  }
  gm.extended_terms = terms;
  for (DetectedEffect& e : out.effects)
    if (e.effect == ModelEffect::GaussMarkov) e.sigma_dps = gm.fit.sigma_dps;
}

// Outliers alone: isolated spikes are white to the Allan variance (each adds a²/n of variance
// per sample), so the base model already predicts the measured curve, spikes included. The
// extended model is the base model with that much white noise handed to the spikes, not a
// refit of the cleaned series: a refit redistributes the poorly constrained long-τ terms at
// random, and its replicas then miss the curve the base model held (seen: in-band fraction
// 1.00 → 0.59 with 50 of 50 spikes found). Removing the outliers leaves the base model's curve.
void spikesAsWhiteNoise(std::span<const double> xd, std::span<const double> xc, const Context& c, GaussMarkovFound& gm,
                        AxisModelCheck& out) {
  double energy = 0.0;
  for (std::size_t i = 0; i < xd.size(); ++i) energy += (xd[i] - xc[i]) * (xd[i] - xc[i]);
  const double spike_white = energy / static_cast<double>(xd.size()) * c.tau0;
  gm.clean_fit = out.base_fit;
  const double white = std::max(0.0, whiteCoefficientOf(out.base_fit.value) - spike_white);
  gm.clean_fit.value.set(NoiseTerm::AngleRandomWalk, noiseTermFromCoefficient(NoiseTerm::AngleRandomWalk, white));
  gm.extended_terms = gm.clean_fit.value;
}

}  // namespace

AxisModelCheck checkAxisModel(const AxisModelCheckInput& input, const ModelCheckOptions& options_in) {
  validateChannels(input);
  validateOptions(options_in);
  ModelCheckOptions o = options_in;
  if (o.threads == 0) o.threads = std::max(1u, std::thread::hardware_concurrency());

  AxisModelCheck out;
  out.samples = input.rate_dps.size();
  std::vector<double> xd(input.rate_dps.begin(), input.rate_dps.end());
  removeLinearTrend(xd, 1.0 / input.rate_hz);

  std::vector<AllanPoint> curve;
  Context c = makeContext(input, xd, curve);
  out.base_fit = fitChainTerms(curve, c);
  out.chain = input.chain;
  const TemperatureChannel temp = prepareTemperature(input.temperature_c, c);
  if (!input.time_s.empty()) checkSampleTiming(input.time_s, out);

  // Round 1: replicas of the base model, the nulls of every statistic.
  const std::vector<SeriesStats> base_reps =
      runReplicas(pureModel(c.rate, out.base_fit.value), statisticalUncertainty(out.base_fit), c, {}, o, 1, kStatAll);
  out.replicas_simulated += o.replicas;
  const SeriesStats measured = measureSeries(xd, c, kStatAllan | kStatPsd);
  const AllanNull base_allan = allanNull(base_reps, measured.log_adev, c, o.false_alarm);
  out.allan_base = base_allan.band;
  out.statistics.push_back(makeStatistic("allan_band_max_z_base",
                                         maxAbsZ(measured.log_adev, base_allan.median_log, base_allan.spread_log),
                                         base_allan.max_z));
  spectrumForPlots(measured, base_reps, c, out);

  const NullSummary outlier_null = summarizeNull(column(base_reps, &SeriesStats::outlier_max_z), o.false_alarm, false);
  const NullSummary spectral_null =
      summarizeNull(column(base_reps, &SeriesStats::spectral_log_ratio), o.false_alarm, false);
  const NullSummary line_scan_null = summarizeNull(column(base_reps, &SeriesStats::line_scan), o.false_alarm, false);

  // The detectors, each removing what it names from xc (the measured series, cleaned).
  std::vector<double> xc = xd;
  Removal removal;
  const OutliersFound outliers = checkOutliers(xd, xc, outlier_null, o.replicas, out);
  bool deterministic_found = outliers.found;
  deterministic_found =
      checkSinusoids(xc, c, spectral_null, line_scan_null, o.replicas, removal, out) || deterministic_found;
  deterministic_found = checkTemperatureAndSteps(input, xc, c, temp, base_reps, o, removal, out) || deterministic_found;
  removeLinearTrend(xc, c.tau0);
  GaussMarkovFound gm = checkGaussMarkov(xc, c, deterministic_found, curve, base_reps, o, out);
  refitThroughChain(xc, c, deterministic_found, gm, out);
  const bool outliers_alone = outliers.found && removal.sinusoids.empty() && removal.lines.empty() &&
                              !removal.temperature && removal.step_samples.empty() && !gm.found;
  if (outliers_alone) spikesAsWhiteNoise(xd, xc, c, gm, out);
  out.extended_fit = gm.clean_fit;
  out.extended_fit.value = gm.extended_terms;

  ExtensionInputs ext;
  ext.xd = xd;
  ext.xc = xc;
  ext.measured_log_adev = &measured.log_adev;
  ext.base_allan = &base_allan;
  ext.removal = &removal;
  ext.temp_detrended = &temp.smoothed;
  ext.gauss_markov = &gm;
  ext.outliers = outliers;
  ext.deterministic_found = deterministic_found;
  checkExtendedModel(ext, c, o, out);
  return out;
}

}  // namespace gyrod::processing
