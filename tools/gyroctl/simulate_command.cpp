// gyroctl simulate: a recording of the simulated gyro (docs/simulator.md), as the CSV that
// analyze/filter read: t,gx,gy,gz,temp; with --motion, turned by a motion spec
// (formats/motion_spec.hpp) and followed by the truth wx,wy,wz that any stream can be scored on;
// with --accel, the accelerometer ax,ay,az [g] after temp (gravity at the attitude the motion
// turns the board to, plus the accel noise terms).
#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "formats/model_toml.hpp"
#include "formats/motion_spec.hpp"
#include "formats/output_file.hpp"
#include "processing/simulation/noise_simulator.hpp"
#include "tools/gyroctl/commands.hpp"

namespace gyrod::gyroctl {
namespace {

using namespace gyrod::processing;

struct SimulateOptions {
  std::string model_file;
  std::optional<double> quantization, arw, bias_instability, rrw, rate_ramp;
  double duration_s = 0.0;
  std::optional<double> rate_hz;
  std::uint64_t seed = 1;
  std::optional<int> dlpf, fs_sel;
  std::string warm_up;                  // DELTA_C,TAU_S; empty: the model's temperature curve
  std::string temperature_coefficient;  // K or KX,KY,KZ [°/s per °C]; empty: the model's coupling
  std::string motion;                   // empty: at rest, and no truth columns (the output stays as it always was)
  // --accel: ax,ay,az columns. Without it nothing of the accel is computed or written.
  bool accel = false;
  double accel_noise_density = 4e-4;  // N [g/√Hz]: the product spec's 400 µg/√Hz (§6.2)
  double accel_bias_instability = 0.0;
  double accel_random_walk = 0.0;
  std::string accel_bias;  // B or BX,BY,BZ [g]; empty: 0
  int accel_range_g = 2;
  std::string output;
};

// The bound on what simulate writes (README "gyroctl simulate"): at most this long, and
// never more than the target's filesystem has free, so a mistyped --duration cannot fill a disk.
constexpr double kMaxSimulateDurationS = 1e7;  // about 116 days
// A line is five %.17g numbers: each at most 24 characters ("-1.2345678901234567e-308"),
// four commas and a newline. The estimate is an upper bound, real lines are a little shorter.
constexpr std::uint64_t kMaxSimulateLineBytes = 5 * 24 + 5;
constexpr std::uint64_t kMaxSimulateLineBytesWithTruth = 8 * 24 + 8;  // + wx,wy,wz
constexpr std::uint64_t kAccelLineBytes = 3 * 24 + 3;                 // + ax,ay,az
constexpr std::size_t kSamplesBetweenWriteChecks = 1 << 16;

std::string byteCount(double bytes) {
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  std::size_t u = 0;
  while (bytes >= 1000.0 && u + 1 < std::size(units)) {
    bytes /= 1000.0;
    ++u;
  }
  char buf[48];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.3g %s", bytes, units[u]);
  return buf;
}

void requireDurationWithinBound(double duration_s) {
  if (duration_s > kMaxSimulateDurationS) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "--duration %g s is longer than simulate writes (at most %g s)", duration_s,
                  kMaxSimulateDurationS);
    throw std::invalid_argument(buf);
  }
}

// Refuses before writing when the recording cannot fit on the target's filesystem.
void requireRoomFor(std::uint64_t samples, std::uint64_t line_bytes, const formats::AtomicOutputFile& out) {
  const double needed = static_cast<double>(samples) * static_cast<double>(line_bytes) + 64.0;
  const std::uint64_t available = out.availableBytes();
  if (needed > static_cast<double>(available))
    throw ExitError(ExitCode::CantCreate, out.target() + ": " + std::to_string(samples) + " samples need up to " +
                                              byteCount(needed) + " (" + std::to_string(line_bytes) +
                                              " bytes a line) but its filesystem has " +
                                              byteCount(static_cast<double>(available)) + " free");
}

int runSimulate(const SimulateOptions& opt) {
  SimulationModel model;
  if (!opt.model_file.empty()) {
    model = recording::readModelToml(opt.model_file);
  } else {
    // Terms from the command line, the same on all three axes.
    for (AxisNoiseModel& axis : model.axes) {
      axis.terms.quantization_urad = opt.quantization.value_or(0.0);
      axis.terms.arw_deg_per_sqrt_h = opt.arw.value_or(0.0);
      axis.terms.bias_instability_deg_per_h = opt.bias_instability.value_or(0.0);
      axis.terms.rrw_deg_per_h_sqrt_h = opt.rrw.value_or(0.0);
      axis.terms.rate_ramp_deg_per_h2 = opt.rate_ramp.value_or(0.0);
    }
  }
  // Command-line sensor options override the file's.
  if (opt.rate_hz) model.rate_hz = *opt.rate_hz;
  if (opt.dlpf) model.dlpf_cfg = *opt.dlpf;
  if (opt.fs_sel) model.fs_sel = *opt.fs_sel;
  if (!opt.warm_up.empty()) model.temperature = withWarmUp(model.temperature, recording::parseWarmUpSpec(opt.warm_up));
  if (!opt.temperature_coefficient.empty()) {
    const auto k = recording::parseAxisValues(opt.temperature_coefficient, "--temperature-coefficient");
    for (std::size_t a = 0; a < kSimulatedAxes; ++a) model.axes[a].extra.temperature_coefficient_dps_per_c = k[a];
  }

  if (opt.accel) {
    AccelModel accel;
    const int ranges[] = {2, 4, 8, 16};
    const auto range = std::find(std::begin(ranges), std::end(ranges), opt.accel_range_g);
    if (range == std::end(ranges))
      throw std::invalid_argument("--accel-range-g must be 2, 4, 8 or 16, got " + std::to_string(opt.accel_range_g));
    accel.afs_sel = static_cast<int>(range - std::begin(ranges));
    const std::array<double, kSimulatedAxes> bias = opt.accel_bias.empty()
                                                        ? std::array<double, kSimulatedAxes>{}
                                                        : recording::parseAxisValues(opt.accel_bias, "--accel-bias");
    for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
      accel.axes[a].bias_g = bias[a];
      accel.axes[a].velocity_random_walk_g_per_sqrt_hz = opt.accel_noise_density;
      accel.axes[a].bias_instability_g = opt.accel_bias_instability;
      accel.axes[a].acceleration_random_walk_g_per_sqrt_s = opt.accel_random_walk;
    }
    model.accel = accel;
  }

  requireDurationWithinBound(opt.duration_s);
  // Both validate: std::invalid_argument (bad model or profile text) and RecordingError (bad
  // motion CSV) → exit 2.
  const bool with_motion = !opt.motion.empty();
  NoiseSimulator sim = with_motion
                           ? NoiseSimulator(model, opt.duration_s, opt.seed, recording::motionFromSpec(opt.motion))
                           : NoiseSimulator(model, opt.duration_s, opt.seed);
  std::vector<std::string> inputs{opt.model_file};
  if (with_motion && !recording::isMotionProfileText(opt.motion)) inputs.push_back(opt.motion);
  formats::AtomicOutputFile out(opt.output, inputs);
  const std::uint64_t n = sim.sampleCount();
  requireRoomFor(
      n, (with_motion ? kMaxSimulateLineBytesWithTruth : kMaxSimulateLineBytes) + (opt.accel ? kAccelLineBytes : 0),
      out);
  std::FILE* f = out.stream();
  std::fputs("t,gx,gy,gz,temp", f);
  if (opt.accel) std::fputs(",ax,ay,az", f);
  std::fputs(with_motion ? ",wx,wy,wz\n" : "\n", f);
  for (std::uint64_t i = 0; i < n; ++i) {
    // Stop at the first failed write (a full disk) instead of computing the rest.
    if (i % kSamplesBetweenWriteChecks == 0 && out.failed()) break;
    const SimulatedSample s = sim.next();
    // 17 significant digits: every double survives the text round trip exactly.
    std::fprintf(f, "%.17g,%.17g,%.17g,%.17g,%.17g", s.t_s, s.rate_dps[0], s.rate_dps[1], s.rate_dps[2],
                 s.temperature_c);
    if (opt.accel) std::fprintf(f, ",%.17g,%.17g,%.17g", s.accel_g[0], s.accel_g[1], s.accel_g[2]);
    if (with_motion) std::fprintf(f, ",%.17g,%.17g,%.17g", s.true_rate_dps[0], s.true_rate_dps[1], s.true_rate_dps[2]);
    std::fputc('\n', f);
  }
  out.commit();
  // n is 64-bit on every ABI (a long simulation overflows a 32-bit size_t): %llu, not %zu,
  // which on armhf read the wrong varargs and crashed in strlen.
  std::fprintf(stderr, "wrote %llu samples at %g Hz (%s%s, seed %llu) to %s\n", static_cast<unsigned long long>(n),
               model.rate_hz, model.dlpf_cfg ? ("DLPF_CFG " + std::to_string(*model.dlpf_cfg)).c_str() : "no DLPF",
               model.fs_sel ? (", FS_SEL " + std::to_string(*model.fs_sel)).c_str() : ", not quantised",
               static_cast<unsigned long long>(opt.seed), opt.output.c_str());
  return kExitOk;
}

}  // namespace

void addSimulateCommand(CLI::App& app, CommandRunner& run) {
  auto opt = std::make_shared<SimulateOptions>();
  auto* sub =
      app.add_subcommand("simulate",
                         "Write a simulated MPU6050 recording (t,gx,gy,gz,temp; with --motion also the truth wx,wy,wz) "
                         "from a noise model");
  auto* model = sub->add_option("--model", opt->model_file, "model file (TOML, see docs/simulator.md)");
  auto* terms = sub->add_option_group("terms", "noise terms on all three axes (instead of --model)");
  auto* q = terms->add_option("--quantization", opt->quantization, "quantization noise Q [urad]");
  auto* n = terms->add_option("--arw", opt->arw, "angle random walk N [deg/sqrt(h)]");
  auto* b = terms->add_option("--bias-instability", opt->bias_instability, "bias instability B [deg/h]");
  auto* k = terms->add_option("--rrw", opt->rrw, "rate random walk K [deg/h^1.5]");
  auto* r = terms->add_option("--rate-ramp", opt->rate_ramp, "rate ramp R [deg/h^2]");
  for (CLI::Option* o : {q, n, b, k, r}) o->excludes(model);
  sub->add_option("--duration", opt->duration_s, "length [s], at most 1e7 and what fits on the target's disk")
      ->required()
      ->check(CLI::PositiveNumber);
  sub->add_option("--rate", opt->rate_hz, "output rate [Hz] (default: the model file's, else 50)");
  sub->add_option("--seed", opt->seed, "random seed (same seed, same file on every machine)")->default_val(1);
  sub->add_option("--dlpf", opt->dlpf, "DLPF_CFG 0..6 (default: the model file's, else no DLPF)");
  sub->add_option("--fs-sel", opt->fs_sel, "FS_SEL 0..3: quantise and saturate (default: the model file's, else not)");
  sub->add_option("--warm-up", opt->warm_up,
                  "DELTA_C,TAU_S[,START_S]: the die temperature rises by DELTA_C from the model's start with time "
                  "constant TAU_S (from START_S on); the bias follows through the temperature coupling "
                  "(docs/simulator.md)");
  sub->add_option("--temperature-coefficient", opt->temperature_coefficient,
                  "K or KX,KY,KZ [deg/s per C]: the bias's temperature coupling (reference: the model's, 25 C)");
  sub->add_option("--motion", opt->motion,
                  "true rotation: profiles such as step:axis=z,at=5,rate=10 (summed with +), or a CSV t,wx,wy,wz; "
                  "adds the truth columns wx,wy,wz (docs/simulator.md)");
  auto* accel =
      sub->add_flag("--accel", opt->accel,
                    "also write the accelerometer ax,ay,az [g] after temp: gravity at the attitude integrated "
                    "from the motion's true rates, plus the accel noise terms (docs/simulator.md)");
  sub->add_option("--accel-noise-density", opt->accel_noise_density,
                  "accel white noise N [g/sqrt(Hz)] (velocity random walk; default 4e-4, the product spec's)")
      ->check(CLI::NonNegativeNumber)
      ->needs(accel);
  sub->add_option("--accel-bias-instability", opt->accel_bias_instability, "accel bias instability B [g] (default 0)")
      ->check(CLI::NonNegativeNumber)
      ->needs(accel);
  sub->add_option("--accel-random-walk", opt->accel_random_walk,
                  "accel random walk K [g/sqrt(s)] (acceleration random walk; default 0)")
      ->check(CLI::NonNegativeNumber)
      ->needs(accel);
  sub->add_option("--accel-bias", opt->accel_bias, "B or BX,BY,BZ [g]: constant accel bias (default 0)")->needs(accel);
  sub->add_option("--accel-range-g", opt->accel_range_g,
                  "accel full scale 2, 4, 8 or 16 g (AFS_SEL), used with --fs-sel")
      ->needs(accel);
  sub->add_option("-o,--output", opt->output, "output CSV")->required();
  sub->callback([&run, opt] { run = [opt] { return runSimulate(*opt); }; });
}

}  // namespace gyrod::gyroctl
