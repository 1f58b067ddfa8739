#pragma once
// The bias against temperature of one axis of a still recording (the calibration's part that
// the rate stream needs, issue 11): weighted least squares on block means of
//   rate = bias + k·(T − T_ref) [+ A·e^{−t/τ}]
// T_ref is the weighted mean of the block temperatures, so the errors of bias and k are
// uncorrelated. The blocks (block_s long, 10 s by default) average out the white noise; what
// remains in the block residuals is correlated (flicker, rate random walk), so the standard
// errors are the ordinary ones scaled by (1 + ρ)/(1 − ρ), ρ the lag-1 correlation of the
// residuals (clamped to [0, 0.95]): an effective number of independent blocks.
// The warm-up shape A·e^{−t/τ} (a bias transient beyond what the temperature explains): τ
// minimises the joint fit's residual (log-spaced scan from duration/100 to duration/3, so the
// transient settles within the record and cannot stand in for a slow drift, then golden section,
// as fitExponentialWarmUp finds the temperature's τ); searched only on a record whose temperature
// moves (a warm-up), and kept only when |A| > 5 standard errors (τ was searched, hence more than 3). When
// τ is close to the temperature's own time constant, e^{−t/τ} and T are nearly collinear, A's
// standard error is large, and the shape is rightly dropped: the record cannot tell them apart.
// A temperature spread (std of the block means) below 0.1 °C fits no coefficient (k = 0 and
// its σ = 0): a record at one temperature says nothing about k.
#include <cstddef>
#include <span>

namespace gyrod::processing {

struct TemperatureBiasFit {
  double bias_dps = 0.0;  // at reference_c, after the warm-up shape
  double bias_std_dps = 0.0;
  double coefficient_dps_per_c = 0.0;
  double coefficient_std_dps_per_c = 0.0;
  double reference_c = 25.0;
  double warm_up_amplitude_dps = 0.0;  // 0: no significant shape
  double warm_up_amplitude_std_dps = 0.0;
  double warm_up_time_constant_s = 0.0;
  double temperature_spread_c = 0.0;  // weighted std of the block temperatures
  std::size_t blocks = 0;
  double residual_correlation = 0.0;  // ρ above, after clamping
  bool coefficientFitted() const { return coefficient_std_dps_per_c > 0.0; }
};

inline constexpr double kTemperatureBiasBlockSeconds = 10.0;
inline constexpr double kMinimumTemperatureSpreadC = 0.1;
inline constexpr double kWarmUpShapeSignificance = 5.0;  // standard errors

// `secs` from any origin (the shape's t counts from the first sample), `rate_dps` and
// `temp_c` of the same length. Throws std::invalid_argument for different lengths, a value
// that is not finite, times that decrease, or fewer than 8 blocks.
TemperatureBiasFit fitTemperatureBias(std::span<const double> secs, std::span<const double> rate_dps,
                                      std::span<const double> temp_c, double block_s = kTemperatureBiasBlockSeconds);

}  // namespace gyrod::processing
