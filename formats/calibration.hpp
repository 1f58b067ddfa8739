#pragma once
// The calibration of the sensor model file (docs/calibration.md): made from a still recording
// (gyroctl analyze / model-check --write-model) and turned into the rate stream's parameters
// (gyroctl filter --model, and gyrod).
#include <span>
#include <string>
#include <vector>

#include "formats/model_toml.hpp"
#include "formats/recording_csv.hpp"
#include "processing/attitude/attitude_estimator.hpp"
#include "processing/motion/rate_estimator.hpp"
#include "processing/motion/temperature_bias_fit.hpp"

namespace gyrod::recording {

// The rate stream's parameters: per axis the terms and bias_dps of [x], [x.calibration] (or
// none: no temperature term, bias_std 0), and [filter] (or its defaults); rate_hz the model's.
// Throws std::invalid_argument as validateRateEstimatorParameters does.
processing::RateEstimatorParameters rateEstimatorParameters(const SensorModel& model);

// The attitude estimator on the rate stream of `rate`'s model (gyrod's RATE orientation and
// `gyroctl attitude --model`, which must agree bit for bit): no bias of its own (the stream's
// is used), and for the 1σ the largest axis's angle random walk and bias 1σ.
processing::attitude::AttitudeParameters rateStreamAttitudeParameters(const processing::RateEstimatorParameters& rate);

// Seconds from the first sample for each sample: from t when present, else i/rate.
std::vector<double> secondsFromStart(const Recording& rec, double rate_hz);

// One axis's calibration from a still record: the bias against temperature (and time) of
// processing::fitTemperatureBias, as the file's [x.calibration] and [x]'s bias_dps.
// Without a temperature channel (`temp_c` empty) only the bias (and a warm-up shape in time)
// is fitted, at reference 25 °C. `corrected` is the rate minus the fitted temperature term and
// shape (the record as if at the reference temperature, after the warm-up): the series the
// noise terms are fitted on. Throws std::invalid_argument as fitTemperatureBias does.
struct AxisCalibrationFit {
  processing::TemperatureBiasFit fit;
  AxisCalibration calibration;
  double bias_dps = 0.0;
  std::vector<double> corrected;
  bool changed() const { return fit.coefficientFitted() || fit.warm_up_amplitude_dps != 0.0; }
};
AxisCalibrationFit calibrateAxis(std::span<const double> secs, std::span<const double> rate_dps,
                                 std::span<const double> temp_c);

// The model with what a board learned on top of it folded in (docs/calibration-state.md): per
// axis, with r(T) = offset + slope·(T − T_origin) the learned residual and T_ref the axis's
// reference temperature (the model's, or 25 °C when it has no [x.calibration]),
//   bias_dps' = bias_dps + r(T_ref),  coefficient' = coefficient + slope,
//   bias_std' = √(var r(T_ref)),  coefficient_std' = √var(slope)
// (the learned covariance is the posterior, the model's own uncertainty already in it; the
// covariance of bias' and coefficient' is not kept, as the file has no place for it). The noise
// terms, the warm-up shape and everything else stay the model's.
SensorModel withLearnedResidual(SensorModel model, const processing::LearnedResidual& learned);

}  // namespace gyrod::recording
