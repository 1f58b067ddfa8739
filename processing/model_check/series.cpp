// What the model check measures on every series, the measured one and each replica alike:
// the Allan curve, the largest outlier, the largest narrow spectral peak, the temperature
// slope and the largest step of the low-passed residual, the Gauss–Markov χ² gain.
#include <algorithm>
#include <cmath>
#include <vector>

#include "processing/model_check/pipeline.hpp"

namespace gyrod::processing::model_check_detail {
namespace {

constexpr std::size_t kMaxBlocks = 8192;
constexpr std::size_t kAllanPerDecade = 5;
constexpr std::size_t kPsdBands = 48;

}  // namespace

SearchedBins searchedBins(std::size_t n) {
  SearchedBins b;
  b.nfft = fftLength(n);
  // At least 10 cycles in the series, and clear of the lowest bins where the background
  // (random walk, flicker) changes too fast for a local median.
  b.k_lo = std::max<std::size_t>(
      64, static_cast<std::size_t>(std::ceil(10.0 * static_cast<double>(b.nfft) / static_cast<double>(n))));
  // Up to a few bins below Nyquist: real lines sit there (on tests/data's set-2 records one
  // 0.46 Hz wide at 48.8 Hz, 98.2 % of Nyquist); the line model is an AR(2), whose spectrum
  // folds at Nyquist as a sampled line's does, and the replicas' null covers a background
  // with bins on one side only.
  b.k_hi = b.nfft / 2 - 4;
  return b;
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
  // Haar scales of the step scan (steps.cpp): 2, 4, … blocks, up to 1/16 of the record.
  for (std::size_t w = 2; 16 * w <= c.blocks; w *= 2) c.scales.push_back(w);

  const SearchedBins bins = searchedBins(c.n);
  c.k_lo = bins.k_lo;
  c.k_hi = bins.k_hi;
  const double df = in.rate_hz / static_cast<double>(bins.nfft);
  c.line_scales = lineScanScales(c.k_hi > c.k_lo ? c.k_hi - c.k_lo : 0, df);
  c.line_background_block = lineBackgroundBlock(df);
  c.line_halves = lineScanHalves(c.n, in.rate_hz);
  const double f_lo = 2.0 / duration, f_hi = 0.5 * in.rate_hz;
  for (std::size_t j = 0; j <= kPsdBands; ++j)
    c.psd_edges.push_back(f_lo * std::pow(f_hi / f_lo, static_cast<double>(j) / static_cast<double>(kPsdBands)));
  c.chain = makeChainModel(in.chain, in.rate_hz, c.ms);
  return c;
}

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

SeriesStats measureSeries(std::span<const double> xd, const Context& c, unsigned mask) {
  SeriesStats s;
  if (mask & (kStatAllan | kStatGaussMarkov)) {
    const std::vector<double> v = overlappingAllanVariances(xd, c.ms);
    s.log_adev.resize(v.size());
    for (std::size_t j = 0; j < v.size(); ++j) s.log_adev[j] = 0.5 * std::log(v[j]);
    if (mask & kStatGaussMarkov)
      s.gm_statistic = gaussMarkovStatistic(fitGaussMarkovToAllan(c.taus, v, c.edf, c.t_grid));
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
      s.line_scan = std::max(
          scanForLines(p.power, blockMedianBackground(p.power, c.line_background_block), c.k_lo, c.k_hi, c.line_scales)
              .statistic,
          scanHalvesForLines(xd, c).statistic);
    }
    if (mask & kStatPsd) s.psd = bandAveragedPsd(p, c.rate, c.psd_edges, &s.psd_max);
  }
  if (mask & (kStatTemperature | kStatSteps)) {
    const std::vector<double> y = lowPassedResidual(xd, c);
    if ((mask & kStatTemperature) && !c.temp_blocks.empty()) s.temp_slope = temperatureSlope(y, c.temp_blocks);
    if (mask & kStatSteps) measureStepScales(y, c, s);
  }
  if (mask & kStatWhiteness) {
    s.whiteness_q = heldOutWhiteness(xd.first(xd.size() / 2), xd.subspan(xd.size() / 2)).test.q;
    const HalvesChange h = halvesChange(xd, c.rate);
    s.halves_colour_q = h.colour_q;
    s.halves_spectrum_stat = h.spectrum_stat;
  }
  return s;
}

std::vector<double> column(const std::vector<SeriesStats>& reps, double SeriesStats::*field) {
  std::vector<double> v;
  v.reserve(reps.size());
  for (const SeriesStats& s : reps) v.push_back(s.*field);
  return v;
}

double medianOf(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return sortedQuantile(v, 0.5);
}

CheckStatistic makeStatistic(const std::string& name, double value, const NullSummary& null) {
  return {name, value, null.median, null.two_sided ? null.median + null.threshold : null.threshold, null.fires(value)};
}

EffectEvidence nullEvidence(double value, const NullSummary& null, std::size_t replicas) {
  EffectEvidence e;
  e.statistic = value;
  e.threshold = null.threshold;
  e.null_median = null.median;
  e.replicas = replicas;
  return e;
}

}  // namespace gyrod::processing::model_check_detail
