// gyroctl live-check: the live check (processing/model_check/live_check.hpp, docs/live-check.md)
// over a recording, interval by interval of still data as a running board's would come: the
// first --baseline seconds are the board's baseline, every later interval is compared with it,
// and each effect is printed when first named and when gone. A run of still samples breaks at
// a GAP or DROPPED line and at kLiveMotionBreakS of moving samples in a row (gyrod's `still`
// column, when the recording has one); what does not fill an interval is left out.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "formats/recording_csv.hpp"
#include "processing/model_check/live_check.hpp"
#include "protocol/effect_line.hpp"
#include "tools/gyroctl/commands.hpp"
#include "tools/gyroctl/input.hpp"
#include "tools/gyroctl/series_checks.hpp"

namespace gyrod::gyroctl {
namespace {

struct LiveCheckOptions {
  std::string file;
  std::optional<double> rate_hz;
  double interval_s = 300.0;
  double baseline_s = 1800.0;
  double false_alarms_per_week = 0.25;
  bool json = false;
};

std::string g4(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

std::string range(const processing::LiveInterval95& i) { return "(" + g4(i.lo) + "–" + g4(i.hi) + ")"; }

char axisName(std::size_t axis) { return "xyz"[axis]; }

// One change as text: "3600 s  new   line on y: 12.5 Hz (12.49–12.51), ..."
std::string effectText(const processing::LiveEffect& e) {
  std::string s = g4(e.t) + " s  " + (e.gone ? "gone  " : "new   ") + processing::liveEffectName(e.kind) + " on " +
                  axisName(e.axis);
  if (e.gone) return s + (e.kind == processing::LiveEffectKind::Line ? " at " + g4(e.centre_hz) + " Hz" : "");
  if (e.kind == processing::LiveEffectKind::Line) {
    s += ": " + g4(e.centre_hz) + " Hz " + range(e.centre_hz_95) + ", " + g4(e.width_hz) + " Hz wide, rms " +
         g4(e.rms_dps) + " deg/s " + range(e.rms_dps_95);
  } else if (e.kind == processing::LiveEffectKind::OutlierBurst) {
    s += ": " + std::to_string(e.count) + " samples beyond robust z " + g4(processing::kLiveOutlierZ) + " (" +
         g4(e.expected) + " expected), largest z " + g4(e.largest_z);
  } else if (e.kind == processing::LiveEffectKind::BiasStep) {
    s += ": " + g4(e.size_dps) + " deg/s " + range(e.size_dps_95) + " over " + g4(e.scale_s) + " s each side";
  } else {
    s += ": " + g4(e.coefficient_dps_per_c) + " deg/s per C " + range(e.coefficient_dps_per_c_95) + " where " +
         g4(e.baseline_coefficient_dps_per_c) + " was known, the temperature moving " + g4(e.temperature_change_c) +
         " C";
  }
  return s + ", onset " + g4(e.onset_t) + " s " + range(e.onset_95) + "; " + e.evidence;
}

const std::vector<double>& gyroColumn(const recording::Recording& rec, std::size_t axis) {
  const std::string name(recording::kGyroColumns[axis]);
  const std::vector<double>* column = rec.axis(name);
  if (!column || column->empty())
    throw recording::RecordingError(rec.path + ": live-check needs the columns gx,gy,gz; '" + name + "' is missing");
  return *column;
}

processing::LiveCheck makeCheck(const LiveCheckOptions& opt, double rate_hz) {
  processing::LiveCheckSettings s;
  s.rate_hz = rate_hz;
  s.interval_s = opt.interval_s;
  s.baseline_s = opt.baseline_s;
  s.false_alarms_per_week = opt.false_alarms_per_week;
  try {
    return processing::LiveCheck(s);
  } catch (const std::invalid_argument& e) {
    // "live check: interval_s must be > 0" → the option the user typed.
    std::string what = e.what();
    for (const auto& [key, option] : {std::pair<std::string, std::string>{"interval_s", "--interval"},
                                      {"baseline_s", "--baseline"},
                                      {"false_alarms_per_week", "--false-alarms-per-week"}})
      if (const auto at = what.find(key); at != std::string::npos) what.replace(at, key.size(), option);
    throw ExitError(ExitCode::Usage, what.substr(what.find(": ") + 2) + " (at " + g4(rate_hz) + " Hz)");
  }
}

int runLiveCheck(const LiveCheckOptions& opt) {
  const LoadedInput in = loadInput(opt.file, opt.rate_hz, "all");
  const recording::Recording& rec = in.recording;
  std::array<const std::vector<double>*, 3> gyro{};
  for (std::size_t a = 0; a < 3; ++a) gyro[a] = &gyroColumn(rec, a);
  processing::LiveCheck check = makeCheck(opt, in.rate_hz);
  const std::size_t n = check.samplesPerInterval(), total = rec.size();
  std::array<std::vector<double>, 3> interval;
  for (auto& x : interval) x.reserve(n);
  // The die temperature beside them, when the recording has it (the coupling is judged on it).
  const bool have_temp = rec.temp.size() == total;
  std::vector<double> temperature;
  temperature.reserve(n);
  std::size_t lost_index = 0, examined = 0, left_out = 0;
  double run_start_t = 0.0;
  std::size_t run_samples = 0;  // since the run began: the nominal clock of its intervals
  std::size_t changes_printed = 0;
  processing::LiveMotionRule motion(in.rate_hz);
  const auto sampleTime = [&](std::size_t i) { return rec.t.empty() ? static_cast<double>(i) / in.rate_hz : rec.t[i]; };
  const auto breakRun = [&] {
    left_out += interval[0].size();
    for (auto& x : interval) x.clear();
    temperature.clear();
    run_samples = 0;
  };
  for (std::size_t i = 0; i < total; ++i) {
    bool lost_before = false;
    while (lost_index < rec.lost.size() && rec.lost[lost_index].before_sample <= i) {
      lost_before = lost_before || rec.lost[lost_index].before_sample == i;
      ++lost_index;
    }
    if (lost_before) breakRun();
    // A stretch of moving verdicts of kLiveMotionBreakS breaks the run; shorter ones stay in
    // (a still detector flickers at rest).
    const auto verdict = motion.next(rec.still.empty() || rec.still[i] == 1.0);
    const bool finite = std::isfinite((*gyro[0])[i]) && std::isfinite((*gyro[1])[i]) && std::isfinite((*gyro[2])[i]);
    if (verdict != processing::LiveMotionRule::Verdict::Keep || !finite) {
      if (verdict == processing::LiveMotionRule::Verdict::Break || !finite) breakRun();
      ++left_out;
      continue;
    }
    if (run_samples == 0) run_start_t = sampleTime(i);
    for (std::size_t a = 0; a < 3; ++a) interval[a].push_back((*gyro[a])[i]);
    if (have_temp) temperature.push_back(rec.temp[i]);
    ++run_samples;
    if (interval[0].size() < n) continue;
    const double t0 = run_start_t + static_cast<double>(run_samples - n) / in.rate_hz;
    // A temperature missing anywhere in the interval: no coupling judged on it.
    const bool temp_ok =
        have_temp && std::all_of(temperature.begin(), temperature.end(), [](double c) { return std::isfinite(c); });
    for (const processing::LiveEffect& e :
         check.examine(interval, temp_ok ? std::span<const double>(temperature) : std::span<const double>(), t0)) {
      std::printf("%s\n", opt.json ? protocol::effectJson(e).dump().c_str() : effectText(e).c_str());
      ++changes_printed;
    }
    ++examined;
    for (auto& x : interval) x.clear();
    temperature.clear();
  }
  left_out += interval[0].size();
  const std::size_t baseline =
      std::min(examined, static_cast<std::size_t>(std::ceil(opt.baseline_s / opt.interval_s - 1e-9)));
  if (opt.json) {
    nlohmann::json current = nlohmann::json::array();
    for (const processing::LiveEffect& e : check.current()) current.push_back(protocol::effectJson(e));
    std::printf("%s\n", nlohmann::json{{"class", "SUMMARY"},
                                       {"intervals", examined},
                                       {"baseline_intervals", baseline},
                                       {"baseline_ready", check.baselineReady()},
                                       {"samples_left_out", left_out},
                                       {"current", current}}
                            .dump()
                            .c_str());
    return kExitOk;
  }
  std::printf(
      "%s: %zu intervals of %s s examined at %s Hz (%zu the baseline%s), %zu samples left out (moving, "
      "lost, or not filling an interval); %zu changes; current at the end: %zu\n",
      opt.file.c_str(), examined, g4(opt.interval_s).c_str(), g4(in.rate_hz).c_str(), baseline,
      check.baselineReady() ? "" : ", not complete: nothing compared", left_out, changes_printed,
      check.current().size());
  return kExitOk;
}

}  // namespace

void addLiveCheckCommand(CLI::App& app, CommandRunner& run) {
  auto opt = std::make_shared<LiveCheckOptions>();
  auto* sub = app.add_subcommand(
      "live-check", "Run the live check over a recording: what is new against the board's baseline, when it began");
  sub->add_option("FILE", opt->file, "recording CSV with gx,gy,gz (gyrod's, gyroctl import's or simulate's)")
      ->required();
  sub->add_option("--rate", opt->rate_hz, "sample rate in Hz (default: from the t column)");
  sub->add_option("--interval", opt->interval_s, "seconds of still data per examination (default 300)");
  sub->add_option("--baseline", opt->baseline_s, "seconds of still data that make the baseline (default 1800)");
  sub->add_option("--false-alarms-per-week", opt->false_alarms_per_week,
                  "expected false effects per week of clean data, all detectors and axes (default 0.25)");
  sub->add_flag("--json", opt->json, "one JSON line per change (class EFFECT) and a SUMMARY line");
  sub->callback([&run, opt] { run = [opt] { return runLiveCheck(*opt); }; });
}

}  // namespace gyrod::gyroctl
