#pragma once
// The per-sample chain that gyrod runs on each axis and `gyroctl filter` runs offline:
// mean filter with gross-error rejection → scalar Kalman on the AR(1) drift model.
// One object per axis; update() allocates nothing.
#include <cstddef>
#include <optional>
#include <span>

#include "processing/paper/kalman.hpp"
#include "processing/paper/mean_filter.hpp"

namespace gyrod::processing {

struct FilterChainParameters {
  std::size_t mean_window = 20;     // L (paper: 20)
  double mean_threshold_dps = 0.3;  // r (paper: 0.3 °/s)
  ScalarKalmanParameters kalman;    // A, Q, R (P0 = 0, x̂0 = first mean-filter output)
};

struct FilteredRate {
  double mean_dps = 0.0;
  double kalman_dps = 0.0;
};

class AxisFilterChain {
 public:
  explicit AxisFilterChain(const FilterChainParameters& p);
  FilteredRate update(double rate_dps);
  void reset();
  const FilterChainParameters& parameters() const { return params_; }
  const GrossErrorMeanFilter& meanFilter() const { return mean_; }
  const ScalarKalmanFilter& kalman() const { return kalman_; }

 private:
  FilterChainParameters params_;
  GrossErrorMeanFilter mean_;
  ScalarKalmanFilter kalman_;
};

// Which Kalman parameters to take from the caller instead of identifying them.
struct KalmanOverrides {
  std::optional<double> a, q, r;
};

// Identifies A, Q, R from a (preprocessed) series as the paper does: mean-filter it,
// fit AR(1) by Yule–Walker (A = φ1, Q = σa²), R = var(x − mean-filtered x); then
// applies the overrides (when all three are given, nothing is identified and the series
// may be anything). Throws std::invalid_argument when the series is too short.
FilterChainParameters identifyFilterChain(std::span<const double> rate_dps, std::size_t mean_window,
                                          double mean_threshold_dps, const KalmanOverrides& overrides = {});
// The same from a series and its mean-filter output (GrossErrorMeanFilter(mean_window,
// mean_threshold_dps) run over it), for a caller that keeps that output anyway.
FilterChainParameters identifyFilterChainFromMeanFiltered(std::span<const double> rate_dps,
                                                          std::span<const double> mean_filtered,
                                                          std::size_t mean_window, double mean_threshold_dps,
                                                          const KalmanOverrides& overrides = {});

}  // namespace gyrod::processing
