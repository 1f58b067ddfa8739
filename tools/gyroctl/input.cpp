#include "tools/gyroctl/input.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <stdexcept>

namespace gyrod::gyroctl {

LoadedInput loadInput(const std::string& path, std::optional<double> rate_hz, const std::string& axis,
                      const recording::ReadOptions& read) {
  LoadedInput in;
  if (rate_hz && !(std::isfinite(*rate_hz) && *rate_hz > 0.0)) {
    std::ostringstream s;
    s << "--rate " << *rate_hz << ": the sample rate must be a positive number of Hz";
    throw std::invalid_argument(s.str());
  }
  requireNotADirectory(path);
  in.recording = recording::readRecordingCsv(path, read);
  const auto& rec = in.recording;
  if (!rec.t.empty()) {
    const double from_t = recording::sampleRateFromTimes(rec);
    if (rate_hz && std::abs(*rate_hz - from_t) > 0.01 * from_t) {
      std::ostringstream s;
      s << path << ": --rate " << *rate_hz << " Hz disagrees with column 't' (median spacing " << 1.0 / from_t
        << " s, i.e. " << from_t << " Hz)";
      throw recording::RecordingError(s.str());
    }
    in.rate_hz = rate_hz ? *rate_hz : from_t;
    in.rate_source = rate_hz ? "--rate (agrees with t)" : "median spacing of t";
  } else if (rate_hz) {
    in.rate_hz = *rate_hz;
    in.rate_source = "--rate";
  } else {
    in.rate_hz = 50.0;
    in.rate_source = "default (no t column)";
  }

  if (axis == "all") {
    for (std::size_t i = 0; i < rec.axis_names.size(); ++i) in.axis_indices.push_back(i);
  } else {
    bool found = false;
    for (std::size_t i = 0; i < rec.axis_names.size(); ++i)
      if (rec.axis_names[i] == axis) {
        in.axis_indices.push_back(i);
        found = true;
      }
    if (!found) {
      std::string have;
      for (const auto& n : rec.axis_names) have += (have.empty() ? "" : ",") + n;
      throw recording::RecordingError(path + ": no column '" + axis + "' (the file has " + have + ")");
    }
  }
  return in;
}

void requireNotADirectory(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw recording::RecordingError(path + ": cannot read: it is a directory, not a file");
}

}  // namespace gyrod::gyroctl
