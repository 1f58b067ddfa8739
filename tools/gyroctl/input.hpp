#pragma once
// Loading a recording for an offline command: read, pick axes, settle the sample rate.
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

// Refuses a directory as an input file, saying so (reading one would look like an empty
// file). FIFOs and devices stay readable: `analyze /dev/stdin` works.
void requireNotADirectory(const std::string& path);

}  // namespace gyrod::gyroctl
