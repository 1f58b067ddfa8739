// gyroctl model: a sensor model's calibration per axis and, with --state, what a board's gyrod
// learned on top of it (docs/calibration-state.md) and the two combined; --write-model writes
// that combination as a model file, the calibration gyrod then starts from with no state at all.
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>
#include <optional>
#include <string>

#include "formats/calibration.hpp"
#include "formats/calibration_state.hpp"
#include "formats/model_toml.hpp"
#include "formats/output_file.hpp"
#include "formats/toml_document.hpp"
#include "tools/gyroctl/commands.hpp"

namespace gyrod::gyroctl {
namespace {

struct ModelOptions {
  std::string model;
  std::string state;
  std::string write_model;
};

std::string utc(double unix_s) {
  const auto seconds = static_cast<std::time_t>(std::floor(unix_s));
  std::tm tm{};
  ::gmtime_r(&seconds, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// Four significant digits: what a reader compares; the file keeps every digit.
std::string g4(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

void printCalibration(const char* label, const recording::SensorModel& m) {
  const processing::RateEstimatorParameters p = recording::rateEstimatorParameters(m);
  std::printf("%s\n", label);
  std::printf("  axis  bias [deg/s] at T_ref      coefficient [deg/s per C]   T_ref [C]\n");
  for (std::size_t a = 0; a < processing::kMotionAxes; ++a) {
    const processing::AxisBiasModel& x = p.axes[a];
    std::printf("  %c     %-10s +- %-10s  %-10s +- %-10s  %s\n", "xyz"[a], g4(x.bias_dps).c_str(),
                g4(x.bias_std_dps).c_str(), g4(x.temperature_coefficient_dps_per_c).c_str(),
                g4(x.temperature_coefficient_std_dps_per_c).c_str(), g4(x.temperature_reference_c).c_str());
  }
}

int runModel(const ModelOptions& opt) {
  if (!opt.write_model.empty() && opt.state.empty())
    throw ExitError(ExitCode::Usage, "--write-model needs --state (without one the model would be copied unchanged)");
  if (!opt.write_model.empty()) formats::checkOutputTarget(opt.write_model, {opt.model, opt.state});
  const recording::SensorModel model = recording::readSensorModelToml(opt.model);
  const processing::RateEstimatorParameters params = recording::rateEstimatorParameters(model);
  std::printf("model %s: %s Hz, bias model fingerprint %s\n", opt.model.c_str(),
              formats::shortest(model.simulation.rate_hz).c_str(), formats::biasModelFingerprint(params).c_str());
  printCalibration("the model's calibration:", model);
  if (opt.state.empty()) return kExitOk;

  formats::CalibrationState state;
  try {
    state = formats::readCalibrationStateToml(opt.state);
  } catch (const formats::CalibrationStateError& e) {
    throw ExitError(ExitCode::DataError, e.what());
  }
  if (state.model != formats::biasModelFingerprint(params))
    throw ExitError(ExitCode::DataError, opt.state + ": learned with another bias model (fingerprint " + state.model +
                                             ", " + opt.model + "'s " + formats::biasModelFingerprint(params) + ")");
  const processing::LearnedResidual& r = state.residual;
  std::printf("\nstate %s: written %s, %s s into its run; %zu still samples", opt.state.c_str(),
              utc(state.saved_unix_s).c_str(), g4(state.data_time_s).c_str(), r.still_samples);
  if (!std::isnan(r.still_temperature_min_c))
    std::printf(" at %s-%s C", g4(r.still_temperature_min_c).c_str(), g4(r.still_temperature_max_c).c_str());
  std::printf("\n  axis  residual [deg/s] at %s C   slope [deg/s per C]\n", g4(r.temperature_origin_c).c_str());
  for (std::size_t a = 0; a < processing::kMotionAxes; ++a) {
    const processing::LearnedResidualAxis& x = r.axes[a];
    std::printf("  %c     %-10s +- %-10s  %-10s +- %s\n", "xyz"[a], g4(x.offset_dps).c_str(),
                g4(std::sqrt(x.var_offset)).c_str(), g4(x.slope_dps_per_c).c_str(), g4(std::sqrt(x.var_slope)).c_str());
  }
  const recording::SensorModel combined = recording::withLearnedResidual(model, r);
  std::printf("\n");
  printCalibration("the model with what the board learned (--write-model writes it):", combined);
  if (!opt.write_model.empty()) {
    const std::string head = "# Sensor model " + opt.model + " with the calibration state " + opt.state +
                             " folded in (gyroctl model, docs/calibration-state.md).\n";
    formats::writeFileAtomically(opt.write_model, head + recording::sensorModelToToml(combined),
                                 {opt.model, opt.state});
    std::printf("\nModel written to %s\n", opt.write_model.c_str());
  }
  return kExitOk;
}

}  // namespace

void addModelCommand(CLI::App& app, CommandRunner& run) {
  auto opt = std::make_shared<ModelOptions>();
  auto* sub = app.add_subcommand(
      "model", "Show a sensor model's calibration and, with --state, what gyrod learned on top of it on a board");
  sub->add_option("MODEL", opt->model, "sensor model file (gyroctl analyze --write-model)")->required();
  sub->add_option("--state", opt->state,
                  "gyrod's calibration state (its state directory's calibration.toml, docs/calibration-state.md)");
  sub->add_option("--write-model", opt->write_model, "write the model with the state folded in, as TOML");
  sub->callback([&run, opt] { run = [opt] { return runModel(*opt); }; });
}

}  // namespace gyrod::gyroctl
