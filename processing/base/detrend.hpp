#pragma once
// Preprocessing (paper §3.2.2): remove the constant and the least-squares linear trend.
#include <cstddef>
#include <span>

namespace gyrod::processing {

struct LinearTrend {
  double offset = 0.0;       // value at the first sample
  double slope_per_s = 0.0;  // unit per second
};

// Least-squares line x ≈ offset + slope·(i·dt). Numerically stable (centred) form.
// Throws std::invalid_argument for fewer than 2 samples or dt_s ≤ 0 / non-finite.
LinearTrend fitLinearTrend(std::span<const double> x, double dt_s);
// In place: x[i] −= mean. Returns the mean. Throws for an empty span.
double removeConstant(std::span<double> x);
// In place: x[i] −= offset + slope·i·dt. Returns the trend removed. Throws as fitLinearTrend.
LinearTrend removeLinearTrend(std::span<double> x, double dt_s);
// In place, a trend fitted before: x[k] −= offset + slope·(i·dt) with i = first_index + k,
// the operations of removeLinearTrend (so that shares of a series give its bits).
void subtractLinearTrend(std::span<double> x, const LinearTrend& trend, double dt_s, std::size_t first_index = 0);

}  // namespace gyrod::processing
