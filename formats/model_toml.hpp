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
//
// The noise-term keys are NoiseTerms' field names (noise_terms.hpp). Any other key, a
// wrong type or a bad value is an error "FILE:LINE: ..." naming the key.
#include <string>
#include <string_view>

#include "formats/recording_csv.hpp"
#include "processing/noise_simulator.hpp"

namespace gyrod::recording {

// Reads and validates a model file (validateSimulationModel included). Throws
// RecordingError "FILE:LINE: cause" (or "FILE: cause" when the file cannot be read).
processing::SimulationModel readModelToml(const std::string& path);
// The same from text; `source_name` stands for the file name in messages.
processing::SimulationModel parseModelToml(std::string_view text, const std::string& source_name);

// The model as a file that parseModelToml reads back to the same values (17 significant
// digits). Terms, bias and AR are written for every axis.
std::string modelToToml(const processing::SimulationModel& model);

}  // namespace gyrod::recording
