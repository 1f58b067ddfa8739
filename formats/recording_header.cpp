#include "formats/recording_header.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "formats/input_file.hpp"
#include "formats/recording_csv.hpp"
#include "formats/toml_document.hpp"

namespace gyrod::recording {
namespace {

constexpr std::string_view kDevicePrefix = "# device ";
constexpr std::size_t kMaxHeaderRead = 64 * 1024;

[[noreturn]] void fail(const std::string& path, std::size_t line, const std::string& what) {
  throw RecordingError(path + ":" + std::to_string(line) + ": " + what);
}

int parseInt(std::string_view key, std::string_view value, int lo, int hi, const std::string& path, std::size_t line) {
  int v = 0;
  const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
  if (ec != std::errc() || end != value.data() + value.size() || v < lo || v > hi)
    fail(path, line,
         "device header: " + std::string(key) + "='" + std::string(value) + "' is not an integer " +
             std::to_string(lo) + ".." + std::to_string(hi));
  return v;
}

double parseRate(std::string_view value, const std::string& path, std::size_t line) {
  const std::string s(value);
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v) || v <= 0.0)
    fail(path, line, "device header: rate_hz='" + s + "' is not a positive number");
  return v;
}

void parseDeviceLine(std::string_view rest, const std::string& path, std::size_t line, AcquisitionHeader& h) {
  h.line = line;
  std::size_t pos = 0;
  while (pos < rest.size()) {
    while (pos < rest.size() && rest[pos] == ' ') ++pos;
    if (pos >= rest.size()) break;
    std::size_t end = rest.find(' ', pos);
    if (end == std::string_view::npos) end = rest.size();
    const std::string_view token = rest.substr(pos, end - pos);
    pos = end;
    const std::size_t eq = token.find('=');
    if (eq == std::string_view::npos || eq == 0)
      fail(path, line, "device header: '" + std::string(token) + "' is not key=value");
    const std::string_view key = token.substr(0, eq), value = token.substr(eq + 1);
    if (key == "dlpf_cfg")
      h.dlpf_cfg = parseInt(key, value, 0, 6, path, line);
    else if (key == "fs_sel")
      h.fs_sel = parseInt(key, value, 0, 3, path, line);
    else if (key == "smplrt_div")
      h.smplrt_div = parseInt(key, value, 0, 255, path, line);
    else if (key == "rate_hz")
      h.rate_hz = parseRate(value, path, line);
    // Other keys: a later writer's, skipped.
  }
  if (h.dlpf_cfg && h.smplrt_div && h.rate_hz) {
    const double internal = *h.dlpf_cfg == 0 ? 8000.0 : 1000.0;
    const double made = internal / (1.0 + *h.smplrt_div);
    if (std::fabs(made - *h.rate_hz) > 1e-9 * made)
      fail(path, line,
           "device header: rate_hz=" + formats::shortest(*h.rate_hz) + " is not " + formats::shortest(internal) +
               " Hz / (1 + smplrt_div=" + std::to_string(*h.smplrt_div) + ") = " + formats::shortest(made) + " Hz");
  }
}

}  // namespace

std::string acquisitionHeaderComment(int dlpf_cfg, int fs_sel, double rate_hz, int smplrt_div) {
  return "device dlpf_cfg=" + std::to_string(dlpf_cfg) + " fs_sel=" + std::to_string(fs_sel) +
         " rate_hz=" + formats::shortest(rate_hz) + " smplrt_div=" + std::to_string(smplrt_div);
}

AcquisitionHeader parseAcquisitionHeader(std::string_view text, const std::string& path) {
  AcquisitionHeader h;
  std::size_t pos = 0, line = 0;
  bool seen_columns = false;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view l = text.substr(pos, end - pos);
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    ++line;
    pos = end + 1;
    // The header is the comments before the first sample: before the column line, and after it
    // where gyrod writes them (docs/recording-format.md: line 1 is the column line).
    if (l.empty()) break;
    if (l.front() != '#') {
      const bool column_line = !seen_columns && std::isalpha(static_cast<unsigned char>(l.front()));
      if (!column_line) break;
      seen_columns = true;
      continue;
    }
    if (l.starts_with(kDevicePrefix)) parseDeviceLine(l.substr(kDevicePrefix.size()), path, line, h);
    if (l.size() >= 2 && l.substr(2).starts_with(kCalibrationStatePrefix)) {
      if (h.calibration_state_line == 0) h.calibration_state_line = line;
      h.calibration_state_toml += std::string(l.substr(2 + kCalibrationStatePrefix.size())) + "\n";
    }
  }
  return h;
}

std::vector<std::string> calibrationStateHeaderComments(std::string_view toml) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (pos < toml.size()) {
    std::size_t end = toml.find('\n', pos);
    if (end == std::string_view::npos) end = toml.size();
    const std::string_view l = toml.substr(pos, end - pos);
    pos = end + 1;
    if (l.empty() || l.front() == '#') continue;
    out.push_back(std::string(kCalibrationStatePrefix) + std::string(l));
  }
  return out;
}

AcquisitionHeader readAcquisitionHeader(const std::string& path) {
  formats::InputFile in;
  try {
    in = formats::openInputFile(path, formats::kRecordingInput);
  } catch (const formats::InputFileError&) {
    return {};  // the reading of the recording itself says why
  }
  std::string text(kMaxHeaderRead, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), in.get()));
  // Only whole lines: a comment cut at the end of the buffer is not parsed.
  const std::size_t last = text.rfind('\n');
  if (text.size() == kMaxHeaderRead && last != std::string::npos) text.resize(last + 1);
  return parseAcquisitionHeader(text, path);
}

}  // namespace gyrod::recording
