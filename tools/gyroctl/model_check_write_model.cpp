// gyroctl model-check --write-model (model_check_write_model.hpp).
#include "tools/gyroctl/model_check_write_model.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <span>
#include <system_error>

#include "formats/calibration.hpp"
#include "formats/model_toml.hpp"
#include "formats/output_file.hpp"
#include "formats/recording_csv.hpp"
#include "processing/base/noise_terms.hpp"
#include "processing/motion/warm_up_fit.hpp"
#include "processing/simulation/noise_simulator.hpp"
#include "processing/simulation/sensor_model.hpp"
#include "tools/gyroctl/exit_codes.hpp"
#include "tools/gyroctl/model_check_support.hpp"

namespace gyrod::gyroctl {

using namespace gyrod::processing;

namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// The model axis of a checked column: gx, gy, gz (docs/model-check.md). The column of a
// file of bare numbers is not written into the model.
std::optional<std::size_t> simulatorAxisFor(const std::string& column) {
  if (column == recording::kBareNumbersColumn) return std::nullopt;
  return recording::axisOfColumn(column);
}

// Mean of the noise-free curve over the recording's times: the temperature term's
// reference, so that k·(T − reference) averages to zero and bias_dps stays the mean rate.
double meanOfCurve(const TemperatureModel& m, std::span<const double> secs) {
  double s = 0.0;
  for (double t : secs) s += m.final_c + (m.start_c - m.final_c) * std::exp(-t / m.time_constant_s);
  return s / static_cast<double>(secs.size());
}

// One axis's extended model: the refitted five terms plus each named effect as the
// simulator's AxisExtraEffects (times and phases from the first sample, as the check fits
// them); the effects without a simulator counterpart go into `notes`.
AxisNoiseModel extendedAxisModel(const AxisModelCheck& r, std::span<const double> rate_dps,
                                 const recording::Recording& rec, double rate_hz, double temperature_reference_c,
                                 const std::string& name, std::vector<std::string>& notes) {
  AxisNoiseModel m;
  // An extension that did not gain is not the model: the base terms stay, and its effects
  // become comments.
  m.terms = r.verdict.accepted ? r.extended_fit.value : r.base_fit.value;
  long double sum = 0.0L;
  for (double v : rate_dps) sum += v;
  double bias = static_cast<double>(sum / static_cast<long double>(rate_dps.size()));
  const double n = static_cast<double>(rate_dps.size());
  AxisExtraEffects& x = m.extra;
  for (const DetectedEffect& e : r.effects) {
    if (!e.explained) {
      notes.push_back(name + ": " + std::string(modelEffectName(e.effect)) + " seen, not explained (" +
                      notExplainedReason(r.verdict) + "): not modelled");
      continue;
    }
    switch (e.effect) {
      case ModelEffect::TemperatureBias:
        x.temperature_coefficient_dps_per_c = e.k_dps_per_c;
        x.temperature_reference_c = temperature_reference_c;
        break;
      case ModelEffect::Sinusoid: x.sinusoids.push_back({e.freq_hz, e.amp_dps, e.phase_rad}); break;
      case ModelEffect::NarrowbandLine: x.narrowband_lines.push_back({e.centre_hz, e.width_hz, e.rms_dps}); break;
      case ModelEffect::GaussMarkov:
        x.gauss_markov_tau_s = e.tau_s;
        x.gauss_markov_sigma_dps = e.sigma_dps;
        break;
      case ModelEffect::BiasSteps:
        for (std::size_t j = 0; j < e.times_s.size() && j < e.sizes_dps.size(); ++j) {
          // The check reports the step's time from t (when present); the simulator counts
          // samples from 0 at the nominal rate, so use the sample index.
          const std::size_t i = rec.t.empty()
                                    ? static_cast<std::size_t>(std::llround(e.times_s[j] * rate_hz))
                                    : static_cast<std::size_t>(
                                          std::lower_bound(rec.t.begin(), rec.t.end(), e.times_s[j]) - rec.t.begin());
          x.bias_steps.push_back({static_cast<double>(i) / rate_hz, e.sizes_dps[j]});
          bias -= e.sizes_dps[j] * (n - static_cast<double>(std::min<std::size_t>(i, rate_dps.size()))) / n;
        }
        break;
      case ModelEffect::Outliers:
        x.outlier_count = e.count;
        x.outlier_amplitude_dps = e.outlier_median_amplitude_dps;
        break;
      case ModelEffect::SampleGaps:
        notes.push_back(name + ": sample_gaps found (" + std::to_string(e.count) + " gaps, " + std::to_string(e.lost) +
                        " samples lost): not modelled, the simulator delivers every sample");
        break;
      case ModelEffect::Unexplained:
        notes.push_back(name + ": unexplained mismatch at tau " + fmt("%.4g", e.where_lo) + " to " +
                        fmt("%.4g", e.where_hi) + " s: not modelled, no catalogue effect explains it");
        break;
    }
  }
  m.bias_dps = bias;
  return m;
}

}  // namespace

void requireWritableTarget(const std::string& path, const std::string& input) {
  const std::filesystem::path p(path);
  std::error_code ec;
  if (std::filesystem::is_directory(p, ec))
    throw ExitError(ExitCode::CantCreate, path + ": cannot write the model: it is a folder");
  const std::filesystem::path folder = p.parent_path().empty() ? std::filesystem::path(".") : p.parent_path();
  if (!std::filesystem::is_directory(folder, ec))
    throw ExitError(ExitCode::CantCreate,
                    path + ": cannot write the model: " + folder.string() +
                        (std::filesystem::exists(folder, ec) ? " is not a folder" : ": folder does not exist"));
  formats::checkOutputTarget(path, {input});  // a FIFO, a device, the input itself
  if (::access(folder.c_str(), W_OK) != 0)
    throw ExitError(ExitCode::CantCreate,
                    path + ": cannot write the model in " + folder.string() + ": " + std::strerror(errno));
}

std::string extendedModelToml(const std::string& file, std::uint64_t seed, std::size_t replicas, const LoadedInput& in,
                              const std::vector<std::pair<std::string, AxisModelCheck>>& results) {
  const recording::Recording& rec = in.recording;
  recording::SensorModel sensor;
  SimulationModel& model = sensor.simulation;
  model.rate_hz = in.rate_hz;
  const std::vector<double> secs = recording::secondsFromStart(rec, in.rate_hz);
  double reference_c = model.temperature.start_c;
  if (!rec.temp.empty()) {
    model.temperature = processing::fitExponentialWarmUp(secs, rec.temp);
    reference_c = meanOfCurve(model.temperature, secs);
  }
  std::vector<std::string> notes, axes_written;
  for (std::size_t k = 0; k < results.size(); ++k) {
    const auto& [name, r] = results[k];
    const auto slot = simulatorAxisFor(name);
    if (!slot) continue;
    model.axes[*slot] = extendedAxisModel(r, rec.axes[in.axis_indices[k]], rec, in.rate_hz, reference_c, name, notes);
    axes_written.push_back(name);
    // The rate stream's calibration, fitted as gyroctl analyze fits it (bias_dps stays the
    // check's: the mean with its steps removed).
    try {
      sensor.calibration[*slot] = recording::calibrateAxis(secs, rec.axes[in.axis_indices[k]], rec.temp).calibration;
    } catch (const std::invalid_argument& e) {
      notes.push_back(name + ": no calibration (" + e.what() + ")");
    }
  }
  // The acquisition chain the check modelled (the same for every axis): the simulator then
  // makes the noise through the same DLPF and rounding. The rounding's white noise is part of
  // the fitted white term, and the simulator adds it again, so that much is taken out of it.
  if (!results.empty()) {
    const AcquisitionChain& chain = results.front().second.chain;
    model.dlpf_cfg = chain.dlpf_cfg;
    model.fs_sel = chain.fs_sel;
    if (chain.fs_sel) {
      const double lsb = 1.0 / processing::gyroSensitivityLsbPerDps(*chain.fs_sel);
      const double rounding = lsb * lsb / (12.0 * in.rate_hz);
      for (AxisNoiseModel& axis : model.axes) {
        const double c = allanVarianceCoefficient(NoiseTerm::AngleRandomWalk, axis.terms.arw_deg_per_sqrt_h);
        axis.terms.arw_deg_per_sqrt_h =
            c > 0.0 ? noiseTermFromCoefficient(NoiseTerm::AngleRandomWalk, std::max(0.0, c - rounding)) : 0.0;
      }
    }
  }
  validateSimulationModel(model);
  std::string head = "# Extended model of " + file + " from gyroctl model-check (seed " + std::to_string(seed) + ", " +
                     std::to_string(replicas) +
                     " replicas): the five terms refitted with the named\n"
                     "# effects removed, plus those effects as [axis.extra] tables (docs/model-check.md).\n"
                     "# Axes checked:";
  for (const std::string& a : axes_written) head += " " + a;
  head += ".\n";
  if (!rec.temp.empty())
    head +=
        "# [temperature] is a warm-up curve fitted to the recording's temperature; the recording's own\n"
        "# temperature (room cycles, steps) is not reproduced, only the temperature coefficient.\n";
  for (const std::string& note : notes) head += "# " + note + "\n";
  return head + recording::sensorModelToToml(sensor);
}
}  // namespace gyrod::gyroctl
