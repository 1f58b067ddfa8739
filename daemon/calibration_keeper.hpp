#pragma once
// What the rate stream learns on this board, kept across restarts (docs/calibration-state.md):
// the residual filter's state (processing::LearnedResidual) in `<state directory>/calibration.toml`
// (formats/calibration_state.hpp). At the start it is read back and the rate estimator begins
// from it, when it was learned with the same sensor model and rate; every `save_interval_s` of
// data time it is written again, off the loop, and once more at a clean stop.
// The sample loop never waits on the file: it copies the state (a few dozen numbers) and hands
// the write to a thread of its own (OffLoopJob); a write still running when the next is due is
// not doubled, and the stop's write waits for it (the two never write the file at once).
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "daemon/event_loop.hpp"
#include "daemon/off_loop_job.hpp"
#include "formats/calibration_state.hpp"
#include "processing/motion/rate_estimator.hpp"

namespace gyrod::daemon {

inline constexpr std::string_view kCalibrationStateFile = "calibration.toml";

// The state directory gyrod keeps its calibration in: state.directory when set, else systemd's
// $STATE_DIRECTORY (the first one, StateDirectory= in the unit), else none ("").
std::string calibrationStateDirectory(const std::string& configured);

// What a restart begins from, and how it was judged.
struct RestoredCalibration {
  processing::LearnedResidual residual;
  double elapsed_s = 0.0;  // since it was written (wall clock; 0 when the clock went back)
  formats::CalibrationState state;
};

class CalibrationKeeper {
 public:
  // `fingerprint`: formats::biasModelFingerprint of the sensor model the rate stream runs on.
  CalibrationKeeper(EventLoop& loop, const std::string& directory, std::string fingerprint, double rate_hz,
                    double save_interval_s);
  CalibrationKeeper(const CalibrationKeeper&) = delete;
  CalibrationKeeper& operator=(const CalibrationKeeper&) = delete;

  const std::string& path() const { return path_; }
  // Reads the file (if any) and says in one log line what came of it: nullopt when there is
  // none, it cannot be read, it is not a state file, or it belongs to another model or rate.
  // A refused regular file is renamed to calibration.toml.refused (replacing an older one), so
  // that the next write does not destroy what it held.
  std::optional<RestoredCalibration> restore();
  // The sensor model changed (SIGHUP): what is learned from now on is relative to this one.
  void setFingerprint(std::string fingerprint) { fingerprint_ = std::move(fingerprint); }
  // Per sample on the loop: starts a write when save_interval_s of data time has passed since
  // the last (no allocation otherwise).
  void onSample(double t_s, const processing::RateEstimator& estimator);
  // At a clean stop, on the loop's thread after the loop ended: writes now and logs it.
  void writeAtStop(const processing::RateEstimator& estimator);
  std::uint64_t writes() const { return writes_; }
  bool restored() const { return restored_; }
  const std::string& lastError() const { return last_error_; }

 private:
  formats::CalibrationState snapshot(const processing::RateEstimator& estimator) const;
  // Renames a refused regular file aside; the words for the log line ("" when nothing was moved).
  std::string keepAside();

  std::string path_;
  std::string fingerprint_;
  double rate_hz_;
  double save_interval_s_;
  std::optional<double> first_t_s_, last_t_s_, last_save_t_s_;
  std::shared_ptr<std::mutex> file_mutex_ = std::make_shared<std::mutex>();  // one writer at a time
  OffLoopJob<std::string> job_;
  std::string last_error_;  // logged once until it changes
  std::uint64_t writes_ = 0;
  bool restored_ = false;
};

}  // namespace gyrod::daemon
