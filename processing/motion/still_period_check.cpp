#include "processing/motion/still_period_check.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
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

// The chip's noise after two identical first-order sections with the cascade −3 dB at the
// bandwidth: each section's corner is bandwidth / √(√2 − 1), and six of its time constants
// 6 / (2π · 1.554 · bandwidth) = 0.614 / bandwidth.
constexpr double kCorrelationTimeConstants = 6.0;

}  // namespace

double lowPassCorrelationSeconds(double bandwidth_hz) {
  if (!(bandwidth_hz > 0.0)) return 0.0;
  const double section_corner_hz = bandwidth_hz / std::sqrt(std::sqrt(2.0) - 1.0);
  return kCorrelationTimeConstants / (2.0 * std::numbers::pi * section_corner_hz);
}

StillPeriodVerdict checkStillPeriod(const std::array<std::span<const double>, 3>& axes, double rate_hz,
                                    const StillPeriodCheckParameters& p) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) throw std::invalid_argument("still period check: rate must be > 0");
  if (axes[1].size() != axes[0].size() || axes[2].size() != axes[0].size())
    throw std::invalid_argument("still period check: the axes have different lengths");
  StillPeriodVerdict worst;
  double worst_ratio = -1.0;
  const std::size_t n = axes[0].size();
  if (n < kMinSamples) return worst;
  // The noise level's cluster size m_c, and the tested m: powers of two from 2·m_c.
  const auto m_c = static_cast<std::size_t>(
      std::max(1.0, std::ceil(lowPassCorrelationSeconds(p.low_pass_bandwidth_hz) * rate_hz - 1e-9)));
  std::vector<std::size_t> ms;
  std::size_t first = 2;
  while (first < 2 * m_c) first *= 2;
  for (std::size_t m = first; kMinClustersAcross * m <= n; m *= 2) ms.push_back(m);
  if (ms.empty()) return worst;  // a window too short to see past the low-pass
  for (std::size_t axis = 0; axis < axes.size(); ++axis) {
    const double sigma0_squared =
        m_c == 1 ? sampleAllanVariance(axes[axis])
                 : static_cast<double>(m_c) * overlappingAllanVariances(axes[axis], std::vector<std::size_t>{m_c})[0];
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
