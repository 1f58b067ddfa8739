#pragma once
// Is the sensor at rest? A windowed test, per axis, of the last W samples of c = raw − model
// bias against the white-noise level from the Allan fit; the sensor is still when all three
// axes pass. Two statistics per axis:
//   mean test        |c̄ − r̂| ≤ z·√(σm² + P)     c̄ the window mean, r̂ the residual bias the
//                   caller expects (RateEstimator's) and P its variance, σm² the Allan
//                   variance at τ = W·τ0 (for white rate noise exactly the variance of c̄);
//   difference test  D = Σ(c_k − c_{k−1})² / (2·σ0²) ≤ g·χ²_{1−αd}(h)   over the W − 1
//                   differences, σ0² the Allan variance at τ0 (E[(Δc)²] = 2σ0² for any
//                   stationary noise). For white noise D has mean W − 1 and variance about
//                   3(W − 1) (adjacent differences correlate by −½), matched by g·χ²(h)
//                   with g = 3/2, h = 2(W − 1)/3 (Satterthwaite).
// The mean test sees a constant rotation; the difference test sees anything that changes
// from sample to sample (vibration, a sine, the start of a turn) whatever its mean.
//
// Probabilities, per window (the sensor at rest, white Gaussian noise at the stated levels):
//   false moving, one axis      αm + αd − αm·αd,  αm = 2(1 − Φ(z))   (c̄ and D independent)
//   false moving, the sensor    1 − Π_axes (1 − αm)(1 − αd)
//   false still under a constant rotation ω on one axis (relative to r̂), others at rest:
//       P_fs(ω) = [Φ(z − ω/s) − Φ(−z − ω/s)]·(1 − αd)·((1 − αm)(1 − αd))²,  s = √(σm² + P)
// (falseStillProbability() computes it). The resolution, the ω with P_fs ≈ ½, is about z·s:
// 0.07 °/s for the paper's ARW (0.95 °/√h), W = 0.5 s, z = 3.
//
// What cannot be told apart: a rotation that is constant over the window and smaller than the
// resolution looks exactly like a bias change of the same size. No test on the gyro alone
// separates them; the detector passes such windows, and the residual filter (RateEstimator)
// then learns the rotation as bias at the speed its process noise allows.
//
// The accelerometer splits them for any rotation that tilts the board (changes the direction
// of gravity in the chip's axes; a turn about the vertical does not). When observeAccel() is
// fed finite values, a window is still only if, in addition, the last Wa accel samples are
// steady on every axis (σa the accel's white noise per sample, g):
//   slope test       |β̂| ≤ z·σa/√S,  β̂ the least-squares slope of a over the Wa samples (g per
//                   sample), S = Σ(k − k̄)² = Wa(Wa² − 1)/12 (β̂'s std for white noise is σa/√S);
//   difference test  Σ(a_k − a_{k−1})²/(2σa²) ≤ g·χ²_{1−αd}(h), as for the gyro with Wa.
// A tilt at ω rad/s moves a horizontal axis by about ω/rate g per sample; over Wa = 250
// samples at 50 Hz and σa = 3 mg the slope test resolves z·σa·rate/√S ≈ 0.4 mg/s, i.e. tilts
// of 0.02 °/s, well below the gyro's 0.07 °/s. The mean of a is not tested: a board at rest
// in any attitude is still. Without accel (nothing fed, or NaN) the verdict is the gyro's
// alone, exactly as before. Per window at rest the accel adds a false-moving probability of
// 1 − ((1 − αm)(1 − αd))³ for white accel noise at σa.
//
// Storage: a ring of W samples per axis, sized at construction; update() allocates nothing.
// Running sums are recomputed from the ring once per W samples, so rounding does not pile up.
#include <array>
#include <cstddef>
#include <vector>

#include "processing/base/noise_terms.hpp"
#include "processing/simulation/motion_profile.hpp"

namespace gyrod::processing {

struct StillDetectorParameters {
  std::size_t window_samples = 25;       // W (0.5 s at 50 Hz); ≥ 3
  double mean_threshold_sigmas = 3.0;    // z
  double difference_false_alarm = 1e-3;  // αd, per axis and window at rest
  // The accelerometer's part (used only when accel is fed): Wa and σa of the header.
  std::size_t accel_window_samples = 250;  // Wa (5 s at 50 Hz); ≥ 3
  double accel_noise_g = 0.003;            // σa, white noise per sample and axis, g
};

// The noise level of one axis at rest.
struct StillNoiseLevel {
  double window_allan_variance = 0.0;  // σm²: Allan variance at τ = W·τ0, (°/s)²
  double sample_allan_variance = 0.0;  // σ0²: Allan variance at τ0, (°/s)²
};
// The levels of an Allan fit: σ² of the five terms (allanVarianceOfTerms) at W/rate and 1/rate.
StillNoiseLevel stillNoiseLevelFromTerms(const NoiseTerms& terms, double rate_hz, std::size_t window_samples);

class StillDetector {
 public:
  // Throws std::invalid_argument naming the parameter for W < 3, z ≤ 0, αd outside (0, 1),
  // or a level that is not finite and > 0.
  StillDetector(const StillDetectorParameters& params, const std::array<StillNoiseLevel, kMotionAxes>& levels);

  // One sample of c = raw − model bias; `expected` is r̂ per axis and `expected_variance` P.
  // Returns whether the window ending here passes on every axis (false until W samples).
  bool update(const AngularRate& corrected, const AngularRate& expected, const AngularRate& expected_variance);
  // The same sample's accel (x, y, z in g), before update(). Any NaN means "no accel": the
  // accel window empties and the verdict is the gyro's alone until finite values come again.
  void observeAccel(const std::array<double, kMotionAxes>& accel_g);
  // Whether the last update() required the accel (and its window was full and steady).
  bool usingAccel() const { return accel_present_; }
  bool accelSteady() const;

  bool still() const { return still_; }
  // Consecutive samples whose window passed (0 when the last one did not).
  std::size_t stillRun() const { return still_run_; }
  double windowMean(std::size_t axis) const;
  std::size_t windowSamples() const { return params_.window_samples; }
  double windowVariance(std::size_t axis) const { return levels_[axis].window_allan_variance; }
  double differenceThreshold() const { return difference_threshold_; }  // on D
  void reset();

  // The probabilities of the header comment, for these parameters.
  double falseMovingProbabilityPerAxis() const;
  double falseMovingProbability() const;
  double falseStillProbability(std::size_t axis, double offset_dps, double expected_variance = 0.0) const;

 private:
  StillDetectorParameters params_;
  std::array<StillNoiseLevel, kMotionAxes> levels_;
  double difference_threshold_ = 0.0;
  std::vector<double> ring_;  // W samples per axis, axis-major: ring_[axis·W + slot]
  std::size_t next_slot_ = 0, filled_ = 0;
  std::array<double, kMotionAxes> sum_{}, diff_sq_sum_{}, last_{};
  std::size_t still_run_ = 0;
  bool still_ = false;
  void recomputeSums();
  // Accel ring: Wa samples per axis, axis-major like ring_.
  std::vector<double> accel_ring_;
  std::size_t accel_next_ = 0, accel_filled_ = 0;
  bool accel_present_ = false;
  double accel_difference_threshold_ = 0.0;
  double accel_slope_bound_ = 0.0;  // z·σa/√S
};

}  // namespace gyrod::processing
