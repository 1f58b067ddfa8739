#include "tools/gyroctl/input.hpp"

#include "formats/edit_distance.hpp"
#include "tools/gyroctl/exit_codes.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
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
    if (!found) throwNoSuchAxis(rec, axis);
  }
  return in;
}

void throwNoSuchAxis(const recording::Recording& rec, const std::string& axis) {
  std::vector<std::string> have = rec.axis_names;
  for (std::size_t a = 0; a < recording::kAccelColumns.size(); ++a) {
    const std::string name(recording::kAccelColumns[a]);
    if (!rec.accel_g[a].empty() && std::find(have.begin(), have.end(), name) == have.end()) have.push_back(name);
  }
  std::string message = "--axis '" + axis + "': " + rec.path + " has no column '" + axis + "'";
  const auto nearest = std::min_element(have.begin(), have.end(), [&](const auto& x, const auto& y) {
    return formats::editDistance(axis, x) < formats::editDistance(axis, y);
  });
  // Only a near miss is a suggestion, as for an unknown command (main.cpp).
  if (nearest != have.end() && formats::editDistance(axis, *nearest) <= std::max<std::size_t>(1, axis.size() / 3))
    message += "; did you mean '" + *nearest + "'?";
  std::string list;
  for (const auto& n : have) list += (list.empty() ? "" : ",") + n;
  throw ExitError(ExitCode::Usage, message + " (the file has " + list + "; or all)");
}

bool stderrIsTerminal() { return ::isatty(STDERR_FILENO) == 1; }

std::function<void(std::size_t, std::uint64_t)> readingProgress(const std::string& path) {
  if (!stderrIsTerminal()) return {};
  struct stat st {};
  const std::uint64_t total = ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) ? st.st_size : 0;
  return [path, total](std::size_t lines, std::uint64_t bytes) {
    if (total > 0)
      std::fprintf(stderr, "\rreading %s: %.0f %% (%.1f M lines)\033[K", path.c_str(),
                   100.0 * static_cast<double>(bytes) / static_cast<double>(total), static_cast<double>(lines) / 1e6);
    else
      std::fprintf(stderr, "\rreading %s: %.1f M lines\033[K", path.c_str(), static_cast<double>(lines) / 1e6);
  };
}

}  // namespace gyrod::gyroctl
