#include "processing/motion/still_period_check.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/base/distributions.hpp"

namespace gyrod::processing {
namespace {

// τ up to a quarter of the window: the overlapping estimator keeps N − 2m + 1 ≥ N/2 terms.
constexpr std::size_t kMinClustersAcross = 4;
constexpr std::size_t kMinSamples = 8;

double sampleAllanVariance(std::span<const double> y) {
  long double sum = 0.0L;
  for (std::size_t k = 1; k < y.size(); ++k) {
    const long double d = static_cast<long double>(y[k]) - y[k - 1];
    sum += d * d;
  }
  return static_cast<double>(sum / (2.0L * static_cast<long double>(y.size() - 1)));
}

}  // namespace

StillPeriodVerdict checkStillPeriod(const std::array<std::span<const double>, 3>& axes, double rate_hz,
                                    const StillPeriodCheckParameters& p) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) throw std::invalid_argument("still period check: rate must be > 0");
  if (axes[1].size() != axes[0].size() || axes[2].size() != axes[0].size())
    throw std::invalid_argument("still period check: the axes have different lengths");
  StillPeriodVerdict worst;
  double worst_ratio = -1.0;
  const std::size_t n = axes[0].size();
  if (n < kMinSamples) return worst;
  std::vector<std::size_t> ms;
  for (std::size_t m = 2; kMinClustersAcross * m <= n; m *= 2) ms.push_back(m);
  for (std::size_t axis = 0; axis < axes.size(); ++axis) {
    const double sigma0_squared = sampleAllanVariance(axes[axis]);
    const std::vector<double> variances = overlappingAllanVariances(axes[axis], ms);
    for (std::size_t i = 0; i < ms.size(); ++i) {
      const std::size_t m = ms[i];
      const double edf = overlappingAllanEdf(0, n + 1, m);  // white rate noise
      const double allowed = p.correlation_allowance * sigma0_squared / static_cast<double>(m) *
                                 chiSquareQuantile(1.0 - p.false_alarm, edf) / edf +
                             p.floor_dps * p.floor_dps;
      const double ratio = variances[i] / allowed;
      if (ratio > worst_ratio) {
        worst_ratio = ratio;
        worst = {ratio > 1.0, axis, static_cast<double>(m) / rate_hz, std::sqrt(variances[i]), std::sqrt(allowed)};
      }
    }
  }
  return worst;
}

}  // namespace gyrod::processing
