// False alarms and cost of the live check (processing/model_check/live_check.hpp) on clean
// simulated boards: each board-week a fresh seed of an MPU6050-like model at rest (50 Hz,
// FS_SEL 0 quantisation, ARW 0.3 °/√h, bias instability 10 °/h, rate random walk 5 °/h/√h,
// two steady lines of the chip's own, 16.7 and 20.1 Hz at 0.02 °/s, which the baseline holds,
// a 10 °C warm-up its bias does not follow),
// streamed an interval at a time through the check. Prints the effects named per board-week
// with the 95 % upper bound of their rate (Poisson) and the check's own CPU time per hour of
// data as a share of one core (the simulation's time not counted). docs/live-check.md.
//
// With --line N: instead, N boards of 2 h each with a 12.5 Hz line of amplitude 0.1 × the
// white noise's per-sample σ hidden from t = 3600 s on one axis (seed-chosen): how many are named
// on the right axis within 600 s of the onset, the delays, and the centre's largest error.
// With --step N --size D: N boards of 2 h each with a bias step of D °/s (sign alternating) at a
// seeded time in 3600–3900 s on one axis: how many are named on the right axis within 600 s.
//
//   live_check_false_alarms [--weeks W] [--seed S] [--interval S] [--baseline S] [--line N]
//                           [--step N --size D]
#include <time.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "processing/base/distributions.hpp"
#include "processing/model_check/live_check.hpp"
#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod::processing;

namespace {

double threadCpuSeconds() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

SimulationModel cleanBoard() {
  SimulationModel m;
  m.rate_hz = 50.0;
  m.fs_sel = 0;
  for (AxisNoiseModel& a : m.axes) {
    a.terms.arw_deg_per_sqrt_h = 0.3;
    a.terms.bias_instability_deg_per_h = 10.0;
    a.terms.rrw_deg_per_h_sqrt_h = 5.0;
    a.bias_dps = 0.4;
    a.extra.sinusoids = {{16.7, 0.02, 0.3}, {20.1, 0.02, 1.1}};
  }
  // A warm-up of 10 °C over its first hours (time constant 1 h), the bias not coupled to it:
  // the coupling detector judges every window the temperature moves in, and must stay quiet.
  m.temperature = {25.0, 35.0, 3600.0, 0.02};
  return m;
}

LiveCheckSettings settings(double rate_hz, double interval_s, double baseline_s) {
  LiveCheckSettings s;
  s.rate_hz = rate_hz;
  s.interval_s = interval_s;
  s.baseline_s = baseline_s;
  return s;
}

// One hidden effect per board: `boards` boards of 2 h, the effect `add`ed to axis (seed + b) % 3
// from `onset(b)` on. Returns per board the first effect named after the onset on that axis of
// `kind` (empty when none), and counts the others in *others.
using Hidden = std::function<double(std::size_t b, double t)>;  // what board b's axis gets at t
std::vector<std::optional<LiveEffect>> hiddenEffectRuns(std::size_t boards, std::uint64_t seed, double interval,
                                                        double baseline, LiveEffectKind kind,
                                                        const std::function<double(std::size_t)>& onset,
                                                        const Hidden& add, std::size_t* others) {
  const SimulationModel model = cleanBoard();
  constexpr double kDuration = 7200.0;
  std::vector<std::optional<LiveEffect>> first(boards);
  for (std::size_t b = 0; b < boards; ++b) {
    LiveCheck check(settings(model.rate_hz, interval, baseline));
    NoiseSimulator sim(model, kDuration, seed + b);
    const std::size_t axis = (seed + b) % 3, n = check.samplesPerInterval();
    std::array<std::vector<double>, 3> axes;
    for (auto& x : axes) x.resize(n);
    std::size_t i = 0;
    for (std::size_t k = 0; k < static_cast<std::size_t>(kDuration / interval); ++k) {
      for (std::size_t j = 0; j < n; ++j, ++i) {
        const SimulatedSample sample = sim.next();
        const double t = static_cast<double>(i) / model.rate_hz;
        for (std::size_t a = 0; a < 3; ++a) axes[a][j] = sample.rate_dps[a];
        if (t >= onset(b)) axes[axis][j] += add(b, t);
      }
      for (const LiveEffect& e : check.examine(axes, static_cast<double>(k) * interval)) {
        if (e.gone) continue;
        if (e.kind == kind && e.axis == axis && !first[b] && e.t > onset(b)) {
          first[b] = e;
        } else if (others != nullptr && ++*others <= 10) {
          std::printf("board %zu (hidden on axis %zu at %.0f s): %s on axis %zu at %.0f s: %s\n", b, axis, onset(b),
                      liveEffectName(e.kind), e.axis, e.t, e.evidence.c_str());
        }
      }
    }
  }
  return first;
}

// The named boards' delays after their onsets, "min-max" s, and how many within 600 s.
std::string delayRange(const std::vector<std::optional<LiveEffect>>& first,
                       const std::function<double(std::size_t)>& onset, std::size_t* within) {
  std::vector<double> delays;
  for (std::size_t b = 0; b < first.size(); ++b)
    if (first[b]) delays.push_back(first[b]->t - onset(b));
  *within = static_cast<std::size_t>(std::count_if(delays.begin(), delays.end(), [](double d) { return d <= 600.0; }));
  std::sort(delays.begin(), delays.end());
  return delays.empty()
             ? "none"
             : std::to_string(static_cast<int>(delays.front())) + "-" + std::to_string(static_cast<int>(delays.back()));
}

// The line mode (see above); returns the exit status.
int lineDelays(std::size_t boards, std::uint64_t seed, double interval, double baseline) {
  constexpr double kHz = 12.5;
  // White rate noise of N °/s/√Hz has σ²(τ₀) = N²/τ₀ per sample (IEEE 952): N = ARW/60.
  const double sigma = 0.3 / 60.0 * std::sqrt(cleanBoard().rate_hz);
  const auto onset = [](std::size_t) { return 3600.0; };
  const auto first = hiddenEffectRuns(
      boards, seed, interval, baseline, LiveEffectKind::Line, onset,
      [sigma](std::size_t, double t) { return 0.1 * sigma * std::sin(2.0 * std::numbers::pi * kHz * t); }, nullptr);
  double worst_centre = 0.0;
  for (const auto& e : first)
    if (e) worst_centre = std::max(worst_centre, std::fabs(e->centre_hz - kHz) / kHz);
  std::size_t named = 0;
  const std::string range = delayRange(first, onset, &named);
  std::printf(
      "%zu boards, a 12.5 Hz line of 0.1 sigma from 3600 s: %zu named within 600 s on the right axis; "
      "delays %s s; the centre's largest error %.3g %%\n",
      boards, named, range.c_str(), 100.0 * worst_centre);
  return 0;
}

// The step mode (see above); returns the exit status.
int stepDelays(std::size_t boards, std::uint64_t seed, double interval, double baseline, double size) {
  const auto onset = [seed](std::size_t b) {
    return 3600.0 + 300.0 * static_cast<double>((seed + b) * 7919 % 1000) / 1000.0;
  };
  std::size_t others = 0;
  const auto first = hiddenEffectRuns(
      boards, seed, interval, baseline, LiveEffectKind::BiasStep, onset,
      [size](std::size_t b, double) { return (b % 2 ? -1.0 : 1.0) * size; }, &others);
  std::size_t named = 0;
  const std::string range = delayRange(first, onset, &named);
  std::printf(
      "%zu boards, a bias step of %.4g deg/s at 3600-3900 s: %zu named within 600 s on the right axis "
      "(%.0f %%); delays %s s; %zu other effects named\n",
      boards, size, named, 100.0 * static_cast<double>(named) / static_cast<double>(boards), range.c_str(), others);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  double weeks = 4.0, interval = 300.0, baseline = 1800.0;
  std::uint64_t seed = 1;
  std::size_t line_boards = 0, step_boards = 0;
  double step_size = 0.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const char* value = argv[i + 1];
    if (key == "--weeks")
      weeks = std::atof(value);
    else if (key == "--seed")
      seed = std::strtoull(value, nullptr, 10);
    else if (key == "--interval")
      interval = std::atof(value);
    else if (key == "--baseline")
      baseline = std::atof(value);
    else if (key == "--line")
      line_boards = std::strtoull(value, nullptr, 10);
    else if (key == "--step")
      step_boards = std::strtoull(value, nullptr, 10);
    else if (key == "--size")
      step_size = std::atof(value);
    else {
      std::fprintf(stderr,
                   "usage: live_check_false_alarms [--weeks W] [--seed S] [--interval S] [--baseline S] [--line N]"
                   " [--step N --size D]\n");
      return 64;
    }
  }
  if (line_boards > 0) return lineDelays(line_boards, seed, interval, baseline);
  if (step_boards > 0) return stepDelays(step_boards, seed, interval, baseline, step_size);
  const SimulationModel model = cleanBoard();
  constexpr double kWeek = 7.0 * 86400.0;
  std::size_t named = 0, board_weeks = 0;
  double check_cpu = 0.0, data_s = 0.0;
  for (double done = 0.0; done + 1e-9 < weeks; done += 1.0, ++board_weeks) {
    LiveCheck check(settings(model.rate_hz, interval, baseline));
    NoiseSimulator sim(model, kWeek, seed + board_weeks);
    const std::size_t n = check.samplesPerInterval();
    const auto intervals = static_cast<std::size_t>(kWeek / interval);
    std::array<std::vector<double>, 3> axes;
    for (auto& x : axes) x.resize(n);
    std::vector<double> temperature(n);
    for (std::size_t k = 0; k < intervals; ++k) {
      for (std::size_t i = 0; i < n; ++i) {
        const SimulatedSample sample = sim.next();
        for (std::size_t a = 0; a < 3; ++a) axes[a][i] = sample.rate_dps[a];
        temperature[i] = sample.temperature_c;
      }
      const double t0 = static_cast<double>(k) * interval;
      const double before = threadCpuSeconds();
      const auto changes = check.examine(axes, temperature, t0);
      check_cpu += threadCpuSeconds() - before;
      for (const LiveEffect& e : changes) {
        if (e.gone) continue;
        ++named;
        std::printf("board-week %zu: %s on axis %zu at %.0f s: %s\n", board_weeks + 1, liveEffectName(e.kind), e.axis,
                    e.t, e.evidence.c_str());
      }
    }
    data_s += static_cast<double>(intervals) * interval;
  }
  // Poisson: the 95 % upper bound of the rate for `named` events in `board_weeks`.
  const double upper =
      0.5 * chiSquareQuantile(0.95, 2.0 * static_cast<double>(named + 1)) / static_cast<double>(board_weeks);
  std::printf(
      "%zu board-weeks (interval %.0f s, baseline %.0f s): %zu effects named on clean data, %.3g per "
      "board-week (95 %% upper bound %.3g)\n",
      board_weeks, interval, baseline, named, static_cast<double>(named) / static_cast<double>(board_weeks), upper);
  std::printf("the check's CPU: %.3f s per hour of 3-axis 50 Hz data, %.4f %% of one core\n",
              check_cpu / (data_s / 3600.0), 100.0 * check_cpu / data_s);
  return 0;
}
