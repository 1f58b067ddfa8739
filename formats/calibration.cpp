#include "formats/calibration.hpp"

#include <algorithm>
#include <cmath>

namespace gyrod::recording {

processing::RateEstimatorParameters rateEstimatorParameters(const SensorModel& model) {
  processing::RateEstimatorParameters p;
  p.rate_hz = model.simulation.rate_hz;
  const FilterModel filter = model.filter.value_or(FilterModel{});
  p.still = filter.still;
  p.bias_instability_horizon_s = filter.bias_instability_horizon_s;
  p.temperature_smoothing_s = filter.temperature_smoothing_s;
  p.low_pass_hz = filter.low_pass_hz;
  for (std::size_t a = 0; a < processing::kMotionAxes; ++a) {
    processing::AxisBiasModel& m = p.axes[a];
    m.terms = model.simulation.axes[a].terms;
    m.bias_dps = model.simulation.axes[a].bias_dps;
    if (const auto& c = model.calibration[a]) {
      m.bias_std_dps = c->bias_std_dps;
      m.temperature_coefficient_dps_per_c = c->temperature_coefficient_dps_per_c;
      m.temperature_coefficient_std_dps_per_c = c->temperature_coefficient_std_dps_per_c;
      m.temperature_reference_c = c->temperature_reference_c;
      m.warm_up_amplitude_dps = c->warm_up_amplitude_dps;
      m.warm_up_time_constant_s = c->warm_up_time_constant_s;
    }
  }
  processing::validateRateEstimatorParameters(p);
  return p;
}

SensorModel withLearnedResidual(SensorModel model, const processing::LearnedResidual& learned) {
  processing::validateLearnedResidual(learned);
  for (std::size_t a = 0; a < processing::kMotionAxes; ++a) {
    AxisCalibration c = model.calibration[a].value_or(AxisCalibration{});
    const processing::LearnedResidualAxis& x = learned.axes[a];
    const double d = c.temperature_reference_c - learned.temperature_origin_c;
    model.simulation.axes[a].bias_dps += x.offset_dps + x.slope_dps_per_c * d;
    c.temperature_coefficient_dps_per_c += x.slope_dps_per_c;
    c.bias_std_dps = std::sqrt(x.var_offset + 2.0 * d * x.cov_offset_slope + d * d * x.var_slope);
    c.temperature_coefficient_std_dps_per_c = std::sqrt(x.var_slope);
    model.calibration[a] = c;
  }
  return model;
}

std::vector<double> secondsFromStart(const Recording& rec, double rate_hz) {
  std::vector<double> s(rec.size());
  for (std::size_t i = 0; i < s.size(); ++i)
    s[i] = rec.t.empty() ? static_cast<double>(i) / rate_hz : rec.t[i] - rec.t[0];
  return s;
}

AxisCalibrationFit calibrateAxis(std::span<const double> secs, std::span<const double> rate_dps,
                                 std::span<const double> temp_c) {
  constexpr double kReferenceWithoutTemperatureC = 25.0;
  const std::vector<double> constant_temperature(temp_c.empty() ? rate_dps.size() : 0, kReferenceWithoutTemperatureC);
  const std::span<const double> temp = temp_c.empty() ? std::span<const double>(constant_temperature) : temp_c;
  AxisCalibrationFit out;
  out.fit = processing::fitTemperatureBias(secs, rate_dps, temp);
  const processing::TemperatureBiasFit& f = out.fit;
  out.bias_dps = f.bias_dps;
  AxisCalibration& c = out.calibration;
  c.bias_std_dps = f.bias_std_dps;
  c.temperature_coefficient_dps_per_c = f.coefficient_dps_per_c;
  c.temperature_coefficient_std_dps_per_c = f.coefficient_std_dps_per_c;
  c.temperature_reference_c = f.reference_c;
  c.warm_up_amplitude_dps = f.warm_up_amplitude_dps;
  c.warm_up_amplitude_std_dps = f.warm_up_amplitude_std_dps;
  c.warm_up_time_constant_s = f.warm_up_time_constant_s;
  out.corrected.assign(rate_dps.begin(), rate_dps.end());
  const double t0 = secs.empty() ? 0.0 : secs.front();
  for (std::size_t i = 0; i < out.corrected.size(); ++i) {
    double model = f.coefficient_dps_per_c * (temp[i] - f.reference_c);
    if (f.warm_up_amplitude_dps != 0.0)
      model += f.warm_up_amplitude_dps * std::exp(-(secs[i] - t0) / f.warm_up_time_constant_s);
    out.corrected[i] -= model;
  }
  return out;
}

}  // namespace gyrod::recording

namespace gyrod::recording {

processing::attitude::AttitudeParameters rateStreamAttitudeParameters(const processing::RateEstimatorParameters& rate) {
  processing::attitude::AttitudeParameters params;
  params.rate_hz = rate.rate_hz;
  // The largest axis's angle random walk (°/√h → °/s/√Hz: /60) and bias 1σ.
  double arw = 0.0, bias_std = 0.0;
  for (const auto& axis : rate.axes) {
    arw = std::max(arw, axis.terms.arw_deg_per_sqrt_h / 60.0);
    bias_std = std::max(bias_std, axis.bias_std_dps);
  }
  params.estimate_bias = false;
  params.gyro_angle_random_walk_dps_per_sqrt_hz = arw;
  params.initial_bias_std_dps = bias_std;
  return params;
}

}  // namespace gyrod::recording
