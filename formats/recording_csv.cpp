#include "formats/recording_csv.hpp"

#include "formats/input_file.hpp"

#include <algorithm>
#include <array>
#include <barrier>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <functional>
#include <istream>
#include <iterator>
#include <limits>
#include <memory>
#include <span>
#include <sstream>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>

#include <sys/stat.h>

#include "formats/chunked_line_reader.hpp"
#include "formats/csv_fields.hpp"
#include "formats/decimal_number.hpp"
#include "formats/quoted_value.hpp"
#include "formats/recording_slice.hpp"
#include "processing/base/parallel_share.hpp"

namespace gyrod::recording {
namespace {

using slice_detail::isSkippable;
using slice_detail::kKnownColumns;
using slice_detail::kStreamColumns;
using slice_detail::SliceParser;
using slice_detail::SliceResult;

std::vector<double>* streamColumn(Recording& rec, std::size_t index) {
  if (index == 0) return &rec.time;
  if (index <= 3) return &rec.rate[index - 1];
  if (index <= 6) return &rec.bias[index - 4];
  if (index == 7) return &rec.still;
  return &rec.attitude[index - 8];
}

[[noreturn]] void fail(const std::string& path, std::size_t line, const std::string& cause) {
  std::ostringstream s;
  s << path;
  if (line > 0) s << ':' << line;
  s << ": " << cause;
  throw RecordingError(s.str());
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

// A generous guess of the number of lines from the file's size and one line's length, so
// that the columns are allocated once (capacity never touched costs no memory).
std::size_t expectedLines(std::FILE* file, std::size_t line_bytes) {
  struct stat st {};
  if (::fstat(::fileno(file), &st) != 0 || !S_ISREG(st.st_mode) || st.st_size <= 0) return 0;
  return static_cast<std::size_t>(st.st_size) / std::max<std::size_t>(line_bytes, 1) * 3 / 2 + 16;
}

enum class Role { T, Axis, Temp, Truth, Accel, Stream };
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
           "unknown column " + formats::quotedValue(name) + " (expected any of t,gx,gy,gz,temp,wx,wy,wz,ax,ay,az)");
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
    } else if (const auto accel = std::find(kAccelColumns.begin(), kAccelColumns.end(), name);
               accel != kAccelColumns.end()) {
      roles.push_back({Role::Accel, static_cast<std::size_t>(accel - kAccelColumns.begin())});
    } else {
      roles.push_back({Role::Axis, rec.axis_names.size()});
      rec.axis_names.emplace_back(name);
    }
  }
  if (rec.axis_names.empty()) fail(path, line_no, "no gyro column: the header needs at least one of gx,gy,gz");
  rec.axes.resize(rec.axis_names.size());
  return roles;
}

// Below this many bytes a batch of lines is parsed on the calling thread alone.
constexpr std::size_t kParallelSliceBytes = std::size_t{1} << 17;

// `text` cut at a line end near `front_share` of its bytes (the whole of it in the first part
// when short).
std::pair<std::string_view, std::string_view> splitAtLineNear(std::string_view text, double front_share) {
  if (text.size() < kParallelSliceBytes) return {text, {}};
  const auto nl = text.find('\n', static_cast<std::size_t>(static_cast<double>(text.size()) * front_share));
  if (nl == std::string_view::npos || nl + 1 >= text.size()) return {text, {}};
  return {text.substr(0, nl + 1), text.substr(nl + 1)};
}

// A slice's records and line runs appended to `rec`, its lines numbered after line_no and its
// samples after first_sample; its values too, to `targets`, unless null (already there).
void appendSlice(const SliceResult& slice, std::size_t line_no, std::size_t first_sample, Recording& rec,
                 const std::vector<std::vector<double>*>* targets) {
  for (LostSamples lost : slice.lost) {
    lost.line += line_no;
    lost.before_sample += first_sample;
    rec.lost.push_back(std::move(lost));
  }
  for (const auto& run : slice.line_runs) {
    const std::size_t sample = first_sample + run.first_sample, line = line_no + run.first_line;
    if (rec.line_runs.empty() || rec.line_runs.back().first_line + (sample - rec.line_runs.back().first_sample) != line)
      rec.line_runs.push_back({sample, line});
  }
  for (std::size_t line : slice.sample_lines) rec.line_numbers.push_back(line_no + line);
  if (targets)
    for (std::size_t c = 0; c < slice.columns.size(); ++c)
      (*targets)[c]->insert((*targets)[c]->end(), slice.columns[c].begin(), slice.columns[c].end());
}

// ReadOptions::progress at every multiple of kProgressLines among the `lines` lines of
// `text` (which starts at byte `text_start`, after line `line_no`), with the bytes read up to
// the end of that line.
void reportProgress(const ReadOptions& options, std::string_view text, std::uint64_t text_start, std::size_t line_no,
                    std::size_t lines) {
  if (!options.progress) return;
  std::size_t mark = (line_no / kProgressLines + 1) * kProgressLines;
  std::size_t scanned = 0;  // lines of text passed
  std::size_t pos = 0;      // bytes of text passed
  for (; mark <= line_no + lines; mark += kProgressLines) {
    for (; scanned < mark - line_no; ++scanned) {
      const auto nl = text.find('\n', pos);
      pos = nl == std::string_view::npos ? text.size() : nl + 1;
    }
    options.progress(mark, text_start + pos);
  }
}

// The second core's share of the reading: a thread that lives as long as the reading does
// (one thread, not one a batch: starting one costs ~70 µs here) and, per batch, parses the
// front slice into the recording's columns and then appends the back slice's values after
// it, while the calling thread parses the back slice and then reads the next batch. They
// meet three times a batch: to start, once both slices are parsed, and when done. Neither
// throws between the start and the end of a batch: what fails is kept and rethrown after.
class FrontSliceWorker {
 public:
  using Work = std::function<void()>;
  FrontSliceWorker() : thread_([this] { run(); }) {}
  FrontSliceWorker(const FrontSliceWorker&) = delete;
  FrontSliceWorker& operator=(const FrontSliceWorker&) = delete;
  ~FrontSliceWorker() {
    stop_ = true;
    start_.arrive_and_wait();
    thread_.join();
  }
  // One batch: `parse` on the worker beside `parse_here` on this thread, then `after` on the
  // worker beside `after_here` (neither once a parse failed); returns once all are done,
  // rethrowing the worker's failure first.
  void batch(const Work& parse, const Work& after, const Work& parse_here, const Work& after_here) {
    parse_ = &parse;
    after_ = &after;
    start_.arrive_and_wait();
    std::exception_ptr here_error;
    try {
      parse_here();
    } catch (...) {
      here_error = std::current_exception();
    }
    parsed_.arrive_and_wait();
    if (!here_error && !worker_error_) {
      try {
        after_here();
      } catch (...) {
        here_error = std::current_exception();
      }
    }
    done_.arrive_and_wait();
    if (worker_error_) std::rethrow_exception(std::exchange(worker_error_, nullptr));
    if (here_error) std::rethrow_exception(here_error);
  }

 private:
  void run() {
    while (true) {
      start_.arrive_and_wait();
      if (stop_) return;
      try {
        (*parse_)();
      } catch (...) {
        worker_error_ = std::current_exception();
      }
      parsed_.arrive_and_wait();
      if (!worker_error_) {
        try {
          (*after_)();
        } catch (...) {
          worker_error_ = std::current_exception();
        }
      }
      done_.arrive_and_wait();
    }
  }

  std::barrier<> start_{2}, parsed_{2}, done_{2};
  bool stop_ = false;
  const Work* parse_ = nullptr;
  const Work* after_ = nullptr;
  std::exception_ptr worker_error_;
  std::thread thread_;  // last: it starts once the rest is built
};

// The sample lines after the header, in batches of whole lines (about a chunk each), each cut
// in two slices parsed on both cores and appended in file order: the first bad line is still
// the one named. The front slice stores its values straight into the recording's columns
// (allocated once, from the file's size and the first batch's line length), the back slice
// into its own. Once both are parsed, the front's thread copies the back slice's values after
// the front's while the calling thread reports progress and reads the next batch. Copying
// into the columns' fresh pages costs the front's thread more than reading costs the other,
// so the cut moves, batch by batch, to where both threads take as long (measured): the
// values and every message are the same wherever the cut falls.
void readSampleLines(ChunkedLineReader& reader, const SliceParser& parser,
                     const std::vector<std::vector<double>*>& targets, const ReadOptions& options, std::FILE* file,
                     std::size_t& line_no, Recording& rec) {
  const std::string& path = rec.path;
  const std::size_t columns = targets.size();
  // Checks a parsed slice and appends its records and line runs (and its values, unless
  // already copied), its samples after first_sample.
  const auto append = [&](const SliceResult& slice, std::size_t first_sample, bool values_copied) {
    if (!slice.error.empty()) fail(path, line_no + slice.lines, slice.error);
    appendSlice(slice, line_no, first_sample, rec, values_copied ? nullptr : &targets);
    line_no += slice.lines;
  };
  SliceResult front_slice, back_slice;  // reused: the back slice's columns are allocated once
  bool reserved = false;
  std::optional<FrontSliceWorker> worker;
  if (processing::shareThreadCount() > 1) worker.emplace();
  double front_share = 0.5;  // of a batch's bytes, moved to balance the two threads' time
  using Clock = std::chrono::steady_clock;
  while (true) {
    const auto result = reader.nextLines();
    if (result == ChunkedLineReader::Result::End) break;
    if (result == ChunkedLineReader::Result::TooLong) fail(path, line_no + 1, lineTooLongCause(reader.maxBytes()));
    const std::string_view text = reader.line();
    const std::uint64_t text_start = reader.bytesConsumed() - text.size();
    if (!reserved) {
      reserved = true;
      const auto lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
      const std::size_t expected = expectedLines(file, text.size() / lines);
      for (auto* target : targets) target->reserve(expected);
      if (options.line_numbers) rec.line_numbers.reserve(expected);
    }
    const auto [front, back] = splitAtLineNear(text, front_share);
    const std::size_t first_sample = rec.size();
    front_slice.clear(columns, &targets);
    back_slice.clear(columns);
    if (back.empty() || !worker) {
      for (const auto& [slice_text, slice] : {std::pair{front, &front_slice}, std::pair{back, &back_slice}}) {
        if (slice_text.empty()) continue;
        const std::size_t slice_line = line_no;
        parser.parse(slice_text, *slice);
        append(*slice, rec.size() - (slice == &front_slice ? slice->samples : 0), false);
        reportProgress(options, slice_text, text_start + static_cast<std::size_t>(slice_text.data() - text.data()),
                       slice_line, slice->lines);
      }
      continue;
    }
    const auto fine = [](const SliceResult& slice) { return slice.error.empty(); };
    double front_seconds = 0.0, back_seconds = 0.0;  // each thread's time at work, not waiting
    const auto timed = [](double& seconds, const auto& work) {
      const auto begin = Clock::now();
      work();
      seconds += std::chrono::duration<double>(Clock::now() - begin).count();
    };
    const FrontSliceWorker::Work parse_front = [&, front = front] {
      timed(front_seconds, [&] { parser.parse(front, front_slice); });
    };
    const FrontSliceWorker::Work copy_back = [&] {
      if (!fine(front_slice) || !fine(back_slice)) return;
      timed(front_seconds, [&] {
        for (std::size_t c = 0; c < columns; ++c)
          targets[c]->insert(targets[c]->end(), back_slice.columns[c].begin(), back_slice.columns[c].end());
      });
    };
    const FrontSliceWorker::Work parse_back = [&, back = back] {
      timed(back_seconds, [&] { parser.parse(back, back_slice); });
    };
    const FrontSliceWorker::Work report_and_read_on = [&, front = front, back = back] {
      if (!fine(front_slice)) return;
      timed(back_seconds, [&] {
        reportProgress(options, front, text_start, line_no, front_slice.lines);
        if (!fine(back_slice)) return;
        reportProgress(options, back, text_start + front.size(), line_no + front_slice.lines, back_slice.lines);
        reader.prefetch();  // the text of both slices is no longer needed
      });
    };
    worker->batch(parse_front, copy_back, parse_back, report_and_read_on);
    append(front_slice, first_sample, true);
    append(back_slice, first_sample + front_slice.samples, true);
    // A quarter of the measured relative imbalance moved over each batch: a few batches settle
    // it, and one slow batch (the machine busy elsewhere) does not throw it far.
    if (front_seconds > 0.0 && back_seconds > 0.0)
      front_share =
          std::clamp(front_share - 0.25 * (front_seconds - back_seconds) / (front_seconds + back_seconds), 0.2, 0.8);
  }
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
                      : role == Role::Accel  ? &rec.accel_g[index]
                      : role == Role::Stream ? streamColumn(rec, index)
                                             : &rec.true_rate[index]);
  }
  const auto columnName = [&](std::size_t c) {
    const auto [role, index] = roles[c];
    return bare_numbers           ? std::string("value")
           : role == Role::T      ? std::string("t")
           : role == Role::Temp   ? std::string("temp")
           : role == Role::Truth  ? std::string(kTruthColumns[index])
           : role == Role::Accel  ? std::string(kAccelColumns[index])
           : role == Role::Stream ? std::string(kStreamColumns[index])
                                  : rec.axis_names[index];
  };

  SliceParser parser;
  parser.bare_numbers = bare_numbers;
  parser.line_numbers = options.line_numbers;
  parser.max_bytes = reader.maxBytes();
  for (std::size_t c = 0; c < roles.size(); ++c) {
    parser.column_names.push_back(columnName(c));
    parser.may_be_empty.push_back(roles[c].first == Role::Stream);
  }
  if (bare_numbers) {
    SliceResult slice;
    slice.clear(roles.size());
    parser.parse(first, slice);
    --line_no;  // `first` is line line_no: the slice's line 1
    if (!slice.error.empty()) fail(path, line_no + slice.lines, slice.error);
    appendSlice(slice, line_no, 0, rec, &targets);
    reportProgress(options, first, reader.bytesConsumed(), line_no, slice.lines);
    line_no += slice.lines;
  }
  readSampleLines(reader, parser, targets, options, file, line_no, rec);
  if (std::ferror(file)) fail(path, line_no, std::string("read error: ") + std::strerror(errno));
  if (rec.size() == 0) fail(path, header_line, "no samples after the header");
  return rec;
}

}  // namespace

Recording readRecordingCsv(const std::string& path, const ReadOptions& options) {
  const formats::InputFile file =
      formats::openInputFile(path, options.input_kind ? *options.input_kind : formats::kRecordingInput);
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

}  // namespace gyrod::recording
