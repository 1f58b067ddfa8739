#include "processing/paper/axis_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <optional>
#include <stdexcept>

#include "processing/base/isa_clones.hpp"
#include "processing/base/parallel_share.hpp"

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

// GrossErrorMeanFilter's outputs out[i], first ≤ i < end, for full windows (i ≥ L − 1):
// the window of out[i] is x[i − L + 1 .. i], contiguous in x. The filter sums the window in
// time order, then the kept samples in time order; here four outputs are formed at once,
// each lane doing exactly those additions in that order (four independent chains instead of
// one: the same bits, about four times the speed; one AVX2 register where the machine has it,
// the same bits again). A rejected sample adds +0.0 to its lane's kept sum, which changes no
// bit: that sum starts at +0.0 and so is never −0.0.
GYROD_ISA_CLONES
void meanFilterFullWindows(const double* x, std::size_t window, double threshold, double* out, std::size_t first,
                           std::size_t end) {
  // Elementwise IEEE operations on GCC/Clang vector types, no fused multiply-add: the bits of
  // the scalar code in every lane.
  constexpr std::size_t kLanes = 4;
  const auto n = static_cast<double>(window);
  const Doubles4 n4 = {n, n, n, n}, threshold4 = {threshold, threshold, threshold, threshold},
                 ones = {1.0, 1.0, 1.0, 1.0};
  const LaneMask4 no_sign = {INT64_MAX, INT64_MAX, INT64_MAX, INT64_MAX};
  std::size_t i = first;
  for (; i + kLanes <= end; i += kLanes) {
    const double* w = x + (i + 1 - window);  // lane k's window starts at w + k
    Doubles4 sum = {};
    for (std::size_t j = 0; j < window; ++j) {
      Doubles4 v;
      std::memcpy(&v, w + j, sizeof v);
      sum += v;
    }
    const Doubles4 m = sum / n4;
    Doubles4 kept_sum = {}, kept = {};
    for (std::size_t j = 0; j < window; ++j) {
      Doubles4 v;
      std::memcpy(&v, w + j, sizeof v);
      // keep: |v − m| ≤ r, all ones or zero; a kept v adds itself, a rejected one +0.0.
      const LaneMask4 keep = reinterpret_cast<Doubles4>(reinterpret_cast<LaneMask4>(v - m) & no_sign) <= threshold4;
      kept_sum += reinterpret_cast<Doubles4>(reinterpret_cast<LaneMask4>(v) & keep);
      kept += reinterpret_cast<Doubles4>(reinterpret_cast<LaneMask4>(ones) & keep);
    }
    const Doubles4 mean = kept_sum / kept;
    for (std::size_t k = 0; k < kLanes; ++k) out[i + k] = kept[k] == 0.0 ? m[k] : mean[k];
  }
  for (; i < end; ++i) {  // the last few, one at a time, the same operations
    const double* w = x + (i + 1 - window);
    double sum = 0.0;
    for (std::size_t j = 0; j < window; ++j) sum += w[j];
    const double m = sum / n;
    double kept_sum = 0.0, kept = 0.0;
    for (std::size_t j = 0; j < window; ++j)
      if (std::abs(w[j] - m) <= threshold) {
        kept_sum += w[j];
        kept += 1.0;
      }
    out[i] = kept == 0.0 ? m : kept_sum / kept;
  }
}

}  // namespace

// In contiguous shares on the cores: the first L − 1 outputs (the window filling) from the
// filter itself, the rest from full windows read in place.
std::vector<double> grossErrorMeanFiltered(std::span<const double> x, std::size_t window, double threshold) {
  std::vector<double> out(x.size());
  grossErrorMeanFilterInto(x, window, threshold, out);
  return out;
}

void grossErrorMeanFilterInto(std::span<const double> x, std::size_t window, double threshold, std::span<double> out) {
  if (out.size() != x.size())
    throw std::invalid_argument("the mean filter needs an output as long as its input (" + std::to_string(x.size()) +
                                " samples), got " + std::to_string(out.size()));
  GrossErrorMeanFilter filling(window, threshold);  // throws for bad parameters or samples here, not in a thread
  const std::size_t filled_from = std::min(x.size(), window - 1);
  for (std::size_t i = 0; i < filled_from; ++i) out[i] = filling.update(x[i]);
  for (double v : x.subspan(filled_from))
    if (!std::isfinite(v)) filling.update(v);  // throws, naming the value
  const std::size_t rest = x.size() - filled_from;
  forEachShare(
      rest,
      [&](std::size_t first, std::size_t end) {
        meanFilterFullWindows(x.data(), window, threshold, out.data(), filled_from + first, filled_from + end);
      },
      std::size_t{1} << 16);
}

AxisAnalysis analyzeAxis(std::span<const double> rate_dps, const AnalysisOptions& options) {
  return analyzeAxis(std::vector<double>(rate_dps.begin(), rate_dps.end()), options);
}

// The steps hold at most 20 bytes a sample: the series (8) and the Allan workspace (12),
// which holds the phase of each table and, between them, the mean-filter output (8 of its
// 12) that the Kalman filter then overwrites.
AxisAnalysis analyzeAxis(std::vector<double>&& rate_dps, const AnalysisOptions& options) {
  AllanWorkspace workspace(rate_dps.size());
  return analyzeAxis(std::move(rate_dps), options, workspace);
}

AxisAnalysis analyzeAxis(std::vector<double>&& rate_dps, const AnalysisOptions& options, AllanWorkspace& workspace) {
  if (rate_dps.size() > workspace.capacity())
    throw std::invalid_argument("the axis analysis needs a workspace for " + std::to_string(rate_dps.size()) +
                                " samples, this one holds " + std::to_string(workspace.capacity()));
  if (!(options.rate_hz > 0.0) || !std::isfinite(options.rate_hz))
    throw std::invalid_argument("the axis analysis needs a sample rate that is a positive number of Hz, got " +
                                std::to_string(options.rate_hz));
  const double tau0 = 1.0 / options.rate_hz;
  const auto step = [&](const char* name) {
    if (options.step_done) options.step_done(name);
  };
  AxisAnalysis a;
  a.samples = rate_dps.size();

  // 1. Tests on the raw series, before any preprocessing (paper §3.2.1); they only read it,
  // and so does the fit of the trend that step 2 removes: three tasks on the cores.
  std::optional<LinearTrend> trend;
  std::vector<std::function<void()>> tests = {[&] {
                                                a.zero_mean = zeroMeanTest(rate_dps);
                                                a.reverse_arrangements = reverseArrangementsTest(
                                                    rate_dps, options.reverse_arrangements_segments);
                                              },
                                              [&] { a.normality = chiSquareNormalityTest(rate_dps); }};
  if (options.detrend) tests.emplace_back([&] { trend = fitLinearTrend(rate_dps, tau0); });
  runTasksOnBothCores(std::span(tests));
  step("tests");

  // 2. Preprocessing (§3.2.2), in place: the raw series is not needed again. Each sample's
  // subtraction is its own: in shares on the cores, the same bits as removeLinearTrend.
  std::vector<double> x = std::move(rate_dps);
  if (trend) {
    a.trend_removed = *trend;
    forEachShare(
        x.size(),
        [&](std::size_t first, std::size_t end) {
          subtractLinearTrend(std::span(x).subspan(first, end - first), *trend, tau0, first);
        },
        std::size_t{1} << 16);
  }
  step("detrend");

  // 3. Allan deviation and noise terms (§3.2.3, Table 2). One workspace holds the phase of
  // both tables and, between them, the mean-filter and Kalman output: its pages are
  // allocated and cleared once (once for every axis, when the caller passes one).
  std::vector<std::size_t> ms = options.cluster_sizes.empty() ? octaveClusterSizes(x.size()) : options.cluster_sizes;
  a.allan = allanDeviationTable(x, tau0, ms, {}, workspace);
  a.noise = fitNoiseTerms(a.allan);
  a.noise_from_slopes = readNoiseTermsFromSlopes(a.allan);
  step("allan and fit");

  // 4–6. Mean filter, AR models of its output, Kalman on AR(1) (§4–5). The mean filter runs
  // once: its output identifies the Kalman and then feeds it, exactly as AxisFilterChain
  // (mean filter, then Kalman) would on the same series.
  const std::span<double> filtered = workspace.rateSlots().first(x.size());
  grossErrorMeanFilterInto(x, options.mean_window, options.mean_threshold_dps, filtered);
  step("mean filter");
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
  step("identification, AR, spreads");
  x = std::vector<double>();  // the series is not read again

  ScalarKalmanFilter kalman(a.filter.kalman);
  kalman.filterInPlace(filtered);
  const std::span<const double> kalman_filtered = filtered;
  step("kalman");

  // Table 4: the same Allan analysis on the Kalman output, its spread beside the table's noise
  // types (before the table turns the output into its phase where it lies).
  Spread after;
  a.allan_after_kalman = allanDeviationTableInPlace(workspace, kalman_filtered.size(), tau0, ms, {},
                                                    [&] { after = spreadAboutMean(kalman_filtered); });
  a.variance.kalman = after.variance;
  a.peak_ratio = peak_raw > 0.0 ? after.peak / peak_raw : 0.0;
  a.noise_after_kalman = fitNoiseTerms(a.allan_after_kalman);
  step("allan after kalman");
  return a;
}

}  // namespace gyrod::processing
