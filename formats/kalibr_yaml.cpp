#include "formats/kalibr_yaml.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "formats/csv_fields.hpp"
#include "formats/quoted_value.hpp"

namespace gyrod::formats {
namespace {

using recording::parseNumber;
using recording::trimField;

// Six significant digits, as Kalibr's own files carry far fewer: the fit's 1-σ is rarely
// below 0.1 %, so more digits would only look precise.
std::string sixDigits(double v) {
  std::array<char, 32> buf{};
  std::snprintf(buf.data(), buf.size(), "%.6g", v);
  return buf.data();
}

void writeValue(std::string& out, std::string_view key, const KalibrValue& v, std::string_view unit) {
  if (v.value) {
    std::string line = std::string(key) + ": " + sixDigits(*v.value);
    line.resize(std::max<std::size_t>(line.size(), 42), ' ');
    out += line + "  # [" + std::string(unit) + "]" + (v.note.empty() ? "" : " " + v.note) + "\n";
  } else {
    out += "# " + std::string(key) + ": not estimated" + (v.note.empty() ? "" : " (" + v.note + ")") + "\n";
  }
}

// "key: value" with comments removed; empty key for an empty or comment line.
std::pair<std::string_view, std::string_view> keyAndValue(std::string_view line, const std::string& name,
                                                          std::size_t line_no) {
  if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
  line = trimField(line);
  if (line.empty()) return {};
  const auto colon = line.find(':');
  if (colon == std::string_view::npos)
    throw std::runtime_error(name + ":" + std::to_string(line_no) + ": " + quotedValue(line) + " is not 'key: value'");
  return {trimField(line.substr(0, colon)), trimField(line.substr(colon + 1))};
}

}  // namespace

std::string kalibrImuYaml(const KalibrImu& imu) {
  std::string out;
  for (const auto& c : imu.header_comments) out += (c.empty() ? "#" : "# " + c) + "\n";
  out += "\n#Accelerometers\n";
  writeValue(out, "accelerometer_noise_density", imu.accelerometer_noise_density, "m/s^2/sqrt(Hz)");
  writeValue(out, "accelerometer_random_walk", imu.accelerometer_random_walk, "m/s^3/sqrt(Hz)");
  out += "\n#Gyroscopes\n";
  writeValue(out, "gyroscope_noise_density", imu.gyroscope_noise_density, "rad/s/sqrt(Hz)");
  writeValue(out, "gyroscope_random_walk", imu.gyroscope_random_walk, "rad/s^2/sqrt(Hz)");
  out += "\nrostopic: " + imu.rostopic + "\n";
  out += "update_rate: " + sixDigits(imu.update_rate_hz) + "  # [Hz] (for discretization of the values above)\n";
  return out;
}

KalibrImu parseKalibrImuYaml(std::string_view text, const std::string& name) {
  KalibrImu imu;
  imu.rostopic.clear();
  std::size_t line_no = 0;
  while (!text.empty()) {
    const auto nl = text.find('\n');
    const std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
    ++line_no;
    const auto [key, value] = keyAndValue(line, name, line_no);
    if (key.empty()) continue;
    if (key == "rostopic") {
      imu.rostopic = std::string(value);
      continue;
    }
    const auto number = parseNumber(value);
    const auto where = name + ":" + std::to_string(line_no) + ": ";
    if (!number || !std::isfinite(*number))
      throw std::runtime_error(where + std::string(key) + ": " + quotedValue(value) + " is not a number");
    if (key == "accelerometer_noise_density")
      imu.accelerometer_noise_density.value = *number;
    else if (key == "accelerometer_random_walk")
      imu.accelerometer_random_walk.value = *number;
    else if (key == "gyroscope_noise_density")
      imu.gyroscope_noise_density.value = *number;
    else if (key == "gyroscope_random_walk")
      imu.gyroscope_random_walk.value = *number;
    else if (key == "update_rate")
      imu.update_rate_hz = *number;
    else
      throw std::runtime_error(where + "unknown key " + quotedValue(key));
  }
  return imu;
}

}  // namespace gyrod::formats
