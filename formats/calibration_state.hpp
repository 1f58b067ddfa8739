#pragma once
// gyrod's calibration state (docs/calibration-state.md): what the rate stream's residual filter
// has learned on this board (processing::LearnedResidual), with the sensor model it is relative
// to and when it was written, as a small TOML file in gyrod's state directory. gyrod writes it
// atomically (replaceStateFile) and reads it back at its start; a file that is not one, or
// is one for another model or rate, is refused with one line and gyrod starts without it.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "formats/input_file.hpp"
#include "processing/motion/rate_estimator.hpp"

namespace gyrod::formats {

inline constexpr std::string_view kCalibrationStateFormat = "gyrod-calibration-state";
inline constexpr std::int64_t kCalibrationStateVersion = 1;
// A few hundred bytes in practice.
inline constexpr InputKind kCalibrationStateInput{"calibration state file", 64 * 1024};

struct CalibrationState {
  std::string model;  // biasModelFingerprint() of the bias model the residual is relative to
  double rate_hz = 0.0;
  double saved_unix_s = 0.0;  // CLOCK_REALTIME when written
  double data_time_s = 0.0;   // sensor time its run had covered then
  processing::LearnedResidual residual;
};

// A problem with a state file, one line: "FILE:LINE: cause" or "FILE: cause".
class CalibrationStateError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// 16 hex digits: FNV-1a 64 of `text`.
std::string fnv1a64Hex(std::string_view text);
// What the learned residual is relative to: each axis's bias, temperature coefficient and its
// reference, and warm-up shape (shortest decimals), hashed. The noise terms, the temperature
// profile a simulation plays and the low-pass are not in it: they do not change what the
// residual means, so a model refitted or re-rated keeps its board's state.
std::string biasModelFingerprint(const processing::RateEstimatorParameters& params);

std::string calibrationStateToToml(const CalibrationState& state);
// Parses `text` (`file` names it); throws CalibrationStateError for a syntax error, a key that
// is unknown, missing or of the wrong type, another format or version, or values the rate
// estimator refuses (processing::validateLearnedResidual).
CalibrationState parseCalibrationStateToml(std::string_view text, const std::string& file);
// Reads a regular file of at most kCalibrationStateInput's size (InputFileError otherwise).
CalibrationState readCalibrationStateToml(const std::string& path);

// Replaces `path` by `bytes` so that a reader sees the old file or the new one, never a part:
// written to `path.tmp`, fsync'd, renamed over `path`, and the directory fsync'd. Throws
// std::system_error naming the step and the path; the temporary file is removed on failure.
// Not formats::AtomicOutputFile, gyroctl's: that one installs signal handlers to remove its
// temporaries, where gyrod takes its signals through its event loop.
void replaceStateFile(const std::string& path, std::string_view bytes);

}  // namespace gyrod::formats
