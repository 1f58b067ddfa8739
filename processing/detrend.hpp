#pragma once
// Preprocessing (paper §3.2.2): remove the constant and the least-squares linear trend.
#include <span>

namespace gyrod::processing {

struct LinearTrend {
  double offset = 0.0;        // value at the first sample
  double slope_per_s = 0.0;   // unit per second
};

// Least-squares line x ≈ offset + slope·(i·dt). Numerically stable (centred) form.
LinearTrend fitLinearTrend(std::span<const double> x, double dt_s);
// In place: x[i] −= mean. Returns the mean.
double removeConstant(std::span<double> x);
// In place: x[i] −= offset + slope·i·dt. Returns the trend removed.
LinearTrend removeLinearTrend(std::span<double> x, double dt_s);

}  // namespace gyrod::processing
