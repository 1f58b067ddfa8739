#include "daemon/calibration_keeper.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <system_error>

namespace gyrod::daemon {
namespace {

double unixNow() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void writeState(const std::string& path, formats::CalibrationState state, std::mutex& file_mutex) {
  state.saved_unix_s = unixNow();
  const std::string text = formats::calibrationStateToToml(state);
  const std::lock_guard lock(file_mutex);
  formats::replaceStateFile(path, text);
}

}  // namespace

std::string calibrationStateDirectory(const std::string& configured) {
  if (!configured.empty()) return configured;
  const char* from_systemd = std::getenv("STATE_DIRECTORY");  // colon-separated, one per StateDirectory=
  if (from_systemd == nullptr) return {};
  const std::string all(from_systemd);
  return all.substr(0, all.find(':'));
}

CalibrationKeeper::CalibrationKeeper(EventLoop& loop, const std::string& directory, std::string fingerprint,
                                     double rate_hz, double save_interval_s)
    : path_((std::filesystem::path(directory) / kCalibrationStateFile).string()),
      fingerprint_(std::move(fingerprint)),
      rate_hz_(rate_hz),
      save_interval_s_(save_interval_s),
      job_(
          loop,
          [this](std::string&&) {
            ++writes_;
            if (!last_error_.empty()) spdlog::info("calibration state: written to {} again", path_);
            last_error_.clear();
          },
          [this](const std::string& why) {
            if (why != last_error_) spdlog::error("calibration state: not written: {}", why);
            last_error_ = why;
          }) {}

std::string CalibrationKeeper::keepAside() {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(std::filesystem::symlink_status(path_, ec))) return {};
  const std::string aside = path_ + ".refused";
  std::filesystem::rename(path_, aside, ec);
  return ec ? std::string() : " (kept as " + aside + ")";
}

std::optional<RestoredCalibration> CalibrationKeeper::restore() {
  std::error_code ec;
  if (!std::filesystem::exists(std::filesystem::symlink_status(path_, ec))) {
    spdlog::info("calibration state: none yet at {}: the rate stream starts from the sensor model", path_);
    return std::nullopt;
  }
  RestoredCalibration r;
  try {
    r.state = formats::readCalibrationStateToml(path_);
  } catch (const std::exception& e) {  // unreadable, not a state file, or values out of range
    spdlog::warn("calibration state: {}: not used{}, the rate stream starts from the sensor model", e.what(),
                 keepAside());
    return std::nullopt;
  }
  if (r.state.model != fingerprint_) {
    spdlog::warn(
        "calibration state: {}: learned with another sensor model (fingerprint {}, this one {}): not used{}, the "
        "rate stream starts from the sensor model",
        path_, r.state.model, fingerprint_, keepAside());
    return std::nullopt;
  }
  if (std::fabs(r.state.rate_hz - rate_hz_) > 1e-9 * rate_hz_) {
    spdlog::warn("calibration state: {}: learned at {} Hz, the device runs at {} Hz: not used{}", path_,
                 r.state.rate_hz, rate_hz_, keepAside());
    return std::nullopt;
  }
  r.residual = r.state.residual;
  restored_ = true;
  r.elapsed_s = std::max(0.0, unixNow() - r.state.saved_unix_s);
  const processing::LearnedResidual& l = r.residual;
  spdlog::info(
      "calibration state: restored from {} (written {:.0f} s ago after {:.0f} s of data; {} still samples{}; "
      "residual bias [{:.4f}, {:.4f}, {:.4f}] deg/s at {:.1f} C): the rate stream starts from it",
      path_, r.elapsed_s, r.state.data_time_s, l.still_samples,
      std::isnan(l.still_temperature_min_c)
          ? std::string()
          : fmt::format(" at {:.1f}-{:.1f} C", l.still_temperature_min_c, l.still_temperature_max_c),
      l.axes[0].offset_dps, l.axes[1].offset_dps, l.axes[2].offset_dps, l.temperature_origin_c);
  return r;
}

formats::CalibrationState CalibrationKeeper::snapshot(const processing::RateEstimator& estimator) const {
  formats::CalibrationState s;
  s.model = fingerprint_;
  s.rate_hz = rate_hz_;
  s.data_time_s = first_t_s_ && last_t_s_ ? *last_t_s_ - *first_t_s_ : 0.0;
  s.residual = estimator.learned();
  return s;
}

void CalibrationKeeper::onSample(double t_s, const processing::RateEstimator& estimator) {
  if (!first_t_s_) first_t_s_ = last_save_t_s_ = t_s;
  last_t_s_ = t_s;
  if (t_s - *last_save_t_s_ < save_interval_s_ || job_.running()) return;
  last_save_t_s_ = t_s;
  try {
    job_.start([path = path_, state = snapshot(estimator), mutex = file_mutex_]() {
      writeState(path, state, *mutex);
      return std::string();
    });
  } catch (const std::exception& e) {  // no thread now: the next interval tries again
    spdlog::warn("calibration state: the write could not start: {}", e.what());
  }
}

void CalibrationKeeper::writeAtStop(const processing::RateEstimator& estimator) {
  if (!first_t_s_) return;  // no sample: nothing new was learned, the file stays as it was
  try {
    writeState(path_, snapshot(estimator), *file_mutex_);
    ++writes_;
    last_error_.clear();
    spdlog::info("calibration state: written to {} ({} still samples learned from)", path_,
                 estimator.learned().still_samples);
  } catch (const std::exception& e) {
    last_error_ = e.what();
    spdlog::error("calibration state: not written at the stop: {}", e.what());
  }
}

}  // namespace gyrod::daemon
