// gyroctl filter: the daemon's per-sample chain, offline: (detrend) → mean filter → Kalman;
// with --model also the rate stream (raw − b̂(t), processing::RateEstimator).
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "formats/calibration.hpp"
#include "formats/calibration_state.hpp"
#include "formats/output_file.hpp"
#include "formats/recording_header.hpp"
#include "processing/base/detrend.hpp"
#include "processing/motion/rate_estimator.hpp"
#include "processing/motion/still_detector.hpp"
#include "processing/paper/filter_chain.hpp"
#include "tools/gyroctl/commands.hpp"
#include "tools/gyroctl/input.hpp"
#include "tools/gyroctl/series_checks.hpp"

namespace gyrod::gyroctl {
namespace {

using namespace gyrod::processing;

// 17 significant digits: every double survives the text round trip exactly.
void appendNumber(std::string& out, double v) {
  char buf[32];
  const int n = std::snprintf(buf, sizeof buf, "%.17g", v);
  out.append(buf, static_cast<std::size_t>(n));
}

struct FilterOptions {
  std::string file;
  std::string output;
  std::optional<double> rate_hz;
  std::size_t mean_window = 20;
  double mean_threshold_dps = 0.3;
  std::optional<double> ar_phi, kalman_q, kalman_r;
  bool no_detrend = false;
  std::vector<double> bias_dps;  // --bias: subtract these constants instead of detrending
  std::string model;             // --model: add the rate stream's columns
  bool strict_timing = false;
};

// Identifying the Kalman filter from the file (the AR(1) fit of the mean-filtered series and
// the residual variance) needs as many samples as analyze's tables: from fewer, A, Q and R are
// noise. With --ar-phi, --kalman-q and --kalman-r all given nothing is identified, and the
// chain runs sample by sample as gyrod does, on any number of samples.
constexpr std::size_t kMinSamplesToIdentify = 100;

// The rate stream of a recording (--model): processing::RateEstimator fed with the raw
// columns, the t column, the temp column and, when the file has ax, ay and az, the accel, as
// gyrod feeds it (observeAccel, then update, per sample: daemon/sample_pipeline.cpp). Without
// the accel columns the still detector judges by the gyro alone, as gyrod with accel = false.
class RateColumns {
 public:
  RateColumns(const FilterOptions& opt, const recording::Recording& rec, double rate_hz)
      : rec_(rec), dt_(1.0 / rate_hz) {
    processing::RateEstimatorParameters p =
        recording::rateEstimatorParameters(recording::readSensorModelToml(opt.model));
    if (std::fabs(p.rate_hz - rate_hz) > 1e-9 * rate_hz)
      std::fprintf(stderr, "%s: model rate %g Hz, recording %g Hz: the rate stream runs at the recording's\n",
                   opt.model.c_str(), p.rate_hz, rate_hz);
    p.rate_hz = rate_hz;
    for (std::size_t slot = 0; slot < kMotionAxes; ++slot) {
      const std::string name(recording::kGyroColumns[slot]);
      const std::vector<double>* column = rec.axis(name);
      if (!column)
        throw recording::RecordingError(opt.file + ": --model needs the columns gx, gy and gz (the still detector " +
                                        "tests all three); '" + name + "' is missing");
      columns_[slot] = column;
    }
    if (rec.temp.empty()) {
      fixed_temperature_c_ = p.axes[0].temperature_reference_c;
      std::fprintf(stderr, "%s has no temp column: the rate stream takes the model's reference temperature, %g C\n",
                   opt.file.c_str(), fixed_temperature_c_);
    }
    has_accel_ = std::all_of(rec.accel_g.begin(), rec.accel_g.end(), [&](const auto& c) { return !c.empty(); });
    estimator_.emplace(p);
    startFromTheHeadersState(opt.file, p);
  }
  bool usesAccel() const { return has_accel_; }
  static void appendHeader(std::string& out, const recording::Recording& rec) {
    for (const auto& name : rec.axis_names) out += "," + name + "_rate," + name + "_bias";
    out += ",still";
  }
  void appendRow(std::string& out, std::size_t i) {
    AngularRate raw{};
    for (std::size_t slot = 0; slot < kMotionAxes; ++slot) raw[slot] = (*columns_[slot])[i];
    const double t = rec_.t.empty() ? static_cast<double>(i) * dt_ : rec_.t[i];
    if (has_accel_) estimator_->observeAccel({rec_.accel_g[0][i], rec_.accel_g[1][i], rec_.accel_g[2][i]});
    const RateSample s = estimator_->update(t, raw, rec_.temp.empty() ? fixed_temperature_c_ : rec_.temp[i]);
    for (const auto& name : rec_.axis_names) {
      const std::size_t slot = *recording::axisOfColumn(name);
      out += ',';
      appendNumber(out, s.rate_dps[slot]);
      out += ',';
      appendNumber(out, s.bias_dps[slot]);
    }
    out += s.still ? ",1" : ",0";
  }
  std::size_t stillSamples() const { return estimator_->updates(); }

 private:
  // A recording gyrod made after a restart says in its header which calibration state its rate
  // stream started from (docs/calibration-state.md): start from the same, so that the stream is
  // recomputed bit for bit. A state for another bias model than --model's is left out, said.
  void startFromTheHeadersState(const std::string& file, const processing::RateEstimatorParameters& p) {
    const recording::AcquisitionHeader header = recording::readAcquisitionHeader(file);
    if (header.calibration_state_line == 0) return;
    const std::string where = file + ":" + std::to_string(header.calibration_state_line);
    formats::CalibrationState state;
    try {
      state = formats::parseCalibrationStateToml(header.calibration_state_toml, where + " (calibration-state lines)");
    } catch (const formats::CalibrationStateError& e) {
      throw recording::RecordingError(e.what());
    }
    if (state.model != formats::biasModelFingerprint(p)) {
      std::fprintf(stderr,
                   "%s: the rate stream was started from a calibration state learned with another bias model "
                   "(fingerprint %s, --model's %s): starting from the model instead\n",
                   where.c_str(), state.model.c_str(), formats::biasModelFingerprint(p).c_str());
      return;
    }
    estimator_->startFrom(state.residual, 0.0);  // its variances already hold the time since it was written
    std::fprintf(stderr, "%s: the rate stream starts from the calibration state gyrod started from\n", where.c_str());
  }

  const recording::Recording& rec_;
  double dt_;
  std::array<const std::vector<double>*, kMotionAxes> columns_{};
  double fixed_temperature_c_ = 0.0;
  bool has_accel_ = false;
  std::optional<RateEstimator> estimator_;
};

// The share of samples the still detector (processing/motion/still_detector.hpp) judges moving,
// calibrated on the record itself, for a warning: A, Q and R identified from a record that is
// mostly motion describe the motion, not the sensor's noise. Each axis' white-noise level comes
// from the median absolute second difference of its samples (smooth motion hardly moves it; for
// white noise the second difference has variance 6σ²), the bias from the median. The mean test
// is widened to about 1 °/s (P below), so that a bias that drifts with temperature is not taken
// for motion; the difference test sees anything that changes from sample to sample.
double movingShare(const recording::Recording& rec, double rate_hz) {
  StillDetectorParameters params;
  params.window_samples = std::max<std::size_t>(3, static_cast<std::size_t>(std::lround(0.5 * rate_hz)));
  const std::size_t n = rec.size();
  if (n < params.window_samples + 2) return 0.0;
  std::array<StillNoiseLevel, kMotionAxes> levels;
  levels.fill({1.0, 1.0});  // an axis the file lacks is fed zeros: it always passes
  std::array<const std::vector<double>*, kMotionAxes> columns{};
  AngularRate bias{};
  for (std::size_t i = 0; i < rec.axis_names.size(); ++i) {
    const auto axis = recording::axisOfColumn(rec.axis_names[i]);
    if (!axis) continue;
    const auto& x = rec.axes[i];
    std::vector<double> work(n - 2);
    double mean_square = 0.0;
    for (std::size_t k = 1; k + 1 < n; ++k) {
      const double d2 = x[k + 1] - 2.0 * x[k] + x[k - 1];
      work[k - 1] = std::abs(d2);
      mean_square += d2 * d2 / static_cast<double>(n - 2);
    }
    const auto middle = work.begin() + static_cast<std::ptrdiff_t>(work.size() / 2);
    std::nth_element(work.begin(), middle, work.end());
    const double robust_sigma = 1.4826 * *middle;
    // A coarsely quantised still axis can have a median of 0: the mean square then.
    const double variance = robust_sigma > 0.0 ? robust_sigma * robust_sigma / 6.0 : mean_square / 6.0;
    if (!(variance > 0.0) || !std::isfinite(variance)) continue;  // a constant axis: nothing moves
    levels[*axis] = {variance / static_cast<double>(params.window_samples), variance};
    work.assign(x.begin(), x.end());
    const auto half = work.begin() + static_cast<std::ptrdiff_t>(n / 2);
    std::nth_element(work.begin(), half, work.end());
    bias[*axis] = *half;
    columns[*axis] = &x;
  }
  StillDetector detector(params, levels);
  constexpr double kBiasDriftVariance = 1.0 / 9.0;  // z·√P = 1 °/s at z = 3
  const AngularRate expected{};
  const AngularRate expected_variance{kBiasDriftVariance, kBiasDriftVariance, kBiasDriftVariance};
  std::size_t judged = 0, moving = 0;
  for (std::size_t k = 0; k < n; ++k) {
    AngularRate c{};
    for (std::size_t a = 0; a < kMotionAxes; ++a)
      if (columns[a]) c[a] = (*columns[a])[k] - bias[a];
    const bool still = detector.update(c, expected, expected_variance);
    if (k + 1 < params.window_samples) continue;  // no verdict before the first full window
    ++judged;
    if (!still) ++moving;
  }
  return judged == 0 ? 0.0 : static_cast<double>(moving) / static_cast<double>(judged);
}

// Above this share of moving samples, filter warns that the identified Kalman is meaningless.
constexpr double kMostlyMovingShare = 0.5;

int runFilter(const FilterOptions& opt) {
  if (opt.kalman_q && !(*opt.kalman_q >= 0.0)) throw std::invalid_argument("--kalman-q must be >= 0");
  if (opt.kalman_r && !(*opt.kalman_r >= 0.0)) throw std::invalid_argument("--kalman-r must be >= 0");
  if (opt.ar_phi && !std::isfinite(*opt.ar_phi)) throw std::invalid_argument("--ar-phi must be a finite number");
  formats::checkOutputTarget(opt.output, {opt.file});  // before the work, and again when writing
  LoadedInput in = loadInput(opt.file, opt.rate_hz, "all");
  const auto& rec = in.recording;
  if (!opt.bias_dps.empty() && opt.bias_dps.size() != rec.axes.size()) {
    std::ostringstream s;
    s << "--bias has " << opt.bias_dps.size() << " value(s) but " << opt.file << " has " << rec.axes.size()
      << " gyro column(s)";
    throw std::invalid_argument(s.str());
  }
  for (double b : opt.bias_dps)
    if (!std::isfinite(b)) throw std::invalid_argument("--bias values must be finite numbers");
  const std::size_t n = rec.size();
  const double dt = 1.0 / in.rate_hz;
  for (std::size_t axis = 0; axis < rec.axes.size(); ++axis) requireAnalysableValues(rec, axis);
  std::optional<RateColumns> rate_columns;  // first, so that a bad --model fails before any work
  if (!opt.model.empty()) rate_columns.emplace(opt, rec, in.rate_hz);
  const bool identifies = !(opt.ar_phi && opt.kalman_q && opt.kalman_r);
  if (identifies && n < kMinSamplesToIdentify) {
    std::ostringstream s;
    s << opt.file << ": " << n << " samples are too few to identify the filter (need at least " << kMinSamplesToIdentify
      << ", or give --ar-phi, --kalman-q and --kalman-r)";
    throw recording::RecordingError(s.str());
  }
  reportTiming(opt.file, checkTiming(rec, opt.rate_hz), opt.strict_timing);

  std::vector<std::vector<double>> chain_input;
  std::vector<FilterChainParameters> params;
  for (std::size_t axis = 0; axis < rec.axes.size(); ++axis) {
    std::vector<double> x = rec.axes[axis];
    if (!opt.bias_dps.empty()) {
      for (double& v : x) v -= opt.bias_dps[axis];  // as gyrod does: a constant bias, no trend
    } else if (!opt.no_detrend) {
      removeLinearTrend(x, dt);
    }
    try {
      params.push_back(identifyFilterChain(x, opt.mean_window, opt.mean_threshold_dps,
                                           KalmanOverrides{opt.ar_phi, opt.kalman_q, opt.kalman_r}));
    } catch (const std::invalid_argument& e) {
      throw recording::RecordingError(opt.file + ": column '" + rec.axis_names[axis] +
                                      "': cannot identify the filter: " + e.what());
    }
    chain_input.push_back(std::move(x));
  }

  std::string out;
  out.reserve(n * (1 + 3 * rec.axes.size()) * 24 + 64);
  out += "t";
  for (const auto& name : rec.axis_names) out += "," + name + "," + name + "_mean," + name + "_kalman";
  if (rate_columns) RateColumns::appendHeader(out, rec);
  out += '\n';
  std::vector<AxisFilterChain> chains;
  chains.reserve(params.size());
  for (const auto& p : params) chains.emplace_back(p);
  for (std::size_t i = 0; i < n; ++i) {
    appendNumber(out, rec.t.empty() ? static_cast<double>(i) * dt : rec.t[i]);
    for (std::size_t axis = 0; axis < chains.size(); ++axis) {
      const double x = chain_input[axis][i];
      const FilteredRate f = chains[axis].update(x);
      out += ',';
      appendNumber(out, x);
      out += ',';
      appendNumber(out, f.mean_dps);
      out += ',';
      appendNumber(out, f.kalman_dps);
    }
    if (rate_columns) rate_columns->appendRow(out, i);
    out += '\n';
  }
  formats::writeFileAtomically(opt.output, out, {opt.file, opt.model});

  for (std::size_t axis = 0; axis < params.size(); ++axis) {
    const auto& k = params[axis].kalman;
    std::fprintf(stderr, "%s: L = %zu, r = %g deg/s, A = %.6g, Q = %.6g, R = %.6g%s\n", rec.axis_names[axis].c_str(),
                 params[axis].mean_window, params[axis].mean_threshold_dps, k.a, k.q, k.r,
                 opt.ar_phi || opt.kalman_q || opt.kalman_r ? " (some given on the command line)"
                                                            : " (identified from the file)");
  }
  if (identifies) {
    const double share = movingShare(rec, in.rate_hz);
    if (share > kMostlyMovingShare)
      std::fprintf(stderr,
                   "gyroctl filter: warning: %s: the still detector finds the record moving in %.0f %% of its "
                   "samples; A, Q and R identified from it describe the motion, not the sensor's noise. Identify "
                   "them on a still record (gyroctl analyze --write-model sensor.toml) and use the rate column of "
                   "--model sensor.toml, or give --ar-phi, --kalman-q and --kalman-r\n",
                   opt.file.c_str(), 100.0 * share);
  }
  if (rate_columns)
    std::fprintf(stderr, "rate stream from %s: %zu of %zu samples still (they updated the residual bias); %s\n",
                 opt.model.c_str(), rate_columns->stillSamples(), n,
                 rate_columns->usesAccel() ? "the still detector used the ax, ay, az columns"
                                           : "no ax, ay, az columns: the still detector judged by the gyro alone");
  std::fprintf(stderr, "wrote %zu samples to %s\n", n, opt.output.c_str());
  return kExitOk;
}

}  // namespace

void addFilterCommand(CLI::App& app, CommandRunner& run) {
  auto opt = std::make_shared<FilterOptions>();
  auto* sub =
      app.add_subcommand("filter", "Run the daemon's per-sample chain offline: (detrend) -> mean filter -> Kalman");
  sub->add_option("FILE", opt->file, "recording CSV (as for analyze)")->required();
  sub->add_option("-o,--output", opt->output, "output CSV: t, then gx,gx_mean,gx_kalman per axis")->required();
  sub->add_option("--rate", opt->rate_hz, "sample rate [Hz] (default: from t, else 50)");
  sub->add_option("--mean-window", opt->mean_window, "mean filter window L [samples]")
      ->default_val(20)
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000}));
  sub->add_option("--mean-threshold", opt->mean_threshold_dps, "gross-error threshold r [deg/s]")
      ->default_val(0.3)
      ->check(CLI::PositiveNumber);
  sub->add_option("--ar-phi", opt->ar_phi, "Kalman A = phi1 (default: AR(1) fit of the mean-filtered series)");
  sub->add_option("--kalman-q", opt->kalman_q, "Kalman Q [(deg/s)^2] (default: AR(1) noise variance)");
  sub->add_option("--kalman-r", opt->kalman_r, "Kalman R [(deg/s)^2] (default: var(x - mean-filtered x))");
  auto* no_detrend = sub->add_flag("--no-detrend", opt->no_detrend, "feed the raw input to the mean filter");
  sub->add_option("--bias", opt->bias_dps,
                  "subtract these constants [deg/s], one per gyro column, instead of detrending (as gyrod does)")
      ->delimiter(',')
      ->excludes(no_detrend);
  sub->add_flag("--strict-timing", opt->strict_timing,
                "gaps or irregular spacing in t, or GAP/DROPPED records, are an error instead of a warning");
  sub->add_option("--model", opt->model,
                  "sensor model file (gyroctl analyze --write-model): add gx_rate,gx_bias per axis and still, "
                  "the rate stream of processing::RateEstimator (docs/calibration.md)");
  sub->callback([&run, opt] { run = [opt] { return runFilter(*opt); }; });
}

}  // namespace gyrod::gyroctl
