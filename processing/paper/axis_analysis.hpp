#pragma once
// The paper's whole analysis of one static axis, in its order (Xiong et al. §3–5):
// tests on the raw series → remove constant and trend → Allan deviation and noise
// terms (Table 2) → mean filter → AR(1..p) by Yule–Walker with AIC (Table 3) →
// Kalman on AR(1) → variances and peak ratio → noise terms after Kalman (Table 4).
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/allan/noise_fit.hpp"
#include "processing/base/detrend.hpp"
#include "processing/paper/ar_model.hpp"
#include "processing/paper/filter_chain.hpp"
#include "processing/paper/mean_filter.hpp"
#include "processing/paper/statistics_tests.hpp"

namespace gyrod::processing {

struct AnalysisOptions {
  double rate_hz = 50.0;
  bool detrend = true;                     // remove constant + linear trend first (paper)
  std::vector<std::size_t> cluster_sizes;  // m values; empty → octave
  std::size_t mean_window = 20;
  double mean_threshold_dps = 0.3;
  std::size_t max_ar_order = 3;
  std::size_t reverse_arrangements_segments = 100;
  KalmanOverrides kalman_overrides;
  // Called with the name of each step as it ends ("tests", "allan", ...): for timing the
  // steps (gyroctl analyze, GYROD_ANALYZE_TIMING); empty, nothing is called.
  std::function<void(const char*)> step_done;
};

struct VarianceComparison {
  double raw = 0.0, mean = 0.0, kalman = 0.0;  // (°/s)²
};

struct AxisAnalysis {
  std::size_t samples = 0;
  ZeroMeanTest zero_mean;
  ReverseArrangementsTest reverse_arrangements;
  ChiSquareNormalityTest normality;
  LinearTrend trend_removed;  // zero when detrend is off
  std::vector<AllanPoint> allan;
  NoiseTermFit noise;            // weighted fit (Table 2)
  NoiseTerms noise_from_slopes;  // classical slope reading, cross-check
  std::vector<ArModel> ar;       // orders 1..max_ar_order (Table 3)
  std::size_t ar_order_aic = 0, ar_order_bic = 0;
  FilterChainParameters filter;  // what the Kalman used
  double steady_state_gain = 0.0;
  VarianceComparison variance;
  double peak_ratio = 0.0;  // max|kalman − mean| / max|raw − mean|
  std::vector<AllanPoint> allan_after_kalman;
  NoiseTermFit noise_after_kalman;  // Table 4
};

AxisAnalysis analyzeAxis(std::span<const double> rate_dps, const AnalysisOptions& options);
// The same, consuming the series (it becomes the detrended working copy): peak memory of
// 20 bytes a sample (the series and the Allan workspace, which also holds the filter outputs).
AxisAnalysis analyzeAxis(std::vector<double>&& rate_dps, const AnalysisOptions& options);
// The same in a workspace the caller keeps (capacity ≥ the series; its contents are
// overwritten): several axes analysed in turn then share one, whose pages the kernel
// clears once. The same results, bit for bit.
AxisAnalysis analyzeAxis(std::vector<double>&& rate_dps, const AnalysisOptions& options, AllanWorkspace& workspace);

// GrossErrorMeanFilter(window, threshold) run over x from its start: its outputs, the same
// bits, computed on the cores and several windows at a time. Throws as the filter does.
std::vector<double> grossErrorMeanFiltered(std::span<const double> x, std::size_t window, double threshold);
// The same into `out` (as long as x; not overlapping it).
void grossErrorMeanFilterInto(std::span<const double> x, std::size_t window, double threshold, std::span<double> out);

// Population variance about the mean, and max |x − mean|.
double varianceAboutMean(std::span<const double> x);
double peakDeviationFromMean(std::span<const double> x);

}  // namespace gyrod::processing
