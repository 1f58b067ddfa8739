#include "processing/axis_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "processing/parallel_share.hpp"

namespace gyrod::processing {

namespace {

// The long double mean of varianceAboutMean and peakDeviationFromMean, formed once for both.
long double longDoubleMean(std::span<const double> x) {
  long double mean = 0.0L;
  for (double v : x) mean += v;
  return mean / static_cast<long double>(x.size());
}
double varianceAbout(std::span<const double> x, long double mean) {
  long double ss = 0.0L;
  for (double v : x) ss += (v - mean) * (v - mean);
  return static_cast<double>(ss / static_cast<long double>(x.size()));
}
double peakDeviationFrom(std::span<const double> x, long double mean) {
  double peak = 0.0;
  for (double v : x) peak = std::max(peak, std::abs(static_cast<double>(v - mean)));
  return peak;
}

struct Spread {
  double variance = 0.0;
  double peak = 0.0;
};
// varianceAboutMean(x) and peakDeviationFromMean(x), the same bits, with one mean pass.
Spread spreadAboutMean(std::span<const double> x) {
  if (x.empty()) return {};
  const long double mean = longDoubleMean(x);
  return {varianceAbout(x, mean), peakDeviationFrom(x, mean)};
}

}  // namespace

double varianceAboutMean(std::span<const double> x) {
  if (x.empty()) return 0.0;
  return varianceAbout(x, longDoubleMean(x));
}

double peakDeviationFromMean(std::span<const double> x) {
  if (x.empty()) return 0.0;
  return peakDeviationFrom(x, longDoubleMean(x));
}

namespace {

// GrossErrorMeanFilter's output over x, in contiguous shares on the cores. Its output is a
// function of the window's samples in time order only, so a share starting at i0 first feeds
// its own filter the L − 1 samples before i0 (or all from 0 while the window is filling) and
// then gives the same bits as one filter run from the start. x is finite (the tests on the
// raw series have checked it), so no share throws.
std::vector<double> meanFiltered(std::span<const double> x, std::size_t window, double threshold) {
  std::vector<double> out(x.size());
  const GrossErrorMeanFilter validated(window, threshold);  // throws for bad parameters here, not in a thread
  forEachShare(
      x.size(),
      [&](std::size_t first, std::size_t end) {
        GrossErrorMeanFilter mean(window, threshold);
        for (std::size_t i = first >= window - 1 ? first - (window - 1) : 0; i < first; ++i) mean.update(x[i]);
        for (std::size_t i = first; i < end; ++i) out[i] = mean.update(x[i]);
      },
      std::size_t{1} << 16);
  return out;
}

}  // namespace

AxisAnalysis analyzeAxis(std::span<const double> rate_dps, const AnalysisOptions& options) {
  return analyzeAxis(std::vector<double>(rate_dps.begin(), rate_dps.end()), options);
}

// The steps hold at most three series' worth of doubles at once (the series and the
// Allan phase, twice its size; later the mean-filter output in place of the series):
// 24 bytes a sample.
AxisAnalysis analyzeAxis(std::vector<double>&& rate_dps, const AnalysisOptions& options) {
  if (!(options.rate_hz > 0.0) || !std::isfinite(options.rate_hz))
    throw std::invalid_argument("the axis analysis needs a sample rate that is a positive number of Hz, got " +
                                std::to_string(options.rate_hz));
  const double tau0 = 1.0 / options.rate_hz;
  AxisAnalysis a;
  a.samples = rate_dps.size();

  // 1. Tests on the raw series, before any preprocessing (paper §3.2.1); they only read it,
  // so two run beside the third.
  runBoth(
      [&] {
        a.zero_mean = zeroMeanTest(rate_dps);
        a.reverse_arrangements = reverseArrangementsTest(rate_dps, options.reverse_arrangements_segments);
      },
      [&] { a.normality = chiSquareNormalityTest(rate_dps); });

  // 2. Preprocessing (§3.2.2), in place: the raw series is not needed again.
  std::vector<double> x = std::move(rate_dps);
  if (options.detrend) a.trend_removed = removeLinearTrend(x, tau0);

  // 3. Allan deviation and noise terms (§3.2.3, Table 2).
  std::vector<std::size_t> ms = options.cluster_sizes.empty() ? octaveClusterSizes(x.size()) : options.cluster_sizes;
  a.allan = allanDeviationTable(x, tau0, ms);
  a.noise = fitNoiseTerms(a.allan);
  a.noise_from_slopes = readNoiseTermsFromSlopes(a.allan);

  // 4–6. Mean filter, AR models of its output, Kalman on AR(1) (§4–5). The mean filter runs
  // once: its output identifies the Kalman and then feeds it, exactly as AxisFilterChain
  // (mean filter, then Kalman) would on the same series.
  std::vector<double> filtered = meanFiltered(x, options.mean_window, options.mean_threshold_dps);
  // The identification and the AR models beside the spreads: all only read x and filtered.
  double peak_raw = 0.0;
  runBoth(
      [&] {
        a.filter = identifyFilterChainFromMeanFiltered(x, filtered, options.mean_window, options.mean_threshold_dps,
                                                       options.kalman_overrides);
        a.ar = yuleWalker(filtered, options.max_ar_order);
        a.ar_order_aic = orderByAic(a.ar);
        a.ar_order_bic = orderByBic(a.ar);
        a.steady_state_gain = steadyStateGain(a.filter.kalman.a, a.filter.kalman.q, a.filter.kalman.r);
      },
      [&] {
        const Spread raw = spreadAboutMean(x);
        a.variance.raw = raw.variance;
        peak_raw = raw.peak;
        a.variance.mean = varianceAboutMean(filtered);
      });
  x = std::vector<double>();  // the Kalman output takes the mean-filter output's place

  ScalarKalmanFilter kalman(a.filter.kalman);
  for (double& v : filtered) v = kalman.update(v);
  const std::vector<double>& kalman_filtered = filtered;

  // Table 4: the same Allan analysis on the Kalman output, beside its spread.
  runBoth([&] { a.allan_after_kalman = allanDeviationTable(kalman_filtered, tau0, ms); },
          [&] {
            const Spread after = spreadAboutMean(kalman_filtered);
            a.variance.kalman = after.variance;
            a.peak_ratio = peak_raw > 0.0 ? after.peak / peak_raw : 0.0;
          });
  a.noise_after_kalman = fitNoiseTerms(a.allan_after_kalman);
  return a;
}

}  // namespace gyrod::processing
