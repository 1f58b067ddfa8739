#include "formats/motion_spec.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "formats/csv_fields.hpp"
#include "formats/input_file.hpp"
#include "formats/quoted_value.hpp"
#include "formats/recording_csv.hpp"

namespace gyrod::recording {
namespace {

using processing::MotionPoint;
using processing::MotionProfile;

// ---- profile text --------------------------------------------------------------------

struct KeyRule {
  std::string_view key;        // as the user writes it
  std::string_view parameter;  // the MotionProfile factory's name for it, in its messages
  bool required;
};
struct KindRule {
  std::string_view kind;
  std::vector<KeyRule> keys;  // "axis" first, always required
};

const std::array<KindRule, 4> kKinds = {{
    {"step", {{"axis", "axis", true}, {"at", "time_s", true}, {"rate", "rate_dps", true}}},
    {"sine",
     {{"axis", "axis", true},
      {"freq", "frequency_hz", true},
      {"amp", "amplitude_dps", true},
      {"start", "start_s", false},
      {"duration", "duration_s", false}}},
    {"constant",
     {{"axis", "axis", true},
      {"rate", "rate_dps", true},
      {"start", "start_s", false},
      {"duration", "duration_s", false}}},
    {"turns",
     {{"axis", "axis", true},
      {"count", "count", true},
      {"rate", "rate_dps", true},
      {"still", "still_s", false},
      {"start", "start_s", false}}},
}};

std::string kindNames() {
  std::string names;
  for (const KindRule& k : kKinds) names += (names.empty() ? "" : ", ") + std::string(k.kind);
  return names;
}

std::string keyNames(const KindRule& rule) {
  std::string names;
  for (const KeyRule& k : rule.keys) {
    names += (names.empty() ? "" : ", ") + std::string(k.key);
    if (!k.required) names += " (optional)";
  }
  return names;
}

[[noreturn]] void failText(const std::string& where, const std::string& cause) {
  throw std::invalid_argument("motion: " + where + (where.empty() ? "" : ": ") + cause);
}

bool isLowercaseWord(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= 'a' && c <= 'z'; });
}

// The profiles of a sum, split at each '+' that starts a new "word:" (a '+' inside a number,
// as in 1e+3 or rate=+5, stays where it is).
std::vector<std::string_view> splitTerms(std::string_view text) {
  std::vector<std::string_view> terms;
  std::size_t start = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '+') continue;
    const std::string_view rest = trimField(text.substr(i + 1));
    if (!isMotionProfileText(rest)) continue;
    terms.push_back(trimField(text.substr(start, i - start)));
    start = i + 1;
  }
  terms.push_back(trimField(text.substr(start)));
  return terms;
}

std::size_t parseAxis(std::string_view kind, std::string_view value) {
  if (value == "x") return 0;
  if (value == "y") return 1;
  if (value == "z") return 2;
  failText(std::string(kind), "axis must be x, y or z, got " + formats::quotedValue(value));
}

// The factory's message with its parameter names replaced by the keys the user wrote.
std::string inUserTerms(std::string message, const KindRule& rule) {
  for (const KeyRule& k : rule.keys) {
    const std::string from = std::string(rule.kind) + "." + std::string(k.parameter);
    for (auto at = message.find(from); at != std::string::npos; at = message.find(from, at + k.key.size()))
      message.replace(at, from.size(), k.key);
  }
  return message;
}

MotionProfile buildProfile(const KindRule& rule, std::size_t axis,
                           const std::vector<std::pair<std::string_view, double>>& values) {
  const auto value = [&](std::string_view key, double otherwise) {
    for (const auto& [k, v] : values)
      if (k == key) return v;
    return otherwise;
  };
  try {
    if (rule.kind == "step") return MotionProfile::step(axis, value("at", 0.0), value("rate", 0.0));
    if (rule.kind == "sine")
      return MotionProfile::sine(axis, value("freq", 0.0), value("amp", 0.0), value("start", 0.0),
                                 value("duration", MotionProfile::kForever));
    if (rule.kind == "constant")
      return MotionProfile::constant(axis, value("rate", 0.0), value("start", 0.0),
                                     value("duration", MotionProfile::kForever));
    return MotionProfile::turns(axis, value("count", 0.0), value("rate", 0.0), value("still", 0.0),
                                value("start", 0.0));
  } catch (const std::invalid_argument& e) {
    failText(std::string(rule.kind), inUserTerms(e.what(), rule));
  }
}

MotionProfile parseProfile(std::string_view term) {
  const auto colon = term.find(':');
  const std::string_view kind = trimField(term.substr(0, colon));
  const auto rule = std::find_if(kKinds.begin(), kKinds.end(), [&](const KindRule& k) { return k.kind == kind; });
  if (colon == std::string_view::npos || rule == kKinds.end())
    failText("", "unknown profile " + formats::quotedValue(kind) + " (profiles: " + kindNames() + ")");
  const std::string where(kind);
  std::optional<std::size_t> axis;
  std::vector<std::pair<std::string_view, double>> values;
  std::vector<std::string_view> seen;
  for (const std::string_view field : splitFields(term.substr(colon + 1))) {
    const auto equals = field.find('=');
    const std::string_view key = trimField(field.substr(0, equals));
    if (equals == std::string_view::npos)
      failText(where, formats::quotedValue(field) + " is not key=value (keys: " + keyNames(*rule) + ")");
    const std::string_view text = trimField(field.substr(equals + 1));
    if (std::none_of(rule->keys.begin(), rule->keys.end(), [&](const KeyRule& k) { return k.key == key; }))
      failText(where, "unknown key " + formats::quotedValue(key) + " (keys: " + keyNames(*rule) + ")");
    if (std::find(seen.begin(), seen.end(), key) != seen.end())
      failText(where, "key " + formats::quotedValue(key) + " given twice");
    seen.push_back(key);
    if (key == "axis") {
      axis = parseAxis(kind, text);
      continue;
    }
    const auto number = parseNumber(text);
    if (!number || !std::isfinite(*number))
      failText(where, std::string(key) + " must be a finite number, got " + formats::quotedValue(text));
    values.emplace_back(key, *number);
  }
  for (const KeyRule& k : rule->keys)
    if (k.required && std::find(seen.begin(), seen.end(), k.key) == seen.end())
      failText(where, "missing key " + formats::quotedValue(k.key) + " (keys: " + keyNames(*rule) + ")");
  return buildProfile(*rule, *axis, values);
}

// ---- CSV of true rates -----------------------------------------------------------------

[[noreturn]] void failFile(const std::string& path, std::size_t line, const std::string& cause) {
  std::ostringstream s;
  s << path;
  if (line > 0) s << ':' << line;
  s << ": " << cause;
  throw RecordingError(s.str());
}

constexpr std::array<std::string_view, 4> kMotionColumns = {"t", "wx", "wy", "wz"};

// Column index in kMotionColumns for each field of the header line.
std::vector<std::size_t> readHeader(const std::string& path, std::size_t line_no, std::string_view header) {
  std::vector<std::size_t> columns;
  for (const std::string_view name : splitFields(header)) {
    const auto known = std::find(kMotionColumns.begin(), kMotionColumns.end(), name);
    if (known == kMotionColumns.end())
      failFile(path, line_no, "unknown column " + formats::quotedValue(name) + " (expected t and any of wx,wy,wz)");
    const auto index = static_cast<std::size_t>(known - kMotionColumns.begin());
    if (std::find(columns.begin(), columns.end(), index) != columns.end())
      failFile(path, line_no, "column " + formats::quotedValue(name) + " appears twice");
    columns.push_back(index);
  }
  if (std::find(columns.begin(), columns.end(), 0) == columns.end())
    failFile(path, line_no, "no column 't': the header needs t and any of wx,wy,wz");
  if (columns.size() < 2) failFile(path, line_no, "no rate column: the header needs t and any of wx,wy,wz");
  return columns;
}

MotionPoint readRow(const std::string& path, std::size_t line_no, std::string_view line,
                    const std::vector<std::size_t>& columns) {
  const auto fields = splitFields(line);
  if (fields.size() != columns.size())
    failFile(path, line_no,
             "expected " + std::to_string(columns.size()) + " fields, found " + std::to_string(fields.size()));
  MotionPoint point;
  for (std::size_t c = 0; c < fields.size(); ++c) {
    const std::string column(kMotionColumns[columns[c]]);
    const auto value = parseNumber(fields[c]);
    if (!value)
      failFile(path, line_no, "column '" + column + "': " + formats::quotedValue(fields[c]) + " is not a number");
    if (!std::isfinite(*value))
      failFile(path, line_no, "column '" + column + "': non-finite value " + formats::quotedValue(fields[c]));
    if (columns[c] == 0)
      point.t_s = *value;
    else
      point.rate_dps[columns[c] - 1] = *value;
  }
  return point;
}

}  // namespace

bool isMotionProfileText(std::string_view spec) {
  const auto colon = spec.find(':');
  return colon != std::string_view::npos && isLowercaseWord(trimField(spec.substr(0, colon)));
}

MotionProfile parseMotionProfileText(std::string_view text) {
  if (trimField(text).empty()) failText("", "empty spec (profiles: " + kindNames() + ", summed with '+')");
  const std::vector<std::string_view> terms = splitTerms(text);
  if (terms.size() == 1) return parseProfile(terms.front());
  std::vector<MotionProfile> parts;
  parts.reserve(terms.size());
  for (const std::string_view term : terms) parts.push_back(parseProfile(term));
  return MotionProfile::sum(std::move(parts));
}

MotionProfile readMotionCsv(const std::string& path) {
  std::istringstream in(formats::readInputFile(path, formats::kMotionInput));
  std::vector<std::size_t> columns;
  std::vector<MotionPoint> points;
  std::size_t header_line = 0;
  BoundedLineReader reader(in);  // a file without newlines costs at most the line limit
  for (std::size_t line_no = 1;; ++line_no) {
    const auto result = reader.next();
    if (result == BoundedLineReader::Result::End) break;
    if (result == BoundedLineReader::Result::TooLong) failFile(path, line_no, lineTooLongCause(reader.maxBytes()));
    const std::string_view line = trimField(reader.line());
    if (line.empty() || line.front() == '#') continue;
    if (columns.empty()) {
      columns = readHeader(path, line_no, line);
      header_line = line_no;
      continue;
    }
    points.push_back(readRow(path, line_no, line, columns));
    if (points.size() > 1 && !(points.back().t_s > points[points.size() - 2].t_s)) {
      std::ostringstream s;
      s.precision(17);
      s << "column 't' is not strictly increasing (t = " << points.back().t_s << " after "
        << points[points.size() - 2].t_s << ")";
      failFile(path, line_no, s.str());
    }
  }
  if (columns.empty()) failFile(path, 0, "empty file: no header t,wx,wy,wz and no rows");
  if (points.empty()) failFile(path, header_line, "no rows after the header");
  return MotionProfile::table(std::move(points));
}

MotionProfile motionFromSpec(const std::string& spec) {
  return isMotionProfileText(spec) ? parseMotionProfileText(spec) : readMotionCsv(spec);
}

namespace {
std::vector<double> finiteNumbers(std::string_view text, std::string_view what) {
  std::vector<double> out;
  for (std::string_view field : splitFields(text)) {
    const auto number = parseNumber(field);
    if (!number || !std::isfinite(*number))
      throw std::invalid_argument(std::string(what) + ": " + formats::quotedValue(field) +
                                  " is not a finite number (in " + formats::quotedValue(text) + ")");
    out.push_back(*number);
  }
  return out;
}
}  // namespace

processing::WarmUp parseWarmUpSpec(std::string_view text) {
  const std::vector<double> v = finiteNumbers(text, "warm-up");
  if (v.size() != 2 && v.size() != 3)
    throw std::invalid_argument("warm-up: expected DELTA_C,TAU_S[,START_S] (e.g. 15,300 or 8,300,3600), got " +
                                formats::quotedValue(text));
  if (!(v[1] > 0.0))
    throw std::invalid_argument("warm-up: the time constant TAU_S must be > 0 s, got " + formats::quotedValue(text));
  if (v.size() == 3 && !(v[2] >= 0.0))
    throw std::invalid_argument("warm-up: the start START_S must be >= 0 s, got " + formats::quotedValue(text));
  return {v[0], v[1], v.size() == 3 ? v[2] : 0.0};
}

std::array<double, processing::kSimulatedAxes> parseAxisValues(std::string_view text, std::string_view what) {
  const std::vector<double> v = finiteNumbers(text, what);
  if (v.size() == 1) return {v[0], v[0], v[0]};
  if (v.size() == 3) return {v[0], v[1], v[2]};
  throw std::invalid_argument(std::string(what) + ": expected one value for all axes or three (x,y,z), got " +
                              formats::quotedValue(text));
}

}  // namespace gyrod::recording
