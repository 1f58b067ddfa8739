#pragma once
// A narrowband line: a rate component whose frequency wanders about a centre, as the
// residues of a MEMS gyro's drive and sense loops do (seen on real MPU6050 records as lines
// 0.1–0.5 Hz wide near 16, 20 and 31 Hz). Modelled as a noise-driven second-order resonance
// at the output rate,
//     x_k = a1·x_{k−1} + a2·x_{k−2} + e_k,   a1 = 2r·cos(2π·f0/rate), a2 = −r², e ~ N(0, σe²),
// with r = exp(−π·width/rate): its power spectral density peaks at the centre f0 with a
// half-power full width of `width` (for width ≪ rate), and σe² makes its stationary standard
// deviation `rms`. A fixed sinusoid is its limit width → 0. The simulator
// (noise_simulator.hpp, AxisExtraEffects::narrowband_lines) and the model check
// (processing/model_check, which fits centre, width and rms) share this definition.
#include <cstddef>

namespace gyrod::processing {

struct NarrowbandLine {
  double centre_hz = 0.0;  // > 0 and < rate/2
  double width_hz = 0.0;   // > 0: half-power full width of the spectral peak
  double rms_dps = 0.0;    // ≥ 0: stationary standard deviation
  bool operator==(const NarrowbandLine&) const = default;
};

// The AR(2) form of a line at an output rate.
struct NarrowbandLineRecursion {
  double a1 = 0.0, a2 = 0.0;
  double drive_var = 0.0;  // σe²
};
// Throws std::invalid_argument unless 0 < centre < rate/2, width > 0 and rms ≥ 0 are finite.
NarrowbandLineRecursion narrowbandLineRecursion(const NarrowbandLine& line, double rate_hz);

// Stationary variance of x_k = a1·x_{k−1} + a2·x_{k−2} + e_k per unit σe²:
// (1 − a2) / ((1 + a2)·((1 − a2)² − a1²)).
double ar2StationaryVariancePerDrive(double a1, double a2);

// One-sided power spectral density [(°/s)²/Hz] of the line at frequency f (0 ≤ f ≤ rate/2):
// 2·σe²/rate / |1 − a1·e^{−iω} − a2·e^{−2iω}|², ω = 2π·f/rate.
double narrowbandLinePsd(const NarrowbandLineRecursion& line, double rate_hz, double freq_hz);

}  // namespace gyrod::processing
