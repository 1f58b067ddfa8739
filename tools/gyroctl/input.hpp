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
LoadedInput loadInput(const std::string& path, std::optional<double> rate_hz, const std::string& axis);

// Writes `text` to `path` through a temporary file in the same folder and a rename, so
// an existing file is replaced only by a complete one. Throws std::runtime_error.
void writeFileAtomically(const std::string& path, const std::string& text);

}  // namespace gyrod::gyroctl
