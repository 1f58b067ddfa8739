// gyroctl attitude: the 6-axis attitude estimator (processing/attitude/) over a recording:
// its columns, then the orientation q_ws (Hamilton, sensor → world, z up, heading 0 at the first
// sample), roll, pitch, heading in degrees and their 1σ (docs/attitude.md).
// Without --model the estimator takes the raw gyro and learns the bias itself (at rest and from
// the inclination correction); with --model it takes the rate stream (raw − b̂(t),
// processing::RateEstimator, as `filter --model` computes it) and learns no bias of its own, and
// the model's noise terms set the 1σ.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "formats/calibration.hpp"
#include "formats/output_file.hpp"
#include "processing/attitude/attitude_estimator.hpp"
#include "processing/motion/rate_estimator.hpp"
#include "tools/gyroctl/commands.hpp"
#include "tools/gyroctl/input.hpp"
#include "tools/gyroctl/series_checks.hpp"

namespace gyrod::gyroctl {
namespace {

using processing::attitude::AttitudeEstimator;
using processing::attitude::AttitudeParameters;
using processing::attitude::AttitudeSample;
using processing::attitude::Vector3;

struct AttitudeOptions {
  std::string file;
  std::string output;
  std::optional<double> rate_hz;
  std::string model;
  bool strict_timing = false;
};

// 17 significant digits: every double survives the text round trip exactly.
void appendAttitudeNumber(std::string& out, double v) {
  char buf[32];
  const int n = std::snprintf(buf, sizeof buf, "%.17g", v);
  out.append(buf, static_cast<std::size_t>(n));
}

// The columns of the recording that go through to the output, in the order gyrod writes them.
std::vector<std::pair<std::string, const std::vector<double>*>> passedThroughColumns(const recording::Recording& rec) {
  std::vector<std::pair<std::string, const std::vector<double>*>> columns;
  auto add = [&](const std::string& name, const std::vector<double>& v) {
    if (!v.empty()) columns.emplace_back(name, &v);
  };
  for (std::size_t a = 0; a < rec.axes.size(); ++a) add(rec.axis_names[a], rec.axes[a]);
  add("temp", rec.temp);
  add("time", rec.time);
  for (std::size_t a = 0; a < 3; ++a) add(std::string("w") + "xyz"[a], rec.true_rate[a]);
  for (std::size_t a = 0; a < 3; ++a) add(std::string(recording::kAccelColumns[a]), rec.accel_g[a]);
  for (std::size_t a = 0; a < 3; ++a) add(std::string(recording::kRateColumns[a]), rec.rate[a]);
  for (std::size_t a = 0; a < 3; ++a) add(std::string(recording::kBiasColumns[a]), rec.bias[a]);
  add("still", rec.still);
  return columns;
}

// The column a name denotes, or a RecordingError naming the file and what the command needs.
const std::vector<double>& requiredColumn(const std::string& file, const std::string& name,
                                          const std::vector<double>* column) {
  if (!column || column->empty())
    throw recording::RecordingError(file + ": attitude needs the columns gx,gy,gz and ax,ay,az; '" + name +
                                    "' is missing");
  return *column;
}

int runAttitude(const AttitudeOptions& opt) {
  formats::checkOutputTarget(opt.output, {opt.file});  // before the work, and again when writing
  LoadedInput in = loadInput(opt.file, opt.rate_hz, "all");
  const recording::Recording& rec = in.recording;
  std::array<const std::vector<double>*, 3> gyro{}, accel{};
  for (std::size_t a = 0; a < 3; ++a) {
    const std::string name(recording::kGyroColumns[a]);
    gyro[a] = &requiredColumn(opt.file, name, rec.axis(name));
    accel[a] = &requiredColumn(opt.file, std::string(recording::kAccelColumns[a]), &rec.accel_g[a]);
  }
  for (std::size_t axis = 0; axis < rec.axes.size(); ++axis) requireAnalysableValues(rec, axis);
  reportTiming(opt.file, checkTiming(rec, opt.rate_hz), opt.strict_timing);

  const std::size_t n = rec.size();
  const double dt = 1.0 / in.rate_hz;
  AttitudeParameters params;
  params.rate_hz = in.rate_hz;
  std::optional<processing::RateEstimator> rate_estimator;
  double fixed_temperature_c = 0.0;
  if (!opt.model.empty()) {
    processing::RateEstimatorParameters p =
        recording::rateEstimatorParameters(recording::readSensorModelToml(opt.model));
    p.rate_hz = in.rate_hz;
    if (rec.temp.empty()) {
      fixed_temperature_c = p.axes[0].temperature_reference_c;
      std::fprintf(stderr, "%s has no temp column: the rate stream takes the model's reference temperature, %g C\n",
                   opt.file.c_str(), fixed_temperature_c);
    }
    params = recording::rateStreamAttitudeParameters(p);
    rate_estimator.emplace(p);
  }
  AttitudeEstimator estimator(params);

  const auto columns = passedThroughColumns(rec);
  std::string out;
  out.reserve(n * (columns.size() + 10) * 24 + 128);
  out += "t";
  for (const auto& c : columns) out += "," + c.first;
  out += ",qw,qx,qy,qz,roll,pitch,heading,inclination_std,heading_std\n";
  std::size_t rest_samples = 0;
  AttitudeSample last;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = rec.t.empty() ? static_cast<double>(i) * dt : rec.t[i];
    Vector3 rate{(*gyro[0])[i], (*gyro[1])[i], (*gyro[2])[i]};
    const Vector3 a{(*accel[0])[i], (*accel[1])[i], (*accel[2])[i]};
    if (rate_estimator) {
      rate_estimator->observeAccel(a);
      rate = rate_estimator->update(t, rate, rec.temp.empty() ? fixed_temperature_c : rec.temp[i]).rate_dps;
    }
    const AttitudeSample s = estimator.update(rate, a);
    last = s;
    if (s.rest) ++rest_samples;
    appendAttitudeNumber(out, t);
    for (const auto& c : columns) {
      out += ',';
      appendAttitudeNumber(out, (*c.second)[i]);
    }
    for (double v : {s.q[0], s.q[1], s.q[2], s.q[3], s.roll_deg, s.pitch_deg, s.heading_deg, s.inclination_std_deg,
                     s.heading_std_deg}) {
      out += ',';
      appendAttitudeNumber(out, v);
    }
    out += '\n';
  }
  formats::writeFileAtomically(opt.output, out, {opt.file, opt.model});
  if (rate_estimator)
    std::fprintf(stderr, "attitude from the rate stream of %s (%zu of %zu samples still)\n", opt.model.c_str(),
                 rate_estimator->updates(), n);
  else
    std::fprintf(stderr, "attitude from the raw gyro, its bias learned from the record (%zu of %zu samples at rest)\n",
                 rest_samples, n);
  const Vector3& sens = last.gyro_sensitivity_error;
  const Vector3& cross = last.gyro_cross_axis;
  const Vector3& lever = last.lever_arm_m;
  if (!rate_estimator && rest_samples == 0)
    std::fprintf(stderr, "learned in motion: nothing (no rest in the record, so the gyro bias is not known)\n");
  else
    std::fprintf(
        stderr,
        "learned in motion: gyro sensitivity error x %+.2f %%, y %+.2f %%, z %+.2f %%; cross-axis xy %+.2f %%, "
        "xz %+.2f %%, yz %+.2f %%; accel lever arm %+.3f, %+.3f, %+.3f m; accel delay %+.1f ms\n",
        100.0 * sens[0], 100.0 * sens[1], 100.0 * sens[2], 100.0 * cross[0], 100.0 * cross[1], 100.0 * cross[2],
        lever[0], lever[1], lever[2], 1e3 * last.accel_delay_s);
  std::fprintf(stderr, "wrote %zu samples to %s\n", n, opt.output.c_str());
  return kExitOk;
}

}  // namespace

void addAttitudeCommand(CLI::App& app, CommandRunner& run) {
  auto opt = std::make_shared<AttitudeOptions>();
  auto* sub = app.add_subcommand("attitude", "Estimate the orientation (quaternion, roll, pitch, heading) offline");
  sub->add_option("FILE", opt->file, "recording CSV with gx,gy,gz and ax,ay,az")->required();
  sub->add_option("-o,--output", opt->output,
                  "output CSV: the recording's columns, then qw,qx,qy,qz,roll,pitch,heading,inclination_std,"
                  "heading_std")
      ->required();
  sub->add_option("--rate", opt->rate_hz, "sample rate [Hz] (default: from t, else 50)")->check(CLI::PositiveNumber);
  sub->add_option("--model", opt->model,
                  "sensor model file (gyroctl analyze --write-model): run on the rate stream and its bias "
                  "instead of learning the bias from the record");
  sub->add_flag("--strict-timing", opt->strict_timing,
                "gaps or irregular spacing in t, or GAP/DROPPED records, are an error instead of a warning");
  sub->callback([&run, opt] { run = [opt] { return runAttitude(*opt); }; });
}

}  // namespace gyrod::gyroctl
