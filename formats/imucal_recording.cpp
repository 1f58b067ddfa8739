#include "formats/imucal_recording.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <istream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "formats/csv_fields.hpp"
#include "formats/quoted_value.hpp"
#include "formats/recording_csv.hpp"

namespace gyrod::recording {
namespace {

[[noreturn]] void fail(const std::string& path, std::size_t line, const std::string& cause) {
  std::ostringstream s;
  s << path << ':' << line << ": " << cause;
  throw RecordingError(s.str());
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream ss(line);
  std::string item;
  while (std::getline(ss, item, ',')) {
    while (!item.empty() && (item.back() == '\r' || item.back() == ' ')) item.pop_back();
    while (!item.empty() && item.front() == ' ') item.erase(item.begin());
    f.push_back(item);
  }
  if (!line.empty() && line.back() == ',') f.emplace_back();
  return f;
}

bool parseLong(const std::string& s, long& v) {
  if (s.empty()) return false;
  std::size_t used = 0;
  try {
    v = std::stol(s, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used == s.size();
}

// One output column: its name, where it is in the logger's line, and its counts per unit.
struct ImucalColumn {
  std::string_view name;
  std::size_t field = 0;
  double lsb_per_unit = 1.0;
};

// The gyro columns present (°/s), then the accelerometer columns present (g).
std::vector<ImucalColumn> outputColumns(const std::vector<std::string>& columns, double lsb_per_dps, double lsb_per_g) {
  std::vector<ImucalColumn> out;
  const auto add = [&](const auto& names, double lsb) {
    for (const auto name : names)
      for (std::size_t c = 0; c < columns.size(); ++c)
        if (columns[c] == name) out.push_back({name, c, lsb});
  };
  add(kGyroColumns, lsb_per_dps);
  add(kAccelColumns, lsb_per_g);
  return out;
}

}  // namespace

ImucalConversion convertImucal(std::istream& in, const std::string& path, int fs_sel, int afs_sel) {
  if (fs_sel < 0 || fs_sel > 3) throw std::invalid_argument("FS_SEL " + std::to_string(fs_sel) + " is not in 0..3");
  if (afs_sel < 0 || afs_sel > 3) throw std::invalid_argument("AFS_SEL " + std::to_string(afs_sel) + " is not in 0..3");
  BoundedLineReader reader(in);
  std::string line;
  std::size_t line_no = 0;
  auto next = [&]() -> bool {
    const auto result = reader.next();
    if (result == BoundedLineReader::Result::End) return false;
    ++line_no;
    if (result == BoundedLineReader::Result::TooLong) fail(path, line_no, lineTooLongCause(reader.maxBytes()));
    line.assign(reader.line());
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  if (!next()) throw RecordingError(path + ": empty file");
  auto first = splitCsv(line);
  if (first.size() != 2 || first[0] != "Fs")
    fail(path, line_no,
         "not an imucal recording: the first line should be 'Fs,<rate>' (found " + formats::quotedValue(line) + ")");
  ImucalConversion result;
  char* end = nullptr;
  result.rate_hz = std::strtod(first[1].c_str(), &end);
  const double fs = result.rate_hz;
  if (end == first[1].c_str() || *end != '\0' || !(fs > 0.0) || !std::isfinite(fs))
    fail(path, line_no, "sample rate " + formats::quotedValue(first[1]) + " is not a positive number");

  // Skip the remaining key,value header lines up to the column names.
  std::vector<std::string> columns;
  while (next()) {
    auto f = splitCsv(line);
    long dummy = 0;
    if (!f.empty() && !parseLong(f[0], dummy) && (f.size() != 2 || f[0] == "ax" || f[0] == "gx")) {
      columns = f;
      break;
    }
  }
  if (columns.empty()) fail(path, line_no, "no column-name line (ax,ay,az,gx,gy,gz) found");
  // A sensor column once: given twice it would be converted twice, and no reader could tell
  // which of the two is the sensor's.
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const bool sensor = std::find(kGyroColumns.begin(), kGyroColumns.end(), columns[c]) != kGyroColumns.end() ||
                        std::find(kAccelColumns.begin(), kAccelColumns.end(), columns[c]) != kAccelColumns.end();
    const auto before = columns.begin() + static_cast<std::ptrdiff_t>(c);
    if (sensor && std::find(columns.begin(), before, columns[c]) != before)
      fail(path, line_no, "column " + formats::quotedValue(columns[c]) + " appears twice");
  }
  result.lsb_per_dps = kGyroLsbPerDps[fs_sel];
  result.lsb_per_g = kAccelLsbPerG[afs_sel];
  const auto outputs = outputColumns(columns, result.lsb_per_dps, result.lsb_per_g);
  const auto is_gyro = [](const ImucalColumn& c) {
    return std::find(kGyroColumns.begin(), kGyroColumns.end(), c.name) != kGyroColumns.end();
  };
  if (std::none_of(outputs.begin(), outputs.end(), is_gyro))
    fail(path, line_no, "no gyro column (gx, gy or gz) in " + formats::quotedValue(line));
  result.accel_columns = static_cast<std::size_t>(
      std::count_if(outputs.begin(), outputs.end(), [&](const ImucalColumn& c) { return !is_gyro(c); }));

  std::string& out = result.csv;
  out = "t";
  for (const auto& c : outputs) out += "," + std::string(c.name);
  out += '\n';
  std::size_t& samples = result.samples;
  char buf[40];
  while (next()) {
    if (line.empty()) continue;
    auto f = splitCsv(line);
    if (f.size() != columns.size()) {
      std::ostringstream s;
      s << "expected " << columns.size() << " fields, found " << f.size();
      fail(path, line_no, s.str());
    }
    const double t = static_cast<double>(samples) / fs;
    if (!std::isfinite(t))  // a rate of 1e-320 Hz reads as positive, but its times overflow
      fail(path, line_no,
           "sample rate " + formats::quotedValue(first[1]) + " is too small: t = " + std::to_string(samples) +
               " / Fs is not a finite number");
    std::snprintf(buf, sizeof buf, "%.17g", t);
    out += buf;
    for (const auto& c : outputs) {
      long counts = 0;
      const auto& field = f[c.field];
      if (!parseLong(field, counts))
        fail(path, line_no,
             "column '" + std::string(c.name) + "': " + formats::quotedValue(field) + " is not an integer count");
      if (counts < -32768 || counts > 32767)
        fail(path, line_no, "column '" + std::string(c.name) + "': " + field + " is outside the 16-bit range");
      std::snprintf(buf, sizeof buf, ",%.17g", static_cast<double>(counts) / c.lsb_per_unit);
      out += buf;
    }
    out += '\n';
    ++samples;
  }
  if (samples == 0) fail(path, line_no, "no samples after the header");
  return result;
}

}  // namespace gyrod::recording
