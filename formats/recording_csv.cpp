#include "formats/recording_csv.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <istream>
#include <iterator>
#include <limits>
#include <memory>
#include <span>
#include <sstream>
#include <string_view>

#include <sys/stat.h>

#include "formats/csv_fields.hpp"
#include "formats/quoted_value.hpp"

namespace gyrod::recording {
namespace {

constexpr std::array<std::string_view, 8> kKnownColumns = {"t", "gx", "gy", "gz", "temp", "wx", "wy", "wz"};
// gyrod's columns a sample may leave empty (recording_format.hpp): read as NaN then.
constexpr std::array<std::string_view, 8> kStreamColumns = {"time",    "gx_rate", "gy_rate", "gz_rate",
                                                            "gx_bias", "gy_bias", "gz_bias", "still"};

std::vector<double>* streamColumn(Recording& rec, std::size_t index) {
  if (index == 0) return &rec.time;
  if (index <= 3) return &rec.rate[index - 1];
  if (index <= 6) return &rec.bias[index - 4];
  return &rec.still;
}

[[noreturn]] void fail(const std::string& path, std::size_t line, const std::string& cause) {
  std::ostringstream s;
  s << path;
  if (line > 0) s << ':' << line;
  s << ": " << cause;
  throw RecordingError(s.str());
}

bool isSkippable(std::string_view line) { return line.empty() || line.front() == '#'; }

// Lines of at most `max_bytes` bytes (the '\n' not counted) from a std::FILE, read in large
// chunks: one copy of the text, no allocation per line, the same results as
// BoundedLineReader (a line past the limit stops the reading).
class ChunkedLineReader {
 public:
  enum class Result { Line, End, TooLong };
  static constexpr std::size_t kChunkBytes = std::size_t{1} << 20;

  ChunkedLineReader(std::FILE* file, std::size_t max_bytes)
      : file_(file), max_bytes_(max_bytes), buffer_(kChunkBytes + max_bytes + 2) {}

  Result next() {
    while (true) {
      const char* begin = buffer_.data() + pos_;
      const std::size_t available = end_ - pos_;
      if (const void* nl = std::memchr(begin, '\n', available)) {
        const auto length = static_cast<std::size_t>(static_cast<const char*>(nl) - begin);
        line_ = {begin, length};
        pos_ += length + 1;
        consumed_ += length + 1;
        return length > max_bytes_ ? Result::TooLong : Result::Line;
      }
      if (available > max_bytes_) return Result::TooLong;
      if (eof_) {
        if (available == 0) return Result::End;
        line_ = {begin, available};
        pos_ = end_;
        consumed_ += available;
        return Result::Line;
      }
      // Keep the partial line (at most max_bytes_) and fill the rest of the buffer.
      std::memmove(buffer_.data(), begin, available);
      pos_ = 0;
      end_ = available;
      const std::size_t got = std::fread(buffer_.data() + end_, 1, buffer_.size() - end_, file_);
      end_ += got;
      if (got == 0) eof_ = true;
    }
  }
  std::string_view line() const { return line_; }
  std::size_t maxBytes() const { return max_bytes_; }
  std::uint64_t bytesConsumed() const { return consumed_; }

 private:
  std::FILE* file_;
  std::size_t max_bytes_;
  std::vector<char> buffer_;
  std::size_t pos_ = 0, end_ = 0;
  std::uint64_t consumed_ = 0;
  bool eof_ = false;
  std::string_view line_;
};

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

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

// A generous guess of the number of lines from the file's size and one line's length, so
// that the columns are allocated once (capacity never touched costs no memory).
std::size_t expectedLines(std::FILE* file, std::size_t line_bytes) {
  struct stat st {};
  if (::fstat(::fileno(file), &st) != 0 || !S_ISREG(st.st_mode) || st.st_size <= 0) return 0;
  return static_cast<std::size_t>(st.st_size) / std::max<std::size_t>(line_bytes, 1) * 3 / 2 + 16;
}

enum class Role { T, Axis, Temp, Truth, Stream };
using ColumnRole = std::pair<Role, std::size_t>;  // what a column feeds, and which axis

// The columns of a header line; fills rec.axis_names and sizes rec.axes.
std::vector<ColumnRole> headerRoles(const std::string& path, std::size_t line_no, std::string_view first,
                                    Recording& rec) {
  std::vector<ColumnRole> roles;
  const auto names = splitFields(first);
  if (names.size() == 1 && first.find(',') == std::string_view::npos &&
      std::find(kKnownColumns.begin(), kKnownColumns.end(), names[0]) == kKnownColumns.end())
    fail(path, line_no,
         formats::quotedValue(names[0]) + " is neither a number nor a header of columns t,gx,gy,gz,temp");
  for (auto name : names) {
    const auto stream = std::find(kStreamColumns.begin(), kStreamColumns.end(), name);
    if (stream == kStreamColumns.end() &&
        std::find(kKnownColumns.begin(), kKnownColumns.end(), name) == kKnownColumns.end())
      fail(path, line_no,
           "unknown column " + formats::quotedValue(name) + " (expected any of t,gx,gy,gz,temp,wx,wy,wz)");
    for (std::size_t j = 0; j < roles.size(); ++j)
      if (names[j] == name) fail(path, line_no, "column '" + std::string(name) + "' appears twice");
    if (stream != kStreamColumns.end()) {
      roles.push_back({Role::Stream, static_cast<std::size_t>(stream - kStreamColumns.begin())});
    } else if (name == "t") {
      roles.push_back({Role::T, 0});
    } else if (name == "temp") {
      roles.push_back({Role::Temp, 0});
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
  return roles;
}

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

std::size_t Recording::lineOfSample(std::size_t sample) const {
  if (sample < line_numbers.size()) return line_numbers[sample];
  // The last run starting at or before `sample`: its lines follow one another.
  const auto after = std::upper_bound(line_runs.begin(), line_runs.end(), sample,
                                      [](std::size_t s, const LineRun& run) { return s < run.first_sample; });
  if (after == line_runs.begin()) return sample + 1;
  const LineRun& run = *(after - 1);
  return run.first_line + (sample - run.first_sample);
}

namespace {

// The one reading pass, over an open file (a real file, or a string through fmemopen).
Recording parseRecordingFile(std::FILE* file, const std::string& path, const ReadOptions& options) {
  Recording rec;
  rec.path = path;
  ChunkedLineReader reader(file, kMaxLineBytes);
  std::size_t line_no = 0;
  // The next line, trimmed; nullopt at the end. A line past the limit stops the reading.
  const auto nextLine = [&]() -> std::optional<std::string_view> {
    const auto result = reader.next();
    if (result == ChunkedLineReader::Result::End) return std::nullopt;
    ++line_no;
    if (result == ChunkedLineReader::Result::TooLong) fail(path, line_no, lineTooLongCause(reader.maxBytes()));
    if (options.progress && (line_no & (kProgressLines - 1)) == 0) options.progress(line_no, reader.bytesConsumed());
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
  // A directory opens but cannot be read (EISDIR): that is not an empty file.
  if (std::ferror(file)) fail(path, line_no, std::string("read error: ") + std::strerror(errno));
  if (isSkippable(first)) fail(path, 0, "empty file: no header and no samples");

  std::vector<ColumnRole> roles;  // per column: what it feeds, axis index
  bool bare_numbers = false;
  std::size_t header_line = line_no;
  if (parseNumber(first)) {
    bare_numbers = true;
    rec.axis_names = {std::string(kBareNumbersColumn)};
    rec.axes.resize(1);
    roles = {{Role::Axis, 0}};
  } else {
    roles = headerRoles(path, line_no, first, rec);
  }
  // Where each field's value goes, resolved once; the column's name only for a message.
  std::vector<std::vector<double>*> targets;
  targets.reserve(roles.size());
  for (const auto& [role, index] : roles) {
    targets.push_back(role == Role::T        ? &rec.t
                      : role == Role::Temp   ? &rec.temp
                      : role == Role::Axis   ? &rec.axes[index]
                      : role == Role::Stream ? streamColumn(rec, index)
                                             : &rec.true_rate[index]);
  }
  const auto columnName = [&](std::size_t c) {
    const auto [role, index] = roles[c];
    return bare_numbers           ? std::string("value")
           : role == Role::T      ? std::string("t")
           : role == Role::Temp   ? std::string("temp")
           : role == Role::Truth  ? std::string(kTruthColumns[index])
           : role == Role::Stream ? std::string(kStreamColumns[index])
                                  : rec.axis_names[index];
  };

  bool reserved = false;
  std::array<std::string_view, kKnownColumns.size() + kStreamColumns.size()> fields;
  auto consume = [&](std::string_view line) {
    if (!reserved) {
      reserved = true;
      const std::size_t lines = expectedLines(file, line.size() + 1);
      for (auto* target : targets) target->reserve(lines);
      if (options.line_numbers) rec.line_numbers.reserve(lines);
    }
    const std::size_t count = splitInto(line, fields);
    if (count != roles.size()) {
      std::ostringstream s;
      s << "expected " << roles.size() << " field" << (roles.size() == 1 ? "" : "s") << ", found " << count;
      fail(path, line_no, s.str());
    }
    const std::size_t sample = rec.size();
    if (options.line_numbers) rec.line_numbers.push_back(line_no);
    if (rec.line_runs.empty() ||
        rec.line_runs.back().first_line + (sample - rec.line_runs.back().first_sample) != line_no)
      rec.line_runs.push_back({sample, line_no});
    for (std::size_t c = 0; c < count; ++c) {
      if (fields[c].empty() && roles[c].first == Role::Stream) {  // a value the sample did not have
        targets[c]->push_back(std::numeric_limits<double>::quiet_NaN());
        continue;
      }
      const auto value = parseNumber(fields[c]);
      if (!value)
        fail(path, line_no, "column '" + columnName(c) + "': " + formats::quotedValue(fields[c]) + " is not a number");
      if (!std::isfinite(*value))
        fail(path, line_no, "column '" + columnName(c) + "': non-finite value " + formats::quotedValue(fields[c]));
      targets[c]->push_back(*value);
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
  if (std::ferror(file)) fail(path, line_no, std::string("read error: ") + std::strerror(errno));
  if (rec.size() == 0) fail(path, header_line, "no samples after the header");
  return rec;
}

}  // namespace

Recording readRecordingCsv(const std::string& path, const ReadOptions& options) {
  const std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) fail(path, 0, std::string("cannot open: ") + std::strerror(errno));
  return parseRecordingFile(file.get(), path, options);
}

Recording parseRecordingCsv(std::istream& in, const std::string& path) {
  // The stream's bytes through fmemopen: the same reading pass as a file, line limits included.
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (text.empty()) fail(path, 0, "empty file: no header and no samples");
  const std::unique_ptr<std::FILE, FileCloser> file(::fmemopen(text.data(), text.size(), "rb"));
  if (!file) fail(path, 0, std::string("cannot read: ") + std::strerror(errno));
  return parseRecordingFile(file.get(), path, ReadOptions{});
}

double sampleRateFromTimes(const Recording& r) {
  if (r.t.size() < 2) throw RecordingError(r.path + ": need at least two samples in column 't' to infer the rate");
  std::vector<double> dt(r.t.size() - 1);
  for (std::size_t i = 1; i < r.t.size(); ++i) {
    dt[i - 1] = r.t[i] - r.t[i - 1];
    if (!(dt[i - 1] > 0.0)) {
      std::ostringstream s;
      s.precision(17);
      s << r.path << ':' << r.lineOfSample(i) << ": column 't' is not strictly increasing (t = " << r.t[i] << " after "
        << r.t[i - 1] << ")";
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
