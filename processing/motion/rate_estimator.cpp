#include "processing/motion/rate_estimator.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace gyrod::processing {
namespace {

std::string axisPrefix(std::size_t a) { return std::string("axis ") + "xyz"[a] + ": "; }

void requireFinite(double v, const std::string& what) {
  if (!std::isfinite(v)) throw std::invalid_argument(what + " must be finite, got " + std::to_string(v));
}
void requireNonNegative(double v, const std::string& what) {
  if (!std::isfinite(v) || v < 0.0)
    throw std::invalid_argument(what + " must be finite and >= 0, got " + std::to_string(v));
}
void requirePositive(double v, const std::string& what) {
  if (!std::isfinite(v) || !(v > 0.0))
    throw std::invalid_argument(what + " must be finite and > 0, got " + std::to_string(v));
}

std::array<StillNoiseLevel, kMotionAxes> levelsOf(const RateEstimatorParameters& p) {
  validateRateEstimatorParameters(p);
  std::array<StillNoiseLevel, kMotionAxes> levels{};
  for (std::size_t a = 0; a < kMotionAxes; ++a)
    levels[a] = stillNoiseLevelFromTerms(p.axes[a].terms, p.rate_hz, p.still.window_samples);
  return levels;
}

// Random-walk intensity (variance per second) standing in for the fitted drift terms.
double driftProcessNoisePerSecond(const NoiseTerms& terms, double horizon_s) {
  const double rrw = 3.0 * allanVarianceCoefficient(NoiseTerm::RateRandomWalk, terms.rrw_deg_per_h_sqrt_h);
  const double flicker = 2.0 * allanVarianceCoefficient(NoiseTerm::BiasInstability, terms.bias_instability_deg_per_h);
  const double ramp = 2.0 * allanVarianceCoefficient(NoiseTerm::RateRamp, terms.rate_ramp_deg_per_h2);
  return rrw + flicker / horizon_s + ramp * horizon_s;
}

}  // namespace

double AxisBiasModel::biasAt(double temperature_c, double since_start_s) const {
  double b = bias_dps + temperature_coefficient_dps_per_c * (temperature_c - temperature_reference_c);
  if (warm_up_amplitude_dps != 0.0) b += warm_up_amplitude_dps * std::exp(-since_start_s / warm_up_time_constant_s);
  return b;
}

void validateRateEstimatorParameters(const RateEstimatorParameters& p) {
  requirePositive(p.rate_hz, "rate_hz");
  requirePositive(p.bias_instability_horizon_s, "bias_instability_horizon_s");
  requireNonNegative(p.temperature_smoothing_s, "temperature_smoothing_s");
  if (p.low_pass_hz && !(std::isfinite(*p.low_pass_hz) && *p.low_pass_hz > 0.0 && *p.low_pass_hz < 0.5 * p.rate_hz))
    throw std::invalid_argument("low_pass_hz must be > 0 and below half the rate (" + std::to_string(0.5 * p.rate_hz) +
                                " Hz), got " + std::to_string(*p.low_pass_hz));
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    const AxisBiasModel& m = p.axes[a];
    const std::string w = axisPrefix(a);
    requireFinite(m.bias_dps, w + "bias_dps");
    requireFinite(m.temperature_coefficient_dps_per_c, w + "temperature_coefficient_dps_per_c");
    requireFinite(m.temperature_reference_c, w + "temperature_reference_c");
    requireFinite(m.warm_up_amplitude_dps, w + "warm_up_amplitude_dps");
    if (m.warm_up_amplitude_dps != 0.0) requirePositive(m.warm_up_time_constant_s, w + "warm_up_time_constant_s");
    requireNonNegative(m.bias_std_dps, w + "bias_std_dps");
    requireNonNegative(m.temperature_coefficient_std_dps_per_c, w + "temperature_coefficient_std_dps_per_c");
    for (NoiseTerm t : kAllNoiseTerms) requireNonNegative(m.terms.get(t), w + std::string(noiseTermKey(t)));
    if (m.terms.arw_deg_per_sqrt_h == 0.0 && m.terms.quantization_urad == 0.0)
      throw std::invalid_argument(w +
                                  "the still detector needs a white-noise level: arw_deg_per_sqrt_h or "
                                  "quantization_urad must be > 0");
  }
}

RateEstimator::RateEstimator(const RateEstimatorParameters& params)
    : params_(params), detector_(params.still, levelsOf(params)) {
  const double tau0 = 1.0 / params_.rate_hz;
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    const double q_per_second = driftProcessNoisePerSecond(params_.axes[a].terms, params_.bias_instability_horizon_s);
    axes_[a].q_per_sample = q_per_second * tau0;
    // A window mean of variance σm² is worth W samples of variance W·σm² each (at the low
    // frequencies the residual tracks, the noise is white at the level of the Allan fit).
    axes_[a].sample_var = detector_.windowVariance(a) * static_cast<double>(params_.still.window_samples);
  }
  if (params_.temperature_smoothing_s > 0.0) temperature_alpha_ = -std::expm1(-tau0 / params_.temperature_smoothing_s);
  if (params_.low_pass_hz) {
    // Bilinear transform of ωc/(s + ωc), prewarped so that the −3 dB point is exactly low_pass_hz.
    const double k = std::tan(std::numbers::pi * *params_.low_pass_hz / params_.rate_hz);
    lp_b0_ = k / (1.0 + k);
    lp_a1_ = (k - 1.0) / (k + 1.0);
  }
  reset();
}

void validateLearnedResidual(const LearnedResidual& learned) {
  requireFinite(learned.temperature_origin_c, "temperature_origin_c");
  requireFinite(learned.temperature_c, "temperature_c");
  const bool no_range = std::isnan(learned.still_temperature_min_c) && std::isnan(learned.still_temperature_max_c);
  if (!no_range) {
    requireFinite(learned.still_temperature_min_c, "still_temperature_min_c");
    requireFinite(learned.still_temperature_max_c, "still_temperature_max_c");
    if (learned.still_temperature_min_c > learned.still_temperature_max_c)
      throw std::invalid_argument("still_temperature_min_c must not exceed still_temperature_max_c, got " +
                                  std::to_string(learned.still_temperature_min_c) + " > " +
                                  std::to_string(learned.still_temperature_max_c));
  }
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    const LearnedResidualAxis& x = learned.axes[a];
    const std::string w = axisPrefix(a);
    requireFinite(x.offset_dps, w + "offset_dps");
    requireFinite(x.slope_dps_per_c, w + "slope_dps_per_c");
    requireNonNegative(x.var_offset, w + "var_offset");
    requireNonNegative(x.var_slope, w + "var_slope");
    requireFinite(x.cov_offset_slope, w + "cov_offset_slope");
    // A covariance matrix: |cov| ≤ √(var·var) (a little slack for the rounding of a file).
    if (x.cov_offset_slope * x.cov_offset_slope > x.var_offset * x.var_slope * (1.0 + 1e-9) + 1e-300)
      throw std::invalid_argument(w + "cov_offset_slope must satisfy cov^2 <= var_offset * var_slope, got " +
                                  std::to_string(x.cov_offset_slope));
  }
}

void RateEstimator::reset() {
  detector_.reset();
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    AxisState& s = axes_[a];
    const double bias_std = params_.axes[a].bias_std_dps, k_std = params_.axes[a].temperature_coefficient_std_dps_per_c;
    s.offset = s.slope = 0.0;
    s.p_oo = bias_std * bias_std;
    s.p_os = 0.0;
    s.p_ss = k_std * k_std;
  }
  started_ = false;
  low_pass_primed_ = false;
  updates_ = 0;
  updates_before_ = 0;
  still_temperature_min_ = still_temperature_max_ = std::numeric_limits<double>::quiet_NaN();
  start_from_.reset();
}

void RateEstimator::startFrom(const LearnedResidual& learned, double elapsed_s) {
  if (started_) throw std::logic_error("RateEstimator::startFrom after the first sample");
  validateLearnedResidual(learned);
  requireNonNegative(elapsed_s, "elapsed_s");
  start_from_ = learned;
  for (std::size_t a = 0; a < kMotionAxes; ++a)  // the walk while nobody followed it
    start_from_->axes[a].var_offset += axes_[a].q_per_sample * params_.rate_hz * elapsed_s;
}

LearnedResidual RateEstimator::learned() const {
  if (!started_ && start_from_) return *start_from_;
  LearnedResidual l;
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    const AxisState& s = axes_[a];
    l.axes[a] = {s.offset, s.slope, s.p_oo, s.p_os, s.p_ss};
  }
  l.temperature_origin_c = temperature_start_;
  l.temperature_c = temperature_;
  l.still_temperature_min_c = still_temperature_min_;
  l.still_temperature_max_c = still_temperature_max_;
  l.still_samples = updates_before_ + updates_;
  return l;
}

double RateEstimator::residual(std::size_t axis) const {
  const AxisState& s = axes_.at(axis);
  return s.offset + s.slope * (temperature_ - temperature_start_);
}

double RateEstimator::residualVariance(std::size_t axis) const {
  const AxisState& s = axes_.at(axis);
  const double h = temperature_ - temperature_start_;
  return s.p_oo + 2.0 * h * s.p_os + h * h * s.p_ss;
}

void RateEstimator::measure(std::size_t a, double corrected) {
  // Kalman update of [offset, slope] by c = offset + slope·h + v, h = T − T_start, var(v) = R.
  AxisState& s = axes_[a];
  const double h = temperature_ - temperature_start_;
  const double ph_o = s.p_oo + h * s.p_os, ph_s = s.p_os + h * s.p_ss;  // P·hᵀ
  const double innovation_var = ph_o + h * ph_s + s.sample_var;
  const double gain_o = ph_o / innovation_var, gain_s = ph_s / innovation_var;
  const double innovation = corrected - (s.offset + s.slope * h);
  s.offset += gain_o * innovation;
  s.slope += gain_s * innovation;
  s.p_oo -= gain_o * ph_o;
  s.p_os -= gain_o * ph_s;
  s.p_ss -= gain_s * ph_s;
}

RateSample RateEstimator::update(double t_s, const AngularRate& raw_dps, double temperature_c) {
  if (!started_) {
    started_ = true;
    t_first_ = t_s;
    temperature_ = temperature_start_ = temperature_c;
    if (start_from_) {  // carried to this temperature: [offset, slope] ← J·[offset, slope], P ← J·P·Jᵀ
      const LearnedResidual& l = *start_from_;
      const double d = temperature_start_ - l.temperature_origin_c;
      for (std::size_t a = 0; a < kMotionAxes; ++a) {
        const LearnedResidualAxis& x = l.axes[a];
        AxisState& s = axes_[a];
        s.offset = x.offset_dps + x.slope_dps_per_c * d;
        s.slope = x.slope_dps_per_c;
        s.p_oo = x.var_offset + 2.0 * d * x.cov_offset_slope + d * d * x.var_slope;
        s.p_os = x.cov_offset_slope + d * x.var_slope;
        s.p_ss = x.var_slope;
      }
      updates_before_ = l.still_samples;
      still_temperature_min_ = l.still_temperature_min_c;
      still_temperature_max_ = l.still_temperature_max_c;
      start_from_.reset();
    }
  } else {
    temperature_ += temperature_alpha_ * (temperature_c - temperature_);
  }
  const double since_start = t_s - t_first_;
  AngularRate model{}, corrected{}, expected{}, expected_var{};
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    axes_[a].p_oo += axes_[a].q_per_sample;  // the offset walks; the slope (k's error) is a constant
    model[a] = params_.axes[a].biasAt(temperature_, since_start);
    corrected[a] = raw_dps[a] - model[a];
    expected[a] = residual(a);
    expected_var[a] = residualVariance(a);
  }
  const bool still = detector_.update(corrected, expected, expected_var);
  if (still) {
    for (std::size_t a = 0; a < kMotionAxes; ++a) measure(a, corrected[a]);
    ++updates_;
    // fmin/fmax ignore the NaN of "none yet"
    still_temperature_min_ = std::fmin(still_temperature_min_, temperature_);
    still_temperature_max_ = std::fmax(still_temperature_max_, temperature_);
  }
  RateSample out;
  out.still = still;
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    AxisState& s = axes_[a];
    out.bias_dps[a] = model[a] + residual(a);
    double rate = raw_dps[a] - out.bias_dps[a];
    if (params_.low_pass_hz) {
      const double x = rate;
      if (!low_pass_primed_) s.lp_in = s.lp_out = x;  // start in steady state
      rate = lp_b0_ * (x + s.lp_in) - lp_a1_ * s.lp_out;
      s.lp_in = x;
      s.lp_out = rate;
    }
    out.rate_dps[a] = rate;
  }
  low_pass_primed_ = true;
  return out;
}

}  // namespace gyrod::processing
