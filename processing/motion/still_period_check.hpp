#pragma once
// Did the board move during the start-up still period? gyrod estimates its bias (and
// identifies the paper's filter) from the first bias.still_seconds of samples, assuming the
// board is at rest; a rotation in that window would be absorbed into the bias unseen.
//
// No noise level is known at start, so the window is tested against itself: at rest its
// Allan variance at every τ = m·τ0 stays near what its own sample-to-sample noise predicts.
// Per axis, over the N samples of the window:
//   σ0² = Σ (y_{k+1} − y_k)² / (2(N − 1))             Allan variance at τ0, the noise level
//                                                     (a slow motion barely changes it)
//   A(m)  the overlapping Allan variance at m           (allan.hpp)
//   allowed(m) = c·σ0²/m · χ²_{1−α}(ν)/ν + f²          for m = 2, 4, … ≤ N/4
// with ν the edf of A(m) for white rate noise (overlappingAllanEdf, α = 0). For white noise
// A(m) ≈ σ0²/m. c = 8 allows the correlation the chip's low-pass filter puts between
// neighbouring samples (AR(1) noise with φ gives A(m)/(σ0²/m) → (1 + φ)/(1 − φ)², 6 at
// φ = 0.5); f = 0.01 °/s allows the bias instability of a real MPU6050 (its flat Allan
// deviation is a few 10⁻³ °/s).
// The chip's low-pass (DLPF) correlates the noise over about T_c = 0.614 / bandwidth (six
// time constants of each of the two first-order sections of the simulator's DLPF model,
// processing/simulation/sensor_model.hpp: the autocorrelation is below 2 % after it). When
// T_c spans m_c = ⌈T_c · rate⌉ > 1 samples (8 kHz at DLPF 0: 20; 1 kHz at DLPF 6: 123), σ0² is
// no longer the noise level (the differences of neighbouring samples cancel most of it) and the
// level is read at m_c instead: σ0² is replaced by m_c·A(m_c), and only m ≥ 2·m_c are tested.
// At 50 Hz with the default DLPF (42 Hz) m_c = 1: the formula above, unchanged.
// The window has "moved" when some axis has A(m) > allowed(m)
// at some m: a turn, a step, a sway or a vibration slower than the sample rate shows up at the
// τ of its time scale (a 1 °/s turn of 1 s in a 10 s window at 50 Hz, with the paper's ARW of
// 0.95 °/√h, comes out at 2.7 times the allowed deviation; tests/processing measures it).
//
// What it cannot see: a rotation that is constant over the whole window is indistinguishable
// from a bias (docs/motion.md); nor a vibration much faster than the sample rate (aliased
// into the noise level itself). Pure function; O(N log N).
#include <array>
#include <cstddef>
#include <span>

namespace gyrod::processing {

struct StillPeriodCheckParameters {
  double correlation_allowance = 8.0;  // c
  double floor_dps = 0.01;             // f, an Allan deviation [°/s]
  double false_alarm = 1e-6;           // α per axis and τ
  double low_pass_bandwidth_hz = 0.0;  // the chip's DLPF −3 dB bandwidth; 0: samples uncorrelated
};

// T_c above, in seconds (0 for a bandwidth ≤ 0: no low-pass).
double lowPassCorrelationSeconds(double bandwidth_hz);

struct StillPeriodVerdict {
  bool moved = false;
  // The worst case found (the largest √A/√allowed over axes and τ), moved or not.
  std::size_t axis = 0;
  double tau_s = 0.0;
  double adev_dps = 0.0;     // √A(m)
  double allowed_dps = 0.0;  // √allowed(m)
};

// Throws std::invalid_argument for rate ≤ 0 or axes of different lengths. Fewer than 8
// samples on an axis: nothing can be said (not moved).
StillPeriodVerdict checkStillPeriod(const std::array<std::span<const double>, 3>& axes, double rate_hz,
                                    const StillPeriodCheckParameters& parameters = {});

}  // namespace gyrod::processing
