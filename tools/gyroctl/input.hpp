#pragma once
// Loading a recording for an offline command: read, pick axes, settle the sample rate.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "formats/recording_csv.hpp"

namespace gyrod::gyroctl {

struct LoadedInput {
  recording::Recording recording;
  double rate_hz = 0.0;
  std::string rate_source;                // "t column", "--rate", "default"
  std::vector<std::size_t> axis_indices;  // into recording.axes, in output order
};

// rate: from --rate when given; must agree with the t column (1 % tolerance) if present.
// axis: "all" or a column name. Throws RecordingError naming the file and the problem.
// `read` passes on to readRecordingCsv (line numbers kept or not, progress).
LoadedInput loadInput(const std::string& path, std::optional<double> rate_hz, const std::string& axis,
                      const recording::ReadOptions& read = {});

// The --axis value names no column of `rec`: ExitError(Usage) naming the value, the file,
// the nearest column when it is a near miss, and every gyro and accelerometer column it has.
[[noreturn]] void throwNoSuchAxis(const recording::Recording& rec, const std::string& axis);

// Progress on stderr for long inputs, only when stderr is a terminal (a log or a pipe gets
// nothing): from kProgressSamples samples on, as the reading and the analysis go.
inline constexpr std::size_t kProgressSamples = std::size_t{1} << 20;
bool stderrIsTerminal();
// "reading FILE: 37 % (4.2 M lines)" as readRecordingCsv reports; empty when stderr is not
// a terminal.
std::function<void(std::size_t, std::uint64_t)> readingProgress(const std::string& path);

}  // namespace gyrod::gyroctl
