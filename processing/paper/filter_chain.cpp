#include "processing/paper/filter_chain.hpp"

#include <vector>

namespace gyrod::processing {

AxisFilterChain::AxisFilterChain(const FilterChainParameters& p)
    : params_(p), mean_(p.mean_window, p.mean_threshold_dps), kalman_(p.kalman) {}

FilteredRate AxisFilterChain::update(double rate_dps) {
  FilteredRate out;
  out.mean_dps = mean_.update(rate_dps);
  out.kalman_dps = kalman_.update(out.mean_dps);
  return out;
}

void AxisFilterChain::reset() {
  mean_.reset();
  kalman_.reset();
}

FilterChainParameters identifyFilterChain(std::span<const double> rate_dps, std::size_t mean_window,
                                          double mean_threshold_dps, const KalmanOverrides& overrides) {
  GrossErrorMeanFilter mean(mean_window, mean_threshold_dps);
  if (overrides.a && overrides.q && overrides.r)
    return identifyFilterChainFromMeanFiltered({}, {}, mean_window, mean_threshold_dps, overrides);
  std::vector<double> filtered(rate_dps.size());
  for (std::size_t i = 0; i < rate_dps.size(); ++i) filtered[i] = mean.update(rate_dps[i]);
  return identifyFilterChainFromMeanFiltered(rate_dps, filtered, mean_window, mean_threshold_dps, overrides);
}

FilterChainParameters identifyFilterChainFromMeanFiltered(std::span<const double> rate_dps,
                                                          std::span<const double> mean_filtered,
                                                          std::size_t mean_window, double mean_threshold_dps,
                                                          const KalmanOverrides& overrides) {
  FilterChainParameters p;
  p.mean_window = mean_window;
  p.mean_threshold_dps = mean_threshold_dps;
  if (overrides.a && overrides.q && overrides.r) {  // nothing to identify
    p.kalman = {*overrides.a, *overrides.q, *overrides.r, 0.0, {}};
    ScalarKalmanFilter validate(p.kalman);
    return p;
  }
  p.kalman = identifyKalmanParameters(rate_dps, mean_filtered).params;
  if (overrides.a) p.kalman.a = *overrides.a;
  if (overrides.q) p.kalman.q = *overrides.q;
  if (overrides.r) p.kalman.r = *overrides.r;
  return p;
}

}  // namespace gyrod::processing
