#pragma once
// Recording files: CSV with a header naming any of the columns t,gx,gy,gz,temp
// (seconds, °/s, °/s, °/s, °C), or a file of bare numbers (one column, one axis).
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace gyrod::recording {

// A problem with an input file, already phrased for the user: "FILE:LINE: cause".
class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Recording {
  std::string path;
  std::vector<double> t;                 // empty when the file has no t column
  std::vector<std::string> axis_names;   // "gx", "gy", "gz" in file order (or "x" for bare numbers)
  std::vector<std::vector<double>> axes; // one vector per axis_names entry
  std::vector<double> temp;              // empty when absent
  std::vector<std::size_t> line_numbers; // file line of each sample, for error messages
  std::size_t size() const { return axes.empty() ? 0 : axes.front().size(); }
  const std::vector<double>* axis(const std::string& name) const;
};

// Reads and validates the whole file. Throws RecordingError naming file, line and cause.
Recording readRecordingCsv(const std::string& path);

// Sample rate implied by t: 1 / median spacing. Throws RecordingError if t is not
// strictly increasing (naming file and line).
double sampleRateFromTimes(const Recording& r);

}  // namespace gyrod::recording
