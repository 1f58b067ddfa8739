// gyroctl analyze: every table of the paper for each axis of a static recording.
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <iostream>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "formats/calibration.hpp"
#include "formats/kalibr_yaml.hpp"
#include "formats/model_toml.hpp"
#include "formats/output_file.hpp"
#include "processing/allan/allan.hpp"
#include "processing/allan/noise_fit.hpp"
#include "processing/base/detrend.hpp"
#include "processing/base/noise_terms.hpp"
#include "processing/base/noise_units.hpp"
#include "processing/base/parallel_share.hpp"
#include "processing/motion/warm_up_fit.hpp"
#include "processing/paper/axis_analysis.hpp"
#include "protocol/allan_table.hpp"
#include "tools/gyroctl/analyze_imu.hpp"
#include "tools/gyroctl/commands.hpp"
#include "tools/gyroctl/input.hpp"
#include "tools/gyroctl/series_checks.hpp"

namespace gyrod::gyroctl {
namespace {

using namespace gyrod::processing;
using nlohmann::json;

// Fewer samples than this cannot carry the tests (100 reverse-arrangement segments
// need ≥ 10 samples each to mean anything) nor a useful Allan curve.
constexpr std::size_t kMinimumSamples = 100;
// Consumes the column unless `keep` (the model's calibration reads it again): the analysis
// then works in the column's own memory. Every column shares `workspace` (the Allan tables'
// phase and the filter outputs), whose pages are then allocated and cleared once.
AxisAnalysis analyzeColumn(recording::Recording& rec, std::size_t axis_index, const AnalysisOptions& options, bool keep,
                           processing::AllanWorkspace& workspace) {
  try {
    std::vector<double> column =
        keep ? rec.axes[axis_index] : std::exchange(rec.axes[axis_index], std::vector<double>());
    return analyzeAxis(std::move(column), options, workspace);
  } catch (const std::invalid_argument& e) {
    throw recording::RecordingError(rec.path + ": column '" + rec.axis_names[axis_index] + "': " + e.what());
  }
}

// Without --write-model the analysis needs only the gyro columns: the others are freed
// before it starts, so that the peak memory is the analysis's own.
void releaseColumnsNotAnalysed(recording::Recording& rec) {
  rec.t = std::vector<double>();
  rec.temp = std::vector<double>();
  for (auto& truth : rec.true_rate) truth = std::vector<double>();
}

// GYROD_ANALYZE_TIMING=1: each step's wall and process CPU seconds on stderr, as it ends
// (bench/measure_analyze.sh --steps), to see where the time goes and where a core idles.
// With two axes analysed at once, a line's times run from the line before it, whichever
// axis printed that one.
class StepTimer {
 public:
  StepTimer() : enabled_(std::getenv("GYROD_ANALYZE_TIMING") != nullptr) { last_ = now(); }
  bool enabled() const { return enabled_; }
  void operator()(const std::string& step) {
    if (!enabled_) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    const Times t = now();
    const double wall = t.wall - last_.wall, cpu = t.cpu - last_.cpu;
    std::fprintf(stderr, "step %-36s wall %7.3f s  cpu %7.3f s  cpu/wall %4.2f\n", step.c_str(), wall, cpu,
                 wall > 0.0 ? cpu / wall : 0.0);
    last_ = t;
  }

 private:
  struct Times {
    double wall = 0.0, cpu = 0.0;
  };
  static double seconds(clockid_t clock) {
    timespec ts{};
    clock_gettime(clock, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }
  static Times now() { return {seconds(CLOCK_MONOTONIC), seconds(CLOCK_PROCESS_CPUTIME_ID)}; }
  bool enabled_;
  std::mutex mutex_;
  Times last_;
};

// The unit of a column's values, for key names ("dps", "g") and for text ("deg/s", "g").
const char* unitKey(SensorKind s) { return s == SensorKind::Accel ? "g" : "dps"; }
const char* unitText(SensorKind s) { return s == SensorKind::Accel ? "g" : "deg/s"; }

struct AnalyzeOptions {
  std::string file;
  std::optional<double> rate_hz;
  std::string axis = "all";
  std::string taus = "octave";
  bool no_detrend = false;
  bool json = false;
  bool strict_timing = false;
  std::size_t mean_window = 20;
  double mean_threshold_dps = 0.3;
  double accel_mean_threshold_g = 0.05;
  std::size_t max_ar_order = 3;
  std::string write_model;
  KalibrOptions kalibr;
};

std::vector<double> parseTauList(const std::string& text) {
  std::vector<double> taus;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v) || v <= 0.0)
      throw std::invalid_argument("--taus: '" + item +
                                  "' is not a positive number of seconds (use octave, dense or a list like 1,10,100)");
    taus.push_back(v);
  }
  if (taus.empty()) throw std::invalid_argument("--taus: empty list");
  return taus;
}

std::vector<std::size_t> clusterSizesFor(const std::string& spec, double rate_hz, std::size_t n) {
  if (spec == "octave") return octaveClusterSizes(n);
  if (spec == "dense") return denseClusterSizes(n);
  auto taus = parseTauList(spec);
  // A τ between two whole numbers of samples (a rate such as 100.31 Hz puts every round τ
  // there) is taken at the nearest one, and the τ used is said: the tables show it too.
  const double tau0 = 1.0 / rate_hz;
  for (double& tau : taus) {
    const double samples = tau / tau0;
    const double whole = std::round(samples);
    if (whole < 1.0 || std::abs(samples - whole) <= 1e-9 * samples) continue;
    const double used = whole * tau0;
    std::fprintf(
        stderr,
        "gyroctl analyze: --taus %g s is %.6g samples at %g Hz: using the nearest whole number, m = %.0f, tau = %.6g s\n",
        tau, samples, rate_hz, whole, used);
    tau = used;
  }
  try {
    return clusterSizesForTaus(taus, tau0, n);
  } catch (const std::invalid_argument& e) {
    std::ostringstream s;
    s << "--taus: " << e.what() << " (sample rate " << rate_hz << " Hz)";
    throw std::invalid_argument(s.str());
  }
}

// Each term in the paper's units (or the accelerometer's counterparts) and in SI
// (processing/base/noise_units.hpp names the keys).
json noiseTermsJson(const NoiseTerms& t, SensorKind sensor) {
  json j = json::object();
  for (NoiseTerm term : kAllNoiseTerms)
    for (const auto& figure : noiseFigures(term, t.get(term), sensor)) j[std::string(figure.key)] = figure.value;
  return j;
}

// The shared shape of an Allan table (protocol/allan_table.hpp), as the ALLAN reply sends it.
json allanJson(const std::vector<AllanPoint>& curve) { return json(protocol::allanTableJson(curve)); }

json axisJson(const AxisAnalysis& a, SensorKind sensor) {
  const std::string unit = unitKey(sensor);
  json j;
  j["unit"] = unitText(sensor);
  j["samples"] = a.samples;
  j["tests"] = {{"mean", a.zero_mean.mean},
                {"mean_z", a.zero_mean.z},
                {"zero_mean", a.zero_mean.zero_mean},
                {"reverse_arrangements_u", a.reverse_arrangements.u},
                {"reverse_arrangements_segments", a.reverse_arrangements.segments},
                {"stationary", a.reverse_arrangements.stationary},
                {"chi2", a.normality.chi2},
                {"chi2_dof", a.normality.dof},
                {"chi2_critical", a.normality.critical},
                {"chi2_p", a.normality.p_value},
                {"normal", a.normality.normal}};
  j["trend_removed"] = {{"offset_" + unit, a.trend_removed.offset},
                        {"slope_" + unit + "_per_s", a.trend_removed.slope_per_s}};
  j["allan"] = allanJson(a.allan);
  j["noise"] = noiseTermsJson(a.noise.value, sensor);
  j["noise_uncertainty"] = noiseTermsJson(a.noise.uncertainty, sensor);
  j["noise_fit_reduced_chi2"] = a.noise.reduced_chi2;
  j["noise_from_slopes"] = noiseTermsJson(a.noise_from_slopes, sensor);
  json ar = json::array();
  for (const auto& m : a.ar)
    ar.push_back({{"order", m.order()},
                  {"phi", m.phi},
                  {"phi_std_error", m.phi_std_error},
                  {"noise_var", m.noise_var},
                  {"aic", m.aic},
                  {"bic", m.bic}});
  j["ar"] = ar;
  j["ar_order_aic"] = a.ar_order_aic;
  j["ar_order_bic"] = a.ar_order_bic;
  j["mean_filter"] = {{"window", a.filter.mean_window}, {"threshold_" + unit, a.filter.mean_threshold_dps}};
  j["kalman"] = {{"a", a.filter.kalman.a},
                 {"q", a.filter.kalman.q},
                 {"r", a.filter.kalman.r},
                 {"p0", a.filter.kalman.p0},
                 {"steady_state_gain", a.steady_state_gain}};
  j["variance"] = {{"raw", a.variance.raw}, {"mean", a.variance.mean}, {"kalman", a.variance.kalman}};
  j["peak_ratio"] = a.peak_ratio;
  j["allan_after_kalman"] = allanJson(a.allan_after_kalman);
  j["noise_after_kalman"] = noiseTermsJson(a.noise_after_kalman.value, sensor);
  return j;
}

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

// A noise term is never shown without its uncertainty: "value +- 1 sigma", or a mark.
std::string termWithUncertainty(double value, double sigma) {
  char text[64];
  if (!std::isfinite(value) || !std::isfinite(sigma))
    std::snprintf(text, sizeof text, "%27s", "not enough data");
  else
    std::snprintf(text, sizeof text, "%12.5g +- %-11.3g", value, sigma);
  return text;
}

// Table 2 (or 4) lines of one term: one per figure (the paper's units, then SI).
void printTermLines(std::ostream& o, NoiseTerm t, SensorKind sensor, const AxisAnalysis& a) {
  char line[256];
  const auto values = noiseFigures(t, a.noise.value.get(t), sensor);
  const auto sigmas = noiseFigures(t, a.noise.uncertainty.get(t), sensor);
  const auto slopes = noiseFigures(t, a.noise_from_slopes.get(t), sensor);
  for (std::size_t f = 0; f < values.size(); ++f) {
    std::snprintf(line, sizeof line, "  %-42s %s | %12.5g\n", std::string(values[f].label).c_str(),
                  termWithUncertainty(values[f].value, sigmas[f].value).c_str(), slopes[f].value);
    o << line;
  }
}

void printAxisText(std::ostream& o, const std::string& name, const AxisAnalysis& a) {
  char line[256];
  const SensorKind sensor = sensorOfColumn(name);
  const char* unit = unitText(sensor);
  o << "\n== " << name << " ==\n";
  o << "Tests on the raw series (5 % level)\n";
  std::snprintf(line, sizeof line, "  zero mean     mean = %.6g %s, z = %.3f  -> %s\n", a.zero_mean.mean, unit,
                a.zero_mean.z, a.zero_mean.zero_mean ? "zero mean" : "non-zero mean");
  o << line;
  std::snprintf(line, sizeof line,
                "  stationarity  reverse arrangements over %zu segments: u = %.4f (|u| < 1.96)  -> %s\n",
                a.reverse_arrangements.segments, a.reverse_arrangements.u,
                a.reverse_arrangements.stationary ? "stationary" : "not stationary");
  o << line;
  std::snprintf(line, sizeof line, "  normality     chi2 = %.3f, dof = %zu, critical %.3f, p = %.3g  -> %s\n",
                a.normality.chi2, a.normality.dof, a.normality.critical, a.normality.p_value,
                a.normality.normal ? "normal" : "not normal");
  o << line;
  if (a.trend_removed.offset != 0.0 || a.trend_removed.slope_per_s != 0.0) {
    std::snprintf(line, sizeof line, "Removed: constant %.6g %s and trend %.6g %s per s\n", a.trend_removed.offset,
                  unit, a.trend_removed.slope_per_s, unit);
    o << line;
  }

  o << "\nAllan deviation (" << unit << "; overlapping with 68.3 % chi2 interval)\n";
  o << "      tau [s]        m         adev        oadev     oadev_lo     oadev_hi    terms  alpha\n";
  for (const auto& p : a.allan) {
    std::snprintf(line, sizeof line, "  %11.4f %8zu %12.5g %12.5g %12.5g %12.5g %8zu %6d\n", p.tau_s, p.m, p.adev,
                  p.oadev, p.oadev_lo, p.oadev_hi, p.oadev_terms, p.noise_alpha);
    o << line;
  }

  o << "\nTable 2: noise terms (weighted fit +- 1 sigma | slope-line reading, a cross-check without uncertainty)\n";
  for (NoiseTerm t : kAllNoiseTerms) printTermLines(o, t, sensor, a);

  o << "\nTable 3: AR models of the mean-filtered series (Yule-Walker)\n";
  o << "              ";
  for (const auto& m : a.ar) o << "       AR(" << m.order() << ")";
  o << '\n';
  for (std::size_t k = 0; k < a.ar.size(); ++k) {
    std::snprintf(line, sizeof line, "  phi%-9zu", k + 1);
    o << line;
    for (const auto& m : a.ar) o << format(" %12.4f", k < m.phi.size() ? m.phi[k] : 0.0);
    o << '\n';
  }
  o << "  noise var   ";
  for (const auto& m : a.ar) o << format(" %12.5g", m.noise_var);
  o << "\n  AIC         ";
  for (const auto& m : a.ar) o << format(" %12.2f", m.aic);
  o << "\n  BIC         ";
  for (const auto& m : a.ar) o << format(" %12.2f", m.bic);
  o << "\n  lowest AIC: AR(" << a.ar_order_aic << "), lowest BIC: AR(" << a.ar_order_bic << ")\n";

  std::snprintf(line, sizeof line,
                "\nKalman on AR(1): A = %.5g, Q = %.5g, R = %.5g, P0 = %.3g, steady-state gain %.4f\n",
                a.filter.kalman.a, a.filter.kalman.q, a.filter.kalman.r, a.filter.kalman.p0, a.steady_state_gain);
  o << line;
  std::snprintf(line, sizeof line, "Variance (%s)^2: raw %.5g, mean filter %.5g, Kalman %.5g (%.1f %% of raw)\n", unit,
                a.variance.raw, a.variance.mean, a.variance.kalman,
                a.variance.raw > 0 ? 100.0 * a.variance.kalman / a.variance.raw : 0.0);
  o << line;
  std::snprintf(line, sizeof line, "Peak after Kalman: %.1f %% of before\n", 100.0 * a.peak_ratio);
  o << line;

  o << "\nTable 4: noise terms before and after Kalman (+- 1 sigma)\n";
  for (NoiseTerm t : kAllNoiseTerms) {
    const auto before_figure = noiseFigures(t, a.noise.value.get(t), sensor).front();
    const double before = before_figure.value;
    const double after = noiseFigures(t, a.noise_after_kalman.value.get(t), sensor).front().value;
    const double before_sigma = noiseFigures(t, a.noise.uncertainty.get(t), sensor).front().value;
    const double after_sigma = noiseFigures(t, a.noise_after_kalman.uncertainty.get(t), sensor).front().value;
    std::snprintf(line, sizeof line, "  %-42s %s %s", std::string(before_figure.label).c_str(),
                  termWithUncertainty(before, before_sigma).c_str(), termWithUncertainty(after, after_sigma).c_str());
    o << line;
    if (before > 0.0) o << format("  %+7.1f %%", 100.0 * (after - before) / before);
    o << '\n';
  }
}

// The calibration of one axis into the model: bias against temperature (and a warm-up shape),
// and, when either was fitted, the five terms refitted on the record without them (the
// temperature curve would otherwise show as rate random walk and ramp).
void calibrateAxisInto(recording::SensorModel& sensor, std::size_t slot, const std::string& name,
                       const std::vector<double>& secs, const recording::Recording& rec, std::size_t idx,
                       const AnalysisOptions& options, std::vector<std::string>& notes) {
  recording::AxisCalibrationFit c;
  try {
    c = recording::calibrateAxis(secs, rec.axes[idx], rec.temp);
  } catch (const std::invalid_argument& e) {
    notes.push_back(name + ": no calibration (" + e.what() + ")");
    return;
  }
  sensor.calibration[slot] = c.calibration;
  sensor.simulation.axes[slot].bias_dps = c.bias_dps;
  char line[256];
  std::snprintf(line, sizeof line, "%s: bias %.6g +- %.2g deg/s at %.3f C", name.c_str(), c.bias_dps,
                c.calibration.bias_std_dps, c.calibration.temperature_reference_c);
  std::string note = line;
  if (c.fit.coefficientFitted()) {
    std::snprintf(line, sizeof line, ", %.6g +- %.2g deg/s per C over a spread of %.3g C",
                  c.calibration.temperature_coefficient_dps_per_c, c.calibration.temperature_coefficient_std_dps_per_c,
                  c.fit.temperature_spread_c);
    note += line;
  } else {
    note += rec.temp.empty() ? ", no temperature column" : ", temperature too flat for a coefficient";
  }
  if (c.calibration.warm_up_amplitude_dps != 0.0) {
    std::snprintf(line, sizeof line, ", warm-up shape %.4g +- %.2g deg/s, tau %.4g s",
                  c.calibration.warm_up_amplitude_dps, c.calibration.warm_up_amplitude_std_dps,
                  c.calibration.warm_up_time_constant_s);
    note += line;
  }
  if (c.changed()) {
    std::vector<double> x = c.corrected;
    const double tau0 = 1.0 / options.rate_hz;
    if (options.detrend) removeLinearTrend(x, tau0);
    sensor.simulation.axes[slot].terms = fitNoiseTerms(allanDeviationTable(x, tau0, options.cluster_sizes)).value;
    note += "; terms refitted without them";
  }
  notes.push_back(note);
}

// imu.yaml for Kalibr; each term it could not fill is named on stderr as in the file.
void writeKalibrImu(const AnalyzeOptions& opt, const LoadedInput& in, const std::vector<AxisAnalysis>& analyses) {
  std::vector<std::string> columns, missing;
  for (std::size_t idx : in.axis_indices) columns.push_back(in.recording.axis_names[idx]);
  const auto imu = kalibrImuFromAnalyses(columns, analyses, in.rate_hz, opt.file, opt.kalibr, missing);
  formats::writeFileAtomically(opt.kalibr.output, formats::kalibrImuYaml(imu), {opt.file});
  for (const auto& m : missing) std::fprintf(stderr, "gyroctl analyze: %s: %s\n", opt.kalibr.output.c_str(), m.c_str());
  if (!opt.json) std::printf("\nKalibr imu.yaml written to %s\n", opt.kalibr.output.c_str());
}

// Every selected axis analysed, in axis order. Two at a time on two cores, each with a
// workspace of its own: an axis's serial steps (the Kalman filter, the long-double spreads,
// the tables' serial passes) then leave no core idle.
std::vector<AxisAnalysis> analyzeEveryAxis(const AnalyzeOptions& opt, LoadedInput& in, const AnalysisOptions& options,
                                           StepTimer& step_timer) {
  auto& rec = in.recording;
  const std::size_t samples = rec.size();
  const bool writes_model = !opt.write_model.empty();
  const std::size_t axis_count = in.axis_indices.size();
  const bool two_at_once = axis_count >= 2 && processing::shareThreadCount() > 1;
  // Without --write-model the time column is done with: its memory holds the Allan phase,
  // whose pages are then not cleared a second time; the temperature column's, the second
  // workspace's, when there is one.
  std::vector<processing::AllanWorkspace> workspaces;
  workspaces.reserve(2);
  workspaces.push_back(writes_model ? processing::AllanWorkspace(samples)
                                    : processing::AllanWorkspace(samples, std::move(rec.t)));
  if (two_at_once)
    workspaces.push_back(writes_model ? processing::AllanWorkspace(samples)
                                      : processing::AllanWorkspace(samples, std::move(rec.temp)));
  if (!writes_model) releaseColumnsNotAnalysed(rec);
  step_timer("checks");
  const bool show_progress = samples >= kProgressSamples && stderrIsTerminal();
  std::mutex progress_mutex;
  const auto analyseAxis = [&](std::size_t k, processing::AllanWorkspace& workspace) {
    const std::size_t idx = in.axis_indices[k];
    if (show_progress) {
      const std::lock_guard<std::mutex> lock(progress_mutex);
      std::fprintf(stderr, "\ranalysing %s (%zu of %zu)...\033[K", rec.axis_names[idx].c_str(), k + 1, axis_count);
    }
    AnalysisOptions column_options = options;
    if (sensorOfColumn(rec.axis_names[idx]) == SensorKind::Accel)
      column_options.mean_threshold_dps = opt.accel_mean_threshold_g;
    if (step_timer.enabled())
      column_options.step_done = [&step_timer, &name = rec.axis_names[idx]](const char* step) {
        step_timer(name + " " + step);
      };
    return analyzeColumn(rec, idx, column_options, writes_model, workspace);
  };
  std::vector<AxisAnalysis> analyses(axis_count);
  if (!two_at_once) {
    for (std::size_t k = 0; k < axis_count; ++k) analyses[k] = analyseAxis(k, workspaces[0]);
  } else {
    // Each worker takes the next axis not yet taken; every axis is analysed (an axis's result
    // never depends on another's), and the first failure in axis order is the one reported,
    // as one after the other would report it.
    std::atomic<std::size_t> next_axis{0};
    std::vector<std::exception_ptr> failures(axis_count);
    const auto worker = [&](processing::AllanWorkspace& workspace) {
      for (std::size_t k = next_axis.fetch_add(1); k < axis_count; k = next_axis.fetch_add(1)) {
        try {
          analyses[k] = analyseAxis(k, workspace);
        } catch (...) {
          failures[k] = std::current_exception();
        }
      }
    };
    processing::runBoth([&] { worker(workspaces[1]); }, [&] { worker(workspaces[0]); });
    for (const auto& failure : failures)
      if (failure) std::rethrow_exception(failure);
  }
  if (show_progress) std::fprintf(stderr, "\r\033[K");
  return analyses;
}

int runAnalyze(const AnalyzeOptions& opt) {
  // A target that cannot be written fails now, not after the analysis.
  if (!opt.write_model.empty()) formats::checkOutputTarget(opt.write_model, {opt.file});
  if (!opt.kalibr.output.empty()) formats::checkOutputTarget(opt.kalibr.output, {opt.file});
  // A progress line left on the terminal would run into an error message: cleared on any exit.
  struct ClearProgressLine {
    bool active;
    ~ClearProgressLine() {
      if (active) std::fputs("\r\033[K", stderr);
    }
  } const clear_progress{stderrIsTerminal()};
  StepTimer step_timer;
  recording::ReadOptions read;
  read.line_numbers = false;  // the line runs name any sample's line: 8 bytes a sample saved
  read.progress = readingProgress(opt.file);
  // An accelerometer column is not among the gyro axes loadInput picks from.
  LoadedInput in = loadInput(opt.file, opt.rate_hz, isAccelColumn(opt.axis) ? "all" : opt.axis, read);
  selectAccelColumns(in, opt.axis);
  step_timer("read");
  auto& rec = in.recording;
  const std::size_t samples = rec.size();
  if (rec.size() < kMinimumSamples) {
    std::ostringstream s;
    s << opt.file << ": " << rec.size() << " samples are too few to analyse (need at least " << kMinimumSamples << ")";
    throw recording::RecordingError(s.str());
  }
  AnalysisOptions options;
  options.rate_hz = in.rate_hz;
  options.detrend = !opt.no_detrend;
  options.cluster_sizes = clusterSizesFor(opt.taus, in.rate_hz, rec.size());
  options.mean_window = opt.mean_window;
  options.mean_threshold_dps = opt.mean_threshold_dps;
  options.max_ar_order = opt.max_ar_order;
  // The values and the timing checked on both cores; a bad value is still reported first.
  TimingSummary timing;
  runBoth(
      [&] {
        for (std::size_t idx : in.axis_indices) requireAnalysableValues(rec, idx);
      },
      [&] { timing = checkTiming(rec, opt.rate_hz); });
  reportTiming(opt.file, timing, opt.strict_timing);
  const bool writes_model = !opt.write_model.empty();
  const std::vector<AxisAnalysis> analyses = analyzeEveryAxis(opt, in, options, step_timer);

  json doc;
  doc["file"] = opt.file;
  doc["rate_hz"] = in.rate_hz;
  doc["samples"] = samples;
  doc["detrended"] = options.detrend;
  doc["timing"] = timingJson(timing);
  doc["axes"] = json::object();
  if (!opt.json) {
    std::printf("gyroctl analyze %s: %zu samples at %g Hz (%s), %.1f s%s\n", opt.file.c_str(), samples, in.rate_hz,
                in.rate_source.c_str(), samples / in.rate_hz,
                options.detrend ? ", constant and linear trend removed" : ", no detrending");
  }
  recording::SensorModel sensor;
  SimulationModel& model = sensor.simulation;
  model.rate_hz = in.rate_hz;
  // Only the model needs the times and the temperature (released otherwise).
  const std::vector<double> secs = writes_model ? recording::secondsFromStart(rec, in.rate_hz) : std::vector<double>();
  if (!rec.temp.empty()) model.temperature = fitExponentialWarmUp(secs, rec.temp);
  sensor.filter = recording::FilterModel{};
  sensor.filter->mean_window = opt.mean_window;
  sensor.filter->mean_threshold_dps = opt.mean_threshold_dps;
  std::vector<std::string> notes;
  for (std::size_t k = 0; k < in.axis_indices.size(); ++k) {
    const std::size_t idx = in.axis_indices[k];
    const AxisAnalysis& a = analyses[k];
    if (const auto slot = recording::axisOfColumn(rec.axis_names[idx]); slot && !opt.write_model.empty()) {
      model.axes[*slot].terms = a.noise.value;
      model.axes[*slot].bias_dps = a.zero_mean.mean;
      sensor.kalman[*slot] = a.filter.kalman;
      calibrateAxisInto(sensor, *slot, rec.axis_names[idx], secs, rec, idx, options, notes);
    }
    if (opt.json)
      doc["axes"][rec.axis_names[idx]] = axisJson(a, sensorOfColumn(rec.axis_names[idx]));
    else
      printAxisText(std::cout, rec.axis_names[idx], a);
  }
  if (!opt.write_model.empty()) {
    std::string head = "# Sensor model of " + opt.file + " from gyroctl analyze (docs/calibration.md).\n";
    for (const std::string& note : notes) head += "# " + note + "\n";
    formats::writeFileAtomically(opt.write_model, head + recording::sensorModelToToml(sensor), {opt.file});
    if (!opt.json) std::printf("\nModel written to %s\n", opt.write_model.c_str());
  }
  if (!opt.kalibr.output.empty()) writeKalibrImu(opt, in, analyses);
  if (opt.json) std::cout << doc.dump(1) << '\n';
  std::cout.flush();
  step_timer("output");
  return kExitOk;
}

}  // namespace

void addAnalyzeCommand(CLI::App& app, CommandRunner& run) {
  auto opt = std::make_shared<AnalyzeOptions>();
  auto* sub = app.add_subcommand("analyze",
                                 "The paper's tables for a static recording: tests, Allan deviation, "
                                 "noise terms, AR/AIC, Kalman, terms after Kalman");
  sub->add_option("FILE", opt->file, "CSV with header t,gx,gy,gz,temp (any subset), or one column of bare numbers")
      ->required();
  sub->add_option("--rate", opt->rate_hz, "sample rate [Hz] (default: from t, else 50)");
  sub->add_option("--axis", opt->axis, "gx, gy, gz, ax, ay, az or all (every gyro and accelerometer column)")
      ->default_val("all");
  sub->add_option("--taus", opt->taus, "octave, dense, or a list of tau in seconds (e.g. 1,10,100)")
      ->default_val("octave");
  sub->add_flag("--no-detrend", opt->no_detrend, "keep the constant and the linear trend");
  sub->add_flag("--json", opt->json, "one JSON document on stdout");
  sub->add_flag("--strict-timing", opt->strict_timing,
                "gaps or irregular spacing in t, or GAP/DROPPED records, are an error instead of a warning");
  sub->add_option("--mean-window", opt->mean_window, "mean filter window L [samples]")
      ->default_val(20)
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000}));
  sub->add_option("--mean-threshold", opt->mean_threshold_dps, "gross-error threshold r [deg/s]")
      ->default_val(0.3)
      ->check(CLI::PositiveNumber);
  sub->add_option("--accel-mean-threshold", opt->accel_mean_threshold_g,
                  "gross-error threshold r of the accelerometer columns [g]")
      ->default_val(0.05)
      ->check(CLI::PositiveNumber);
  sub->add_option("--kalibr", opt->kalibr.output,
                  "write Kalibr's imu.yaml (noise densities and random walks in SI, update_rate, rostopic)");
  sub->add_option("--kalibr-inflate", opt->kalibr.inflate,
                  "multiply the imu.yaml noise values by F (Kalibr advises inflating static Allan values)")
      ->default_val(1.0)
      ->check(CLI::PositiveNumber);
  sub->add_option("--kalibr-rostopic", opt->kalibr.rostopic, "rostopic written in the imu.yaml")->default_val("/imu0");
  sub->add_option("--max-ar-order", opt->max_ar_order, "highest AR order for Table 3")
      ->default_val(3)
      ->check(CLI::Range(std::size_t{1}, std::size_t{8}));
  sub->add_option("--write-model", opt->write_model,
                  "write the sensor model (noise terms, bias against temperature, filter parameters per axis) as TOML "
                  "for gyroctl simulate --model, gyroctl filter --model and gyrod's filter.model");
  sub->callback([&run, opt] { run = [opt] { return runAnalyze(*opt); }; });
}

}  // namespace gyrod::gyroctl
