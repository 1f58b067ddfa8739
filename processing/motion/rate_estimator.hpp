#pragma once
// The `rate` stream: the rotation rate of a gyro that moves and warms up (issue 11),
//   rate = raw − b̂(t), then an optional low-pass (off by default, so no delay),
//   b̂(t) = model bias at the current temperature (+ warm-up shape) + residual r̂,
// r̂ tracked per axis by a small Kalman filter, updated only by samples whose window the
// StillDetector passes. Unlike the paper's AR(1) filter (a low-pass of DC gain ≈ 0.45,
// docs/motion.md), nothing here acts on the motion itself: a rotation goes through with gain 1
// and no delay beyond the chip's DLPF.
//
// The residual filter, per axis (τ0 = 1/rate, W the detector's window), state [offset, slope]
// with r̂ = offset + slope·(T − T_start):
//   offset  a random walk of intensity (per second) q = K² + 2·cB/T_B + R²·T_B, from the Allan
//       fit: K² = 3·c_K (rate random walk), cB = (0.6643·B)² the flicker floor turned into a
//       random walk that moves by √(2cB) (the Allan deviation's definition) in the horizon
//       T_B, and the ramp R moving by R·T_B in T_B; starts at 0 ± the model's bias_std_dps;
//   slope   the error of the model's temperature coefficient: a constant, 0 ± its 1σ (σk), so
//       still periods at different temperatures correct k itself, not only the bias;
//   measurement  each still sample's c = raw − model bias, variance W·σm² (σm² = the Allan
//       variance at W·τ0: at the low frequencies the residual follows, W such samples are
//       worth one window mean of variance σm²).
// Updating with the current sample before subtracting keeps the correction a first-order
// smoother of the data itself, whose complement |1 − H(f)| ≤ 1 at every f: while the sensor stays
// at rest, the rate's expected Allan variance cannot exceed raw's at any τ (a correction that
// lags by a window would raise it by about its gain at τ of a few windows).
// A constant rotation ω below the detector's resolution passes as still and is learned as
// bias: after n samples the fraction 1 − Π(1 − K_i) of ω, with K_i the filter's gains
// (K ≈ √(q·τ0/(W·σm²)) per sample in steady state: 2·10⁻⁵ for the paper's Table 2 terms and
// T_B = 100 s, a time constant τ0/K of about 17 min; 2·10⁻⁴ and 90 s with the terms a 1 h
// still record's Allan fit gives, docs/motion.md). Faster than that it cannot learn, whatever
// the data: the process noise is the model's, not a tuning knob. A rotation above the
// resolution is refused by the gate (the detector's mean test is the innovation test
// |c̄ − r̂| ≤ z·√(σm² + var r̂)) until var r̂ has grown, at the rate q, to let it in.
//
// update() allocates nothing; storage (the detector's ring) is sized at construction.
#include <array>
#include <cstddef>
#include <limits>
#include <optional>

#include "processing/base/noise_terms.hpp"
#include "processing/motion/still_detector.hpp"
#include "processing/simulation/motion_profile.hpp"

namespace gyrod::processing {

// The calibration of one axis (the sensor model file's per-axis part).
struct AxisBiasModel {
  double bias_dps = 0.0;  // at temperature_reference_c, after the warm-up
  double temperature_coefficient_dps_per_c = 0.0;
  double temperature_reference_c = 25.0;
  // Warm-up shape beyond the temperature: + amplitude·e^{−t/τ}, t from the first sample
  // (0 amplitude = none).
  double warm_up_amplitude_dps = 0.0;
  double warm_up_time_constant_s = 0.0;
  double bias_std_dps = 0.0;                           // 1σ of bias_dps: the residual's starting uncertainty
  double temperature_coefficient_std_dps_per_c = 0.0;  // 1σ of the coefficient
  NoiseTerms terms;                                    // the Allan fit (paper units)

  double biasAt(double temperature_c, double since_start_s) const;
};

struct RateEstimatorParameters {
  double rate_hz = 50.0;
  std::array<AxisBiasModel, kMotionAxes> axes;
  StillDetectorParameters still;
  double bias_instability_horizon_s = 100.0;  // T_B above
  double temperature_smoothing_s = 1.0;       // time constant of the temperature's EMA; 0 = none
  std::optional<double> low_pass_hz;          // −3 dB of a first-order low-pass on rate; none = off
};
// Throws std::invalid_argument naming the parameter (and axis) for a bad value.
void validateRateEstimatorParameters(const RateEstimatorParameters& p);

// What the residual filter has learned (per axis r̂ = offset + slope·(T − temperature_origin_c)
// and the covariance of [offset, slope]), so that a restart begins from it rather than from the
// model's prior (docs/calibration-state.md). Plain numbers: the state file carries them.
struct LearnedResidualAxis {
  double offset_dps = 0.0;
  double slope_dps_per_c = 0.0;
  double var_offset = 0.0, cov_offset_slope = 0.0, var_slope = 0.0;
  bool operator==(const LearnedResidualAxis&) const = default;
};
struct LearnedResidual {
  std::array<LearnedResidualAxis, kMotionAxes> axes{};
  double temperature_origin_c = 0.0;  // where offset is the residual
  double temperature_c = 0.0;         // the smoothed temperature when it was taken
  // The temperatures of the still samples that taught it (NaN, NaN: none yet).
  double still_temperature_min_c = std::numeric_limits<double>::quiet_NaN();
  double still_temperature_max_c = std::numeric_limits<double>::quiet_NaN();
  std::size_t still_samples = 0;  // the samples that updated it, over every run it carries
};
// Throws std::invalid_argument naming the value when a number is not finite, a variance is
// negative or the covariance is not positive semi-definite.
void validateLearnedResidual(const LearnedResidual& learned);

struct RateSample {
  AngularRate rate_dps{};  // the stream
  AngularRate bias_dps{};  // b̂ = model + residual
  bool still = false;
};

class RateEstimator {
 public:
  explicit RateEstimator(const RateEstimatorParameters& params);

  // One sample at rate_hz: t in s (any origin; the warm-up shape counts from the first call),
  // raw rate, die temperature.
  RateSample update(double t_s, const AngularRate& raw_dps, double temperature_c);
  void reset();
  // The accel of the sample about to be update()d, for the still detector (NaN: none).
  void observeAccel(const std::array<double, kMotionAxes>& accel_g) { detector_.observeAccel(accel_g); }

  const StillDetector& detector() const { return detector_; }
  // r̂ at the current temperature and its variance h·P·hᵀ (h = [1, T − T_start]).
  double residual(std::size_t axis) const;
  double residualVariance(std::size_t axis) const;
  double processNoisePerSecond(std::size_t axis) const { return axes_.at(axis).q_per_sample * params_.rate_hz; }
  std::size_t updates() const { return updates_; }  // samples that updated the residual
  // What has been learned so far (before the first sample: the model's prior, or what
  // startFrom() was given, unmoved).
  LearnedResidual learned() const;
  // Begin from `learned` instead of the model's prior: at the first sample the residual is
  // carried to that sample's temperature (offset + slope·ΔT, the covariance with it), and each
  // offset's variance grows by the random walk's q over `elapsed_s` (the time it was not
  // followed). Only before the first sample (std::logic_error after it); validated
  // (std::invalid_argument). reset() returns to the model's prior.
  void startFrom(const LearnedResidual& learned, double elapsed_s);
  const RateEstimatorParameters& parameters() const { return params_; }

 private:
  struct AxisState {
    double offset = 0.0, slope = 0.0;           // r̂ = offset + slope·(T − T_start)
    double p_oo = 0.0, p_os = 0.0, p_ss = 0.0;  // their covariance
    double q_per_sample = 0.0;
    double sample_var = 0.0;  // R = W·σm²
    double lp_in = 0.0, lp_out = 0.0;
  };
  void measure(std::size_t axis, double corrected);

  RateEstimatorParameters params_;
  StillDetector detector_;
  std::array<AxisState, kMotionAxes> axes_{};
  bool started_ = false;
  bool low_pass_primed_ = false;
  double t_first_ = 0.0;
  double temperature_ = 0.0;        // smoothed
  double temperature_start_ = 0.0;  // of the first sample: the slope's origin
  double temperature_alpha_ = 1.0;  // EMA weight of a new sample
  std::size_t updates_ = 0;
  std::size_t updates_before_ = 0;  // still samples the state it started from had seen
  double still_temperature_min_ = std::numeric_limits<double>::quiet_NaN();
  double still_temperature_max_ = std::numeric_limits<double>::quiet_NaN();
  std::optional<LearnedResidual> start_from_;  // applied at the first sample
  double lp_b0_ = 1.0, lp_a1_ = 0.0;           // y = b0·(x + x1) − a1·y1
};

}  // namespace gyrod::processing
