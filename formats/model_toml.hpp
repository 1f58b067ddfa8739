#pragma once
// Simulation model files (TOML) for `gyroctl simulate --model FILE`:
//
//   rate_hz = 50            # output rate [Hz] (default 50)
//   dlpf = 4                # DLPF_CFG 0..6; omit for no DLPF
//   fs_sel = 0              # FS_SEL 0..3; omit for no quantisation
//   [temperature]           # °C, s; defaults 25, 25, 600, 0
//   start_c = 24.0
//   final_c = 38.0
//   time_constant_s = 900.0
//   noise_std_c = 0.02
//   [x]                     # one table per axis: x, y, z (an absent axis is all zero)
//   quantization_urad = 0.1663
//   arw_deg_per_sqrt_h = 0.95164
//   bias_instability_deg_per_h = 0.60565
//   rrw_deg_per_h_sqrt_h = 0.07759
//   rate_ramp_deg_per_h2 = 0.43223
//   bias_dps = 1.367
//   [x.ar]                  # optional AR(p) at the output rate
//   phi = [-0.2855]
//   noise_var = 0.0577      # σa² [(°/s)²]
//   [x.extra]               # optional effects beyond the paper's model (AxisExtraEffects)
//   temperature_coefficient_dps_per_c = 0.01
//   temperature_reference_c = 25.0
//   gauss_markov_tau_s = 20.0
//   gauss_markov_sigma_dps = 0.002
//   outlier_count = 5
//   outlier_amplitude_dps = 1.0
//   sinusoids = [{freq_hz = 1.08, amp_dps = 0.07, phase_rad = 0.0}]
//   bias_steps = [{time_s = 600.0, size_dps = 0.02}]
//   narrowband_lines = [{centre_hz = 31.4, width_hz = 0.3, rms_dps = 0.02}]  # centre < rate_hz/2
//   [x.calibration]         # optional: the bias model of the `rate` stream (docs/calibration.md)
//   bias_std_dps = 0.0004                    # 1σ of bias_dps (the bias at temperature_reference_c)
//   temperature_coefficient_dps_per_c = 0.03
//   temperature_coefficient_std_dps_per_c = 0.0001
//   temperature_reference_c = 31.2
//   warm_up_amplitude_dps = 0.05             # + A·e^{−t/τ}, t from the first sample; 0 = none
//   warm_up_amplitude_std_dps = 0.004
//   warm_up_time_constant_s = 240.0
//   [x.kalman]              # optional: the paper's Kalman of this axis, as gyrod's filter.kalman
//   a = 0.95
//   q = 0.0012
//   r = 0.018
//   [filter]                # optional: the filters' parameters (every key optional, defaults shown)
//   mean_window = 20
//   mean_threshold_dps = 0.3
//   still_window_samples = 25
//   still_mean_threshold_sigmas = 3.0
//   still_difference_false_alarm = 0.001
//   bias_instability_horizon_s = 100.0
//   temperature_smoothing_s = 1.0
//   low_pass_hz = 5.0       # omit for none
//
// The noise-term keys are NoiseTerms' field names (noise_terms.hpp). Any other key, a
// wrong type or a bad value is an error "FILE:LINE: ..." naming the key.
#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "formats/recording_csv.hpp"
#include "processing/motion/still_detector.hpp"
#include "processing/paper/kalman.hpp"
#include "processing/simulation/noise_simulator.hpp"

namespace gyrod::recording {

// [x.calibration]: the bias model beyond [x]'s bias_dps (processing::AxisBiasModel's fields).
struct AxisCalibration {
  double bias_std_dps = 0.0;
  double temperature_coefficient_dps_per_c = 0.0;
  double temperature_coefficient_std_dps_per_c = 0.0;
  double temperature_reference_c = 25.0;
  double warm_up_amplitude_dps = 0.0;
  double warm_up_amplitude_std_dps = 0.0;  // for the reader; the rate stream takes A as exact
  double warm_up_time_constant_s = 0.0;
};

// [filter]: the paper's chain (mean filter) and the rate stream's settings.
struct FilterModel {
  std::size_t mean_window = 20;
  double mean_threshold_dps = 0.3;
  processing::StillDetectorParameters still;
  double bias_instability_horizon_s = 100.0;
  double temperature_smoothing_s = 1.0;
  std::optional<double> low_pass_hz;
};

// The one sensor model file: the simulator's model plus the calibration (all optional, so a
// file of the simulator alone is still a sensor model).
struct SensorModel {
  processing::SimulationModel simulation;
  std::array<std::optional<AxisCalibration>, processing::kSimulatedAxes> calibration;
  std::array<std::optional<processing::ScalarKalmanParameters>, processing::kSimulatedAxes> kalman;  // a, q, r
  std::optional<FilterModel> filter;
};

// Reads and validates a model file (validateSimulationModel included). Throws
// RecordingError "FILE:LINE: cause" (or "FILE: cause" when the file cannot be read).
processing::SimulationModel readModelToml(const std::string& path);
// The same from text; `source_name` stands for the file name in messages.
processing::SimulationModel parseModelToml(std::string_view text, const std::string& source_name);
// The whole file, calibration included (readModelToml is its `simulation`).
SensorModel readSensorModelToml(const std::string& path);
SensorModel parseSensorModelToml(std::string_view text, const std::string& source_name);

// The model as a file that parseModelToml reads back to the same values (17 significant
// digits). Terms, bias and AR are written for every axis.
std::string modelToToml(const processing::SimulationModel& model);
// The same with the calibration tables ([x.calibration], [x.kalman] after each axis, [filter]
// at the end) where present; without any, exactly modelToToml(model.simulation).
std::string sensorModelToToml(const SensorModel& model);

}  // namespace gyrod::recording
