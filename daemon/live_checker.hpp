#pragma once
// gyrod's live check (docs/live-check.md): the still samples, averaged down to at most
// kLiveCheckMaxRateHz, go into an interval on the loop; a full interval is handed to a thread
// of its own (OffLoopJob), which runs processing::LiveCheck on it and returns what changed; the
// loop then logs each change in one line and hands it on (`on_change`: the EFFECT line to the
// watching clients). The loop's share per sample is an add and a store, with no allocation: the
// two interval buffers are allocated once and swapped. A moving sample or a gap breaks the run
// of still samples; an interval that fills while the last examination still runs is left out
// (counted as skipped).
// The check itself is touched only by the examination's thread, one examination at a time; it
// is shared with that thread, so that an examination still running at the stop ends on its own.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "daemon/event_loop.hpp"
#include "daemon/off_loop_job.hpp"
#include "processing/model_check/live_check.hpp"
#include "protocol/protocol.hpp"

namespace gyrod::daemon {

class LiveChecker {
 public:
  using OnChange = std::function<void(const processing::LiveEffect&)>;

  // `device_rate_hz`: the samples' rate; the check runs at it divided by the smallest whole
  // factor that brings it to kLiveCheckMaxRateHz or below. Throws std::invalid_argument (the
  // settings, as processing::LiveCheck does).
  // `temperature_coefficient_dps_per_c`: the coupling filter.model gives each axis (the check
  // names one that differs).
  LiveChecker(EventLoop& loop, double device_rate_hz, double interval_s, double baseline_s,
              double false_alarms_per_week, const std::array<double, 3>& temperature_coefficient_dps_per_c,
              OnChange on_change);
  LiveChecker(const LiveChecker&) = delete;
  LiveChecker& operator=(const LiveChecker&) = delete;

  // On the loop, per sample: `still` is the still detector's verdict; kLiveMotionBreakS of
  // samples in a row without it break the run (and the samples until it says still again are
  // left out); fewer stay in.
  void onSample(double t_s, const std::array<double, 3>& rate_dps, double temperature_c, bool still);
  // A gap: the run of still samples breaks.
  void breakRun();
  // On the loop; the caller holds what guards it from the STATUS readers.
  protocol::LiveCheckStatus status() const;
  double analysisRateHz() const { return analysis_rate_hz_; }

 private:
  void examine();
  void applyChanges(std::vector<processing::LiveEffect>&& changes);

  double analysis_rate_hz_ = 0.0;
  std::size_t decimation_ = 1;
  std::size_t interval_samples_ = 0;
  std::shared_ptr<processing::LiveCheck> check_;
  // Filled on the loop, and the one an examination reads (not touched by the loop while it runs):
  // the three axes and the temperature.
  using IntervalData = std::array<std::vector<double>, 4>;  // x, y, z [°/s], temperature [°C]
  IntervalData filling_;
  std::shared_ptr<IntervalData> examined_;
  // The decimation's running sums (axes, temperature), and the run's data time at its first
  // output sample.
  std::array<double, 4> sum_{};
  std::size_t summed_ = 0;
  double block_start_t_ = 0.0;
  double run_start_t_ = 0.0;
  std::uint64_t run_samples_ = 0;  // analysis samples since the run began
  processing::LiveMotionRule motion_;
  OnChange on_change_;
  OffLoopJob<std::vector<processing::LiveEffect>> job_;
  std::uint64_t intervals_ = 0, named_ = 0, skipped_ = 0;
  std::vector<processing::LiveEffect> current_;  // a copy, kept on the loop for STATUS
  bool baseline_ready_ = false;
};

}  // namespace gyrod::daemon
