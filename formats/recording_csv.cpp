#include "formats/recording_csv.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>

#include "formats/csv_fields.hpp"
#include "formats/quoted_value.hpp"

namespace gyrod::recording {
namespace {

constexpr std::array<std::string_view, 8> kKnownColumns = {"t", "gx", "gy", "gz", "temp", "wx", "wy", "wz"};

[[noreturn]] void fail(const std::string& path, std::size_t line, const std::string& cause) {
  std::ostringstream s;
  s << path;
  if (line > 0) s << ':' << line;
  s << ": " << cause;
  throw RecordingError(s.str());
}

bool isSkippable(std::string_view line) { return line.empty() || line.front() == '#'; }

}  // namespace

std::optional<std::size_t> axisOfColumn(std::string_view column) {
  for (std::size_t a = 0; a < kGyroColumns.size(); ++a)
    if (column == kGyroColumns[a]) return a;
  if (column == kBareNumbersColumn) return 0;
  return std::nullopt;
}

const std::vector<double>* Recording::axis(const std::string& name) const {
  for (std::size_t i = 0; i < axis_names.size(); ++i)
    if (axis_names[i] == name) return &axes[i];
  return nullptr;
}

Recording readRecordingCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path, 0, std::string("cannot open: ") + std::strerror(errno));
  return parseRecordingCsv(in, path);
}

Recording parseRecordingCsv(std::istream& in, const std::string& path) {
  Recording rec;
  rec.path = path;
  BoundedLineReader reader(in);
  std::size_t line_no = 0;
  // The next line, trimmed; nullopt at the end. A line past the limit stops the reading.
  const auto nextLine = [&]() -> std::optional<std::string_view> {
    const auto result = reader.next();
    if (result == BoundedLineReader::Result::End) return std::nullopt;
    ++line_no;
    if (result == BoundedLineReader::Result::TooLong) fail(path, line_no, lineTooLongCause(reader.maxBytes()));
    return trimField(reader.line());
  };

  // First meaningful line: a header, or the first of a column of bare numbers.
  // Empty lines and comments are skipped; GAP and DROPPED lines are kept as records.
  const auto skippable = [&](std::string_view line) {
    if (!isSkippable(line)) return false;
    if (auto lost = parseLostSamplesLine(line)) {
      lost->line = line_no;
      lost->before_sample = rec.size();
      rec.lost.push_back(std::move(*lost));
    }
    return true;
  };
  std::string_view first;
  while (const auto line = nextLine()) {
    first = *line;
    if (!skippable(first)) break;
  }
  if (isSkippable(first)) fail(path, 0, "empty file: no header and no samples");

  enum class Role { T, Axis, Temp, Truth };
  std::vector<std::pair<Role, std::size_t>> roles;  // per column: what it feeds, axis index
  bool bare_numbers = false;
  std::size_t header_line = line_no;
  if (parseNumber(first)) {
    bare_numbers = true;
    rec.axis_names = {std::string(kBareNumbersColumn)};
    rec.axes.resize(1);
    roles = {{Role::Axis, 0}};
  } else {
    const auto names = splitFields(first);
    if (names.size() == 1 && first.find(',') == std::string_view::npos &&
        std::find(kKnownColumns.begin(), kKnownColumns.end(), names[0]) == kKnownColumns.end())
      fail(path, line_no,
           formats::quotedValue(names[0]) + " is neither a number nor a header of columns t,gx,gy,gz,temp");
    bool have_t = false, have_temp = false;
    for (auto name : names) {
      if (std::find(kKnownColumns.begin(), kKnownColumns.end(), name) == kKnownColumns.end())
        fail(path, line_no,
             "unknown column " + formats::quotedValue(name) + " (expected any of t,gx,gy,gz,temp,wx,wy,wz)");
      for (std::size_t j = 0; j < roles.size(); ++j)
        if (names[j] == name) fail(path, line_no, "column '" + std::string(name) + "' appears twice");
      if (name == "t") {
        roles.push_back({Role::T, 0});
        have_t = true;
      } else if (name == "temp") {
        roles.push_back({Role::Temp, 0});
        have_temp = true;
      } else if (const auto truth = std::find(kTruthColumns.begin(), kTruthColumns.end(), name);
                 truth != kTruthColumns.end()) {
        roles.push_back({Role::Truth, static_cast<std::size_t>(truth - kTruthColumns.begin())});
      } else {
        roles.push_back({Role::Axis, rec.axis_names.size()});
        rec.axis_names.emplace_back(name);
      }
    }
    if (rec.axis_names.empty()) fail(path, line_no, "no gyro column: the header needs at least one of gx,gy,gz");
    rec.axes.resize(rec.axis_names.size());
    (void)have_t;
    (void)have_temp;
  }

  auto consume = [&](std::string_view line) {
    const auto fields = splitFields(line);
    if (fields.size() != roles.size()) {
      std::ostringstream s;
      s << "expected " << roles.size() << " field" << (roles.size() == 1 ? "" : "s") << ", found " << fields.size();
      fail(path, line_no, s.str());
    }
    rec.line_numbers.push_back(line_no);
    for (std::size_t c = 0; c < fields.size(); ++c) {
      const std::string column = bare_numbers                    ? std::string("value")
                                 : roles[c].first == Role::T     ? std::string("t")
                                 : roles[c].first == Role::Temp  ? std::string("temp")
                                 : roles[c].first == Role::Truth ? std::string(kTruthColumns[roles[c].second])
                                                                 : rec.axis_names[roles[c].second];
      const auto value = parseNumber(fields[c]);
      if (!value)
        fail(path, line_no, "column '" + column + "': " + formats::quotedValue(fields[c]) + " is not a number");
      if (!std::isfinite(*value))
        fail(path, line_no, "column '" + column + "': non-finite value " + formats::quotedValue(fields[c]));
      switch (roles[c].first) {
        case Role::T: rec.t.push_back(*value); break;
        case Role::Temp: rec.temp.push_back(*value); break;
        case Role::Axis: rec.axes[roles[c].second].push_back(*value); break;
        case Role::Truth: rec.true_rate[roles[c].second].push_back(*value); break;
      }
    }
  };

  if (bare_numbers) consume(first);
  while (const auto next = nextLine()) {
    const auto line = *next;
    if (skippable(line)) continue;
    if (bare_numbers && line.find(',') != std::string_view::npos)
      fail(path, line_no, "more than one column in a file of bare numbers (add a header t,gx,gy,gz,temp)");
    consume(line);
  }
  if (in.bad()) fail(path, line_no, std::string("read error: ") + std::strerror(errno));
  if (rec.size() == 0) fail(path, header_line, "no samples after the header");
  return rec;
}

double sampleRateFromTimes(const Recording& r) {
  if (r.t.size() < 2) throw RecordingError(r.path + ": need at least two samples in column 't' to infer the rate");
  std::vector<double> dt(r.t.size() - 1);
  for (std::size_t i = 1; i < r.t.size(); ++i) {
    dt[i - 1] = r.t[i] - r.t[i - 1];
    if (!(dt[i - 1] > 0.0)) {
      std::ostringstream s;
      s.precision(17);
      s << r.path << ':' << (i < r.line_numbers.size() ? r.line_numbers[i] : i + 1)
        << ": column 't' is not strictly increasing (t = " << r.t[i] << " after " << r.t[i - 1] << ")";
      throw RecordingError(s.str());
    }
  }
  auto mid = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
  std::nth_element(dt.begin(), mid, dt.end());
  if (!std::isfinite(1.0 / *mid)) {  // steps of 1e-320 s are positive, but no rate
    std::ostringstream s;
    s.precision(17);
    s << r.path << ": column 't' steps by " << *mid << " s, too small for a sample rate";
    throw RecordingError(s.str());
  }
  return 1.0 / *mid;
}

}  // namespace gyrod::recording
