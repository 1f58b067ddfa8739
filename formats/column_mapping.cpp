#include "formats/column_mapping.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "formats/csv_fields.hpp"
#include "formats/edit_distance.hpp"
#include "formats/imucal_recording.hpp"
#include "formats/quoted_value.hpp"
#include "formats/recording_csv.hpp"

namespace gyrod::recording {
namespace {

constexpr double kRadPerDeg = 0.017453292519943295769236907684886;
constexpr double kStandardGravity = 9.80665;  // m/s² per g (CGPM 1901), as Kalibr's output uses
// How many lines before the header a preamble may have: a file whose first lines name none
// of the columns is reported at once instead of being read to its end.
constexpr std::size_t kMaxPreambleLines = 100;

[[noreturn]] void failAt(const std::string& path, std::size_t line, const std::string& cause) {
  std::ostringstream s;
  s << path << ':' << line << ": " << cause;
  throw RecordingError(s.str());
}

// The fields of one line split at `delimiter`, blanks trimmed and one pair of double quotes
// (as spreadsheets write headers) removed.
std::vector<std::string_view> splitAt(std::string_view line, char delimiter) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const auto end = line.find(delimiter, start);
    auto field = trimField(line.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    if (field.size() >= 2 && field.front() == '"' && field.back() == '"') field = field.substr(1, field.size() - 2);
    fields.push_back(field);
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return fields;
}

bool isGyro(std::string_view target) {
  return std::find(kGyroColumns.begin(), kGyroColumns.end(), target) != kGyroColumns.end();
}
bool isAccel(std::string_view target) {
  return std::find(kAccelColumns.begin(), kAccelColumns.end(), target) != kAccelColumns.end();
}

// The nearest of `names` to `word` when it is a near miss ("; did you mean 'gx'?"), else "".
template <typename Names>
std::string didYouMean(std::string_view word, const Names& names) {
  std::string_view best;
  std::size_t best_distance = std::string_view::npos;
  for (std::string_view name : names) {
    const auto d = formats::editDistance(word, name);
    if (d < best_distance) best = name, best_distance = d;
  }
  if (best.empty() || best_distance > std::max<std::size_t>(2, word.size() / 3)) return "";
  return "; did you mean " + formats::quotedValue(best) + "?";  // a header's name may hold any byte
}

std::string joined(const std::vector<std::string_view>& names) {
  std::string all;
  for (const auto n : names) all += (all.empty() ? "" : ",") + std::string(n);
  return all;
}

// One output column: where its value is in a line, and the factor to gyrod's unit.
struct OutputColumn {
  std::string target;
  std::string source;
  std::size_t field = 0;
  double divisor = 1.0;  // gyrod's value = file's / divisor (a division, as the imucal reader's counts)
  bool counts = false;   // a raw 16-bit count: must be an integer in range
};

double divisorFor(const std::string& target, const ColumnMapping& m, bool& counts) {
  counts = false;
  if (isGyro(target)) {
    switch (m.gyro_unit) {
      case GyroUnit::DegPerS: return 1.0;
      case GyroUnit::RadPerS: return kRadPerDeg;
      case GyroUnit::Lsb: counts = true; return kGyroLsbPerDps[m.fs_sel];
    }
  }
  if (isAccel(target)) {
    switch (m.accel_unit) {
      case AccelUnit::G: return 1.0;
      case AccelUnit::MetrePerS2: return kStandardGravity;
      case AccelUnit::Lsb: counts = true; return kAccelLsbPerG[m.afs_sel];
    }
  }
  return 1.0;  // temp: °C
}

void appendNumber(std::string& out, double value) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, value);  // shortest text that reads back exactly
  out.append(buf, ec == std::errc() ? end : buf);
}

}  // namespace

std::vector<std::pair<std::string, std::string>> parseColumnMapping(const std::string& spec) {
  std::vector<std::pair<std::string, std::string>> columns;
  const std::vector<std::string_view> targets(std::begin(kImportTargets), std::end(kImportTargets));
  for (const auto entry : splitFields(spec)) {
    const auto eq = entry.find('=');
    if (eq == std::string_view::npos || trimField(entry.substr(0, eq)).empty() ||
        trimField(entry.substr(eq + 1)).empty())
      throw std::invalid_argument("--columns: " + formats::quotedValue(entry) +
                                  " is not TARGET=COLUMN (for example gx=gx_dps)");
    const std::string target(trimField(entry.substr(0, eq)));
    const std::string source(trimField(entry.substr(eq + 1)));
    if (std::find(targets.begin(), targets.end(), target) == targets.end())
      throw std::invalid_argument("--columns: " + formats::quotedValue(target) + " is not a gyrod column" +
                                  didYouMean(target, targets) + " (columns: " + joined(targets) + ")");
    for (const auto& [t, s] : columns)
      if (t == target) throw std::invalid_argument("--columns: " + formats::quotedValue(target) + " is mapped twice");
    columns.emplace_back(target, source);
  }
  if (std::none_of(columns.begin(), columns.end(), [](const auto& c) { return isGyro(c.first); }))
    throw std::invalid_argument("--columns: no gyro column mapped (gx, gy or gz)");
  return columns;
}

GyroUnit parseGyroUnit(const std::string& text) {
  if (text == "deg/s") return GyroUnit::DegPerS;
  if (text == "rad/s") return GyroUnit::RadPerS;
  if (text == "lsb") return GyroUnit::Lsb;
  throw std::invalid_argument("--gyro-unit " + formats::quotedValue(text) + ": known units are deg/s, rad/s, lsb");
}

AccelUnit parseAccelUnit(const std::string& text) {
  if (text == "g") return AccelUnit::G;
  if (text == "m/s2") return AccelUnit::MetrePerS2;
  if (text == "lsb") return AccelUnit::Lsb;
  throw std::invalid_argument("--accel-unit " + formats::quotedValue(text) + ": known units are g, m/s2, lsb");
}

char parseDelimiter(const std::string& text) {
  if (text == "," || text == ";") return text[0];
  if (text == "tab" || text == "\t") return '\t';
  throw std::invalid_argument("--delimiter " + formats::quotedValue(text) + ": known delimiters are ',', ';', tab");
}

namespace {

// The lines of a mapped file, numbered from 1; a line longer than the reader's limit stops
// the import with its line number.
class NumberedLines {
 public:
  NumberedLines(std::istream& in, const std::string& path) : reader_(in), path_(path) {}
  bool next() {
    const auto result = reader_.next();
    if (result == BoundedLineReader::Result::End) return false;
    ++number_;
    if (result == BoundedLineReader::Result::TooLong) failAt(path_, number_, lineTooLongCause(reader_.maxBytes()));
    line_ = reader_.line();
    return true;
  }
  std::string_view line() const { return line_; }
  std::size_t number() const { return number_; }

 private:
  BoundedLineReader reader_;
  const std::string& path_;
  std::string_view line_;
  std::size_t number_ = 0;
};

// The header: the first line within kMaxPreambleLines that names every mapped column and the
// time column (a logger's preamble comes before it). Its names, copied out of the reader's
// buffer; `lines` is left on it.
std::vector<std::string> findMappedHeader(NumberedLines& lines, const std::string& path, const ColumnMapping& mapping) {
  std::vector<std::string> wanted;
  for (const auto& c : mapping.columns) wanted.push_back(c.second);
  if (mapping.time_column) wanted.push_back(*mapping.time_column);
  const auto names_all = [&](const std::vector<std::string_view>& fields) {
    return std::all_of(wanted.begin(), wanted.end(), [&](const std::string& w) {
      return std::find(fields.begin(), fields.end(), w) != fields.end();
    });
  };
  std::vector<std::string> first_fields;  // of the first non-empty line, for the message
  std::size_t first_line = 0;
  for (;;) {
    if (!lines.next() || lines.number() > kMaxPreambleLines) {
      if (first_line == 0) throw RecordingError(path + ": empty file");
      const std::vector<std::string_view> have(first_fields.begin(), first_fields.end());
      for (const auto& w : wanted)
        if (std::find(have.begin(), have.end(), w) == have.end())
          failAt(path, first_line,
                 "no column " + formats::quotedValue(w) + " in the header" + didYouMean(w, have) + " (the header has " +
                     formats::quotedValue(joined(have)) + ")");
      failAt(path, first_line, "no header line names all of the mapped columns");
    }
    if (trimField(lines.line()).empty()) continue;
    const auto fields = splitAt(lines.line(), mapping.delimiter);
    if (first_line == 0) {
      first_line = lines.number();
      first_fields.assign(fields.begin(), fields.end());
    }
    if (names_all(fields)) return {fields.begin(), fields.end()};
  }
}

// The rate of a time column: one over the median spacing of its times (0 when it is not
// positive).
double rateFromTimes(const std::vector<double>& times) {
  if (times.size() < 2) return 0.0;
  std::vector<double> spacing;
  spacing.reserve(times.size() - 1);
  for (std::size_t i = 1; i < times.size(); ++i) spacing.push_back(times[i] - times[i - 1]);
  std::nth_element(spacing.begin(), spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2), spacing.end());
  const double median = spacing[spacing.size() / 2];
  return median > 0.0 ? 1.0 / median : 0.0;
}

}  // namespace

MappedConversion convertMappedColumns(std::istream& in, const std::string& path, const ColumnMapping& mapping) {
  if (mapping.time_column.has_value() == mapping.rate_hz.has_value())
    throw std::invalid_argument("import --columns needs exactly one of --time COLUMN and --rate HZ");
  if (mapping.rate_hz && !(std::isfinite(*mapping.rate_hz) && *mapping.rate_hz > 0.0))
    throw std::invalid_argument("--rate: the sample rate must be a positive number of Hz");
  NumberedLines lines(in, path);
  const std::vector<std::string> header_names = findMappedHeader(lines, path, mapping);
  MappedConversion result;
  result.header_line = lines.number();
  const auto field_of = [&](const std::string& name) -> std::size_t {
    const auto first = std::find(header_names.begin(), header_names.end(), name);
    // A name given twice in the header: no reader could tell which is the sensor's.
    if (std::find(std::next(first), header_names.end(), name) != header_names.end())
      failAt(path, result.header_line, "column " + formats::quotedValue(name) + " appears twice in the header");
    return static_cast<std::size_t>(first - header_names.begin());
  };

  std::vector<OutputColumn> outputs;
  for (const char* target : kImportTargets)
    for (const auto& [t, source] : mapping.columns)
      if (t == target) {
        OutputColumn c{t, source, field_of(source)};
        c.divisor = divisorFor(t, mapping, c.counts);
        outputs.push_back(c);
      }
  // A plain index (not an optional: gcc 12 takes an optional's value here for uninitialised).
  const std::size_t time_field = mapping.time_column ? field_of(*mapping.time_column) : 0;

  std::string& out = result.csv;
  out = "t";
  for (const auto& c : outputs) out += "," + c.target;
  out += '\n';
  std::vector<double> times;
  while (lines.next()) {
    if (trimField(lines.line()).empty()) continue;
    const auto fields = splitAt(lines.line(), mapping.delimiter);
    if (fields.size() != header_names.size()) {
      std::ostringstream s;
      s << "expected " << header_names.size() << " fields (as the header on line " << result.header_line << "), found "
        << fields.size();
      failAt(path, lines.number(), s.str());
    }
    const auto number = [&](std::size_t field, const std::string& column) {
      const auto value = parseNumber(fields[field]);
      if (!value)
        failAt(
            path, lines.number(),
            "column " + formats::quotedValue(column) + ": " + formats::quotedValue(fields[field]) + " is not a number");
      if (!std::isfinite(*value))
        failAt(path, lines.number(),
               "column " + formats::quotedValue(column) + ": " + formats::quotedValue(fields[field]) +
                   " is not a finite number");
      return *value;
    };
    double t = 0.0;
    if (mapping.time_column) {
      t = number(time_field, *mapping.time_column);
      times.push_back(t);
    } else {
      t = static_cast<double>(result.samples) / *mapping.rate_hz;
      if (!std::isfinite(t)) failAt(path, lines.number(), "--rate is too small: t is not a finite number");
    }
    appendNumber(out, t);
    for (const auto& c : outputs) {
      const double value = number(c.field, c.source);
      if (c.counts && (value != std::floor(value) || value < -32768.0 || value > 32767.0))
        failAt(path, lines.number(),
               "column " + formats::quotedValue(c.source) + ": " + formats::quotedValue(fields[c.field]) +
                   " is not a 16-bit count (the unit is lsb)");
      out += ',';
      appendNumber(out, value / c.divisor);
    }
    out += '\n';
    ++result.samples;
  }
  if (result.samples == 0) failAt(path, lines.number(), "no samples after the header");
  result.rate_hz = mapping.rate_hz ? *mapping.rate_hz : rateFromTimes(times);
  return result;
}

}  // namespace gyrod::recording
