// The sample lines of a recording, parsed a slice at a time (recording_slice.hpp).
#include "formats/recording_slice.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <system_error>

#include "formats/decimal_number.hpp"
#include "formats/quoted_value.hpp"

namespace gyrod::recording::slice_detail {
namespace {

// Splits `line` into at most fields.size() trimmed fields; returns the number of fields the
// line has (which may be more than were stored).
std::size_t splitInto(std::string_view line, std::span<std::string_view> fields) {
  std::size_t count = 0;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    if (count < fields.size())
      fields[count] =
          trimField(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    ++count;
    if (comma == std::string_view::npos) return count;
    start = comma + 1;
  }
}

}  // namespace

void SliceParser::parse(std::string_view text, SliceResult& out) const {
  std::array<std::string_view, kKnownColumns.size() + kStreamColumns.size()> fields;
  std::size_t start = 0;
  while (start < text.size()) {
    if (const std::size_t next = parsePlainLine(text, start, out); next != 0) {
      start = next;
      continue;
    }
    const auto nl = text.find('\n', start);
    const std::size_t end = nl == std::string_view::npos ? text.size() : nl;
    const std::string_view raw = text.substr(start, end - start);
    start = end + 1;
    ++out.lines;
    if (raw.size() > max_bytes) {
      out.error = lineTooLongCause(max_bytes);
      return;
    }
    const std::string_view line = trimField(raw);
    if (isSkippable(line)) {
      if (auto lost = parseLostSamplesLine(line)) {
        lost->line = out.lines;
        lost->before_sample = out.samples;
        out.lost.push_back(std::move(*lost));
      }
      continue;
    }
    if (bare_numbers && line.find(',') != std::string_view::npos) {
      out.error = "more than one column in a file of bare numbers (add a header t,gx,gy,gz,temp)";
      return;
    }
    if (!consume(line, fields, out)) return;
  }
}

// The common line, in one pass: exactly one plain number per column (no sign '+', no
// spaces, nothing empty), separated by single commas, ending in '\n' or the text's end,
// within the length limit. Each field is then exactly what from_chars read up to the
// comma, which is what the general path below would parse from it: the same values (both
// read with decimalFromChars, std::from_chars' values, faster on plain decimals). The
// sample is stored and the start of the next line returned; 0 (nothing stored) for any
// other line, left to the general path with its messages.
std::size_t SliceParser::parsePlainLine(std::string_view text, std::size_t start, SliceResult& out) const {
  // Not zeroed: a line sets every value it stores, and zeroing 19 doubles a line cost as much
  // as the rest of this function.
  std::array<double, kKnownColumns.size() + kStreamColumns.size()> values;
  const char* p = text.data() + start;
  const char* const end = text.data() + text.size();
  const std::size_t columns = column_names.size();
  if (columns > values.size()) return 0;
  for (std::size_t c = 0; c < columns; ++c) {
    if (p == end || *p == '+') return 0;
    const auto [after, ec] = decimalFromChars(p, end, values[c]);
    if (ec != std::errc() || after == p || !std::isfinite(values[c])) return 0;
    p = after;
    if (c + 1 < columns) {
      if (p == end || *p != ',') return 0;
      ++p;
    } else if (p != end && *p != '\n') {
      return 0;
    }
  }
  const auto line_end = static_cast<std::size_t>(p - text.data());
  if (line_end - start > max_bytes) return 0;
  ++out.lines;
  for (std::size_t c = 0; c < columns; ++c) out.store[c]->push_back(values[c]);
  recordSample(out);
  return line_end + 1;  // past the '\n' (or the end of the text)
}

// The line and run bookkeeping of a sample just stored.
void SliceParser::recordSample(SliceResult& out) const {
  if (line_numbers) out.sample_lines.push_back(out.lines);
  if (out.line_runs.empty() ||
      out.line_runs.back().first_line + (out.samples - out.line_runs.back().first_sample) != out.lines)
    out.line_runs.push_back({out.samples, out.lines});
  ++out.samples;
}

bool SliceParser::consume(std::string_view line, std::span<std::string_view> fields, SliceResult& out) const {
  const std::size_t count = splitInto(line, fields);
  if (count != column_names.size()) {
    std::ostringstream s;
    s << "expected " << column_names.size() << " field" << (column_names.size() == 1 ? "" : "s") << ", found " << count;
    out.error = s.str();
    return false;
  }
  for (std::size_t c = 0; c < count; ++c) {
    if (fields[c].empty() && may_be_empty[c]) {  // a value the sample did not have
      out.store[c]->push_back(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    const auto value = parseNumber(fields[c]);
    if (!value) {
      out.error = "column '" + column_names[c] + "': " + formats::quotedValue(fields[c]) + " is not a number";
      return false;
    }
    if (!std::isfinite(*value)) {
      out.error = "column '" + column_names[c] + "': non-finite value " + formats::quotedValue(fields[c]);
      return false;
    }
    out.store[c]->push_back(*value);
  }
  recordSample(out);
  return true;
}

}  // namespace gyrod::recording::slice_detail
