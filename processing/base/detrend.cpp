#include "processing/base/detrend.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gyrod::processing {

LinearTrend fitLinearTrend(std::span<const double> x, double dt_s) {
  if (x.size() < 2)
    throw std::invalid_argument("the linear trend fit needs at least 2 samples, got " + std::to_string(x.size()));
  if (!(dt_s > 0.0) || !std::isfinite(dt_s))
    throw std::invalid_argument("the linear trend fit needs a sample interval that is positive and finite, got " +
                                std::to_string(dt_s));
  // Centred normal equations: with t̄ = (n−1)/2 (in samples) and x̄ the means,
  // slope = Σ(i − t̄)(x_i − x̄) / Σ(i − t̄)², which avoids the cancellation of the raw
  // Σi², Σi·x_i form on long records. Σ(i − t̄)² = n(n²−1)/12 exactly.
  const double n = static_cast<double>(x.size());
  const double t_mean = (n - 1.0) / 2.0;
  double x_mean = 0.0;
  for (double v : x) x_mean += v;
  x_mean /= n;
  double sxy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) sxy += (static_cast<double>(i) - t_mean) * (x[i] - x_mean);
  const double stt = n * (n * n - 1.0) / 12.0;
  const double slope_per_sample = sxy / stt;
  LinearTrend t;
  t.offset = x_mean - slope_per_sample * t_mean;
  t.slope_per_s = slope_per_sample / dt_s;
  return t;
}

double removeConstant(std::span<double> x) {
  if (x.empty()) throw std::invalid_argument("removing the mean needs at least one sample; the series is empty");
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  for (double& v : x) v -= mean;
  return mean;
}

LinearTrend removeLinearTrend(std::span<double> x, double dt_s) {
  const LinearTrend t = fitLinearTrend(x, dt_s);
  subtractLinearTrend(x, t, dt_s);
  return t;
}

void subtractLinearTrend(std::span<double> x, const LinearTrend& trend, double dt_s, std::size_t first_index) {
  for (std::size_t k = 0; k < x.size(); ++k)
    x[k] -= trend.offset + trend.slope_per_s * (static_cast<double>(first_index + k) * dt_s);
}

}  // namespace gyrod::processing
