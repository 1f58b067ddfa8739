#include "formats/calibration_state.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>
#include <vector>

#include "formats/toml_document.hpp"

namespace gyrod::formats {
namespace {

constexpr std::string_view kAxisNames[] = {"x", "y", "z"};
const std::vector<std::string_view> kTopKeys = {"format",
                                                "version",
                                                "model",
                                                "rate_hz",
                                                "saved_unix_s",
                                                "data_time_s",
                                                "temperature_c",
                                                "temperature_origin_c",
                                                "still_temperature_min_c",
                                                "still_temperature_max_c",
                                                "still_samples",
                                                "x",
                                                "y",
                                                "z"};
const std::vector<std::string_view> kAxisKeys = {"offset_dps", "slope_dps_per_c", "var_offset", "cov_offset_slope",
                                                 "var_slope"};

void appendNumber(std::string& out, std::string_view key, double v) {
  out += std::string(key) + " = " + shortest(v);
  if (out.find_first_of(".eEin", out.rfind('=')) == std::string::npos) out += ".0";  // a TOML float
  out += '\n';
}

// Required keys: absent is an error naming the key.
double requiredNumber(const TomlDocument& doc, const TomlSection& s, std::string_view key) {
  if (const auto v = s.number(key)) return *v;
  doc.failFile("key '" + s.qualified(key) + "' is missing");
}

}  // namespace

std::string fnv1a64Hex(std::string_view text) {
  std::uint64_t h = 0xcbf29ce484222325ULL;  // FNV-1a 64: offset basis and prime
  for (const char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string biasModelFingerprint(const processing::RateEstimatorParameters& params) {
  std::string text;
  for (const processing::AxisBiasModel& m : params.axes)
    text += shortest(m.bias_dps) + ' ' + shortest(m.temperature_coefficient_dps_per_c) + ' ' +
            shortest(m.temperature_reference_c) + ' ' + shortest(m.warm_up_amplitude_dps) + ' ' +
            shortest(m.warm_up_time_constant_s) + '\n';
  return fnv1a64Hex(text);
}

std::string calibrationStateToToml(const CalibrationState& state) {
  const processing::LearnedResidual& r = state.residual;
  std::string out =
      "# gyrod's calibration state: what the rate stream's residual filter learned on this board, relative to\n"
      "# the sensor model whose fingerprint is `model` (docs/calibration-state.md). Written by gyrod, read at its\n"
      "# start; residual = offset + slope * (T - temperature_origin_c), var/cov of [offset, slope].\n";
  out += "format = \"" + std::string(kCalibrationStateFormat) + "\"\n";
  out += "version = " + std::to_string(kCalibrationStateVersion) + "\n";
  out += "model = \"" + state.model + "\"\n";
  appendNumber(out, "rate_hz", state.rate_hz);
  appendNumber(out, "saved_unix_s", state.saved_unix_s);
  appendNumber(out, "data_time_s", state.data_time_s);
  appendNumber(out, "temperature_c", r.temperature_c);
  appendNumber(out, "temperature_origin_c", r.temperature_origin_c);
  if (!std::isnan(r.still_temperature_min_c)) {
    appendNumber(out, "still_temperature_min_c", r.still_temperature_min_c);
    appendNumber(out, "still_temperature_max_c", r.still_temperature_max_c);
  }
  out += "still_samples = " + std::to_string(r.still_samples) + "\n";
  for (std::size_t a = 0; a < 3; ++a) {
    const processing::LearnedResidualAxis& x = r.axes[a];
    out += "\n[" + std::string(kAxisNames[a]) + "]\n";
    appendNumber(out, "offset_dps", x.offset_dps);
    appendNumber(out, "slope_dps_per_c", x.slope_dps_per_c);
    appendNumber(out, "var_offset", x.var_offset);
    appendNumber(out, "cov_offset_slope", x.cov_offset_slope);
    appendNumber(out, "var_slope", x.var_slope);
  }
  return out;
}

CalibrationState parseCalibrationStateToml(std::string_view text, const std::string& file) {
  try {
    const TomlDocument doc(text, file);
    const TomlSection top(file, doc.root(), "", kTopKeys);
    const auto format = top.string("format");
    if (!format) doc.failFile("not a gyrod calibration state file: key 'format' is missing");
    if (*format != kCalibrationStateFormat)
      top.failValue("format", "must be \"" + std::string(kCalibrationStateFormat) + "\"");
    const auto version = top.integer("version");
    if (!version) doc.failFile("key 'version' is missing");
    if (*version != kCalibrationStateVersion)
      top.failValue("version", "this gyrod reads version " + std::to_string(kCalibrationStateVersion));
    CalibrationState s;
    const auto model = top.string("model");
    if (!model) doc.failFile("key 'model' is missing");
    s.model = *model;
    s.rate_hz = requiredNumber(doc, top, "rate_hz");
    if (!(s.rate_hz > 0.0)) top.failValue("rate_hz", "must be > 0");
    s.saved_unix_s = requiredNumber(doc, top, "saved_unix_s");
    s.data_time_s = requiredNumber(doc, top, "data_time_s");
    if (s.data_time_s < 0.0) top.failValue("data_time_s", "must be >= 0");
    processing::LearnedResidual& r = s.residual;
    r.temperature_c = requiredNumber(doc, top, "temperature_c");
    r.temperature_origin_c = requiredNumber(doc, top, "temperature_origin_c");
    const auto lo = top.number("still_temperature_min_c"), hi = top.number("still_temperature_max_c");
    if (lo.has_value() != hi.has_value())
      doc.failFile("keys 'still_temperature_min_c' and 'still_temperature_max_c' come together");
    if (lo) {
      r.still_temperature_min_c = *lo;
      r.still_temperature_max_c = *hi;
    }
    const auto samples = top.integer("still_samples");
    if (!samples) doc.failFile("key 'still_samples' is missing");
    if (*samples < 0) top.failValue("still_samples", "must be >= 0");
    r.still_samples = static_cast<std::size_t>(*samples);
    for (std::size_t a = 0; a < 3; ++a) {
      const std::string_view name = kAxisNames[a];
      const toml::table* t = doc.root()[name].as_table();
      if (t == nullptr) doc.failFile("table [" + std::string(name) + "] is missing");
      const TomlSection axis(file, *t, std::string(name), kAxisKeys);
      processing::LearnedResidualAxis& x = r.axes[a];
      x.offset_dps = requiredNumber(doc, axis, "offset_dps");
      x.slope_dps_per_c = requiredNumber(doc, axis, "slope_dps_per_c");
      x.var_offset = requiredNumber(doc, axis, "var_offset");
      x.cov_offset_slope = requiredNumber(doc, axis, "cov_offset_slope");
      x.var_slope = requiredNumber(doc, axis, "var_slope");
    }
    try {
      processing::validateLearnedResidual(r);
    } catch (const std::invalid_argument& e) {
      doc.failFile(e.what());
    }
    return s;
  } catch (const TomlError& e) {
    throw CalibrationStateError(e.what());
  }
}

CalibrationState readCalibrationStateToml(const std::string& path) {
  return parseCalibrationStateToml(readInputFile(path, kCalibrationStateInput), path);
}

void replaceStateFile(const std::string& path, std::string_view bytes) {
  const std::string temp = path + ".tmp";
  auto fail = [&](const std::string& step) {
    const int error = errno;
    ::unlink(temp.c_str());
    throw std::system_error(error, std::generic_category(), step + " " + temp);
  };
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) fail("cannot create");
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : EIO;
      ::close(fd);
      errno = error;
      fail("cannot write");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    errno = error;
    fail("cannot fsync");
  }
  if (::close(fd) != 0) fail("cannot close");
  if (::rename(temp.c_str(), path.c_str()) != 0) fail("cannot rename onto " + path + ":");
  // The rename is durable once the directory is: fsync it (failure here loses nothing written).
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  const int dir_fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

}  // namespace gyrod::formats
