// Least-squares exponential warm-up curve; see warm_up_fit.hpp.
#include "processing/motion/warm_up_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "processing/base/golden_section.hpp"

namespace gyrod::processing {

TemperatureModel fitExponentialWarmUp(std::span<const double> secs, std::span<const double> temp) {
  if (secs.size() != temp.size() || temp.size() < 2)
    throw std::invalid_argument("the warm-up fit needs at least 2 samples with a time each, got " +
                                std::to_string(temp.size()) + " temperatures and " + std::to_string(secs.size()) +
                                " times");
  for (std::size_t i = 0; i < temp.size(); ++i)
    if (!std::isfinite(temp[i]) || !std::isfinite(secs[i]))
      throw std::invalid_argument("the warm-up fit cannot use sample " + std::to_string(i) + ": it is not finite");
  TemperatureModel m;
  const std::size_t n = temp.size();
  long double sum = 0.0L;
  for (double v : temp) sum += v;
  const double mean = static_cast<double>(sum / static_cast<long double>(n));
  double ss = 0.0, d2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) ss += (temp[i] - mean) * (temp[i] - mean);
  for (std::size_t i = 1; i < n; ++i) d2 += (temp[i] - temp[i - 1]) * (temp[i] - temp[i - 1]);
  m.noise_std_c = n > 1 ? std::sqrt(d2 / (2.0 * static_cast<double>(n - 1))) : 0.0;
  m.start_c = m.final_c = mean;
  const double duration = secs.back() - secs.front();
  if (ss == 0.0 || !(duration > 0.0)) return m;
  m.time_constant_s = duration;
  struct Fit {
    double sse = std::numeric_limits<double>::infinity(), final_c = 0.0, delta_c = 0.0;
  };
  std::vector<double> decay(n);
  const auto fitAt = [&](double log_tau) {
    const double tau = std::exp(log_tau);
    double se = 0.0, see = 0.0, sy = 0.0, sey = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double e = decay[i] = std::exp(-secs[i] / tau);
      se += e;
      see += e * e;
      sy += temp[i] - mean;  // centred for conditioning
      sey += e * (temp[i] - mean);
    }
    const double nn = static_cast<double>(n), det = nn * see - se * se;
    Fit f;
    if (!(det > 1e-12 * nn * see)) return f;  // e^{−t/T} nearly constant: no information
    f.delta_c = (nn * sey - se * sy) / det;
    const double c0 = (sy - f.delta_c * se) / nn;
    f.final_c = mean + c0;
    double sse = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double r = temp[i] - mean - c0 - f.delta_c * decay[i];
      sse += r * r;
    }
    f.sse = sse;
    return f;
  };
  const double lo = std::log(duration / 100.0), hi = std::log(10.0 * duration);
  constexpr int kScan = 31;
  int best = 0;
  double best_sse = std::numeric_limits<double>::infinity();
  for (int j = 0; j < kScan; ++j) {
    const double s = fitAt(lo + (hi - lo) * j / (kScan - 1)).sse;
    if (s < best_sse) {
      best_sse = s;
      best = j;
    }
  }
  if (!std::isfinite(best_sse)) return m;
  const double step = (hi - lo) / (kScan - 1);
  // The time constant: golden section in log τ within one scan step of the best.
  const double a = lo + step * std::max(best - 1, 0), b = lo + step * std::min(best + 1, kScan - 1);
  const double log_tau =
      goldenSectionMinimum(a, b, {30, 0.0}, [&](double log_tau_tried) { return fitAt(log_tau_tried).sse; }).midpoint();
  const Fit f = fitAt(log_tau);
  if (!std::isfinite(f.sse)) return m;
  m.time_constant_s = std::exp(log_tau);
  m.final_c = f.final_c;
  m.start_c = f.final_c + f.delta_c;
  return m;
}

}  // namespace gyrod::processing
