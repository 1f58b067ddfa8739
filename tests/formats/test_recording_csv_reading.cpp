// Reading long recordings: the chunked reader must give the same samples and the same line
// numbers across its 1 MiB chunk boundaries, keep the line limit there, answer a sample's
// line without the per-sample table, and report progress.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fixed_threads.hpp"
#include "formats/csv_fields.hpp"
#include "formats/recording_csv.hpp"
#include "formats/recording_format.hpp"
#include "processing/base/parallel_share.hpp"

using namespace gyrod::recording;
namespace fs = std::filesystem;

namespace {

class ReadingTempFile {
 public:
  explicit ReadingTempFile(const std::string& text) {
    path_ = (fs::temp_directory_path() / ("gyrod-reading-test-" + std::to_string(::getpid()) + ".csv")).string();
    std::ofstream(path_, std::ios::binary) << text;
  }
  ~ReadingTempFile() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// ~3 MiB: t,gx,gy lines of varying length, a comment or an empty line now and then.
struct Written {
  std::string text;
  std::vector<double> gy;
  std::vector<std::size_t> lines;
};
Written longFile() {
  Written w;
  std::ostringstream s;
  s.precision(17);
  s << "# comment before the header\nt,gx,gy\n";
  std::size_t line = 2;
  for (std::size_t i = 0; i < 60'000; ++i) {
    if (i % 997 == 0) {
      s << (i % 2 ? "\n" : "# a comment\n");
      ++line;
    }
    const double gy = (static_cast<double>(i % 1013) - 500.0) / 7.0;
    s << 0.02 * static_cast<double>(i) << ", " << 1.0 / static_cast<double>(i + 1) << "," << gy << "\r\n";
    w.gy.push_back(gy);
    w.lines.push_back(++line);
  }
  w.text = s.str();
  return w;
}

TEST(RecordingReading, SamplesAndLinesSurviveChunkBoundaries) {
  const Written w = longFile();
  ASSERT_GT(w.text.size(), 3u << 20);
  ReadingTempFile f(w.text);
  const Recording rec = readRecordingCsv(f.path());
  ASSERT_EQ(rec.size(), w.gy.size());
  EXPECT_EQ(*rec.axis("gy"), w.gy);
  EXPECT_EQ(rec.line_numbers, w.lines);
  ReadOptions lean;
  lean.line_numbers = false;
  const Recording without = readRecordingCsv(f.path(), lean);
  EXPECT_TRUE(without.line_numbers.empty());
  EXPECT_EQ(*without.axis("gy"), w.gy);
  EXPECT_LT(without.line_runs.size(), 200u);
  for (std::size_t i = 0; i < w.lines.size(); ++i) ASSERT_EQ(without.lineOfSample(i), w.lines[i]) << "sample " << i;
}

TEST(RecordingReading, TheLineLimitHoldsAcrossAChunkBoundary) {
  Written w = longFile();
  const std::size_t lines_before = w.lines.back();
  w.text += "1," + std::string(kMaxLineBytes, '2') + "\n0,1,2\n";
  ReadingTempFile f(w.text);
  try {
    (void)readRecordingCsv(f.path());
    FAIL() << "accepted a line longer than the limit";
  } catch (const RecordingError& e) {
    EXPECT_EQ(std::string(e.what()), f.path() + ":" + std::to_string(lines_before + 1) +
                                         ": line longer than 65536 bytes (the limit for one line)");
  }
}

// The lines of each chunk are cut in two slices parsed on both cores: a bad value anywhere,
// the first of two in one chunk included, is named by its own line.
TEST(RecordingReading, TheFirstBadLineIsNamedWhereverItFalls) {
  const Written w = longFile();
  const auto lineStart = [&](std::size_t sample) {
    std::size_t pos = 0;
    for (std::size_t line = 1; line < w.lines[sample]; ++line) pos = w.text.find('\n', pos) + 1;
    return pos;
  };
  const auto withBadSample = [&](std::string text, std::size_t sample) {
    const std::size_t at = lineStart(sample);
    text.replace(at, w.text.find('\n', at) - at, "0,1,x");
    return text;
  };
  for (std::size_t sample : {std::size_t{0}, std::size_t{9'000}, std::size_t{11'000}, std::size_t{21'000},
                             std::size_t{40'000}, std::size_t{59'999}}) {
    ReadingTempFile f(withBadSample(w.text, sample));
    try {
      (void)readRecordingCsv(f.path());
      FAIL() << "accepted a bad value at sample " << sample;
    } catch (const RecordingError& e) {
      EXPECT_EQ(std::string(e.what()),
                f.path() + ":" + std::to_string(w.lines[sample]) + ": column 'gy': 'x' is not a number");
    }
  }
  // Two bad lines a few kB apart (one chunk, most likely in both of its slices): the first.
  ReadingTempFile two(withBadSample(withBadSample(w.text, 30'000), 25'000));
  try {
    (void)readRecordingCsv(two.path());
    FAIL() << "accepted two bad values";
  } catch (const RecordingError& e) {
    EXPECT_EQ(std::string(e.what()),
              two.path() + ":" + std::to_string(w.lines[25'000]) + ": column 'gy': 'x' is not a number");
  }
}

// Runs a block with the reader's thread count fixed (processing/base/parallel_share.hpp).
// A bad line as the last line of a front slice, the first of a back slice, the last of a
// batch and the first of the next, on one core and on two: always the one named. The edges
// are found as the reader cuts them today (a buffer of 1 MiB + the line limit + 2 bytes, each
// batch up to its last line end, split at the first line end past its middle); were that to
// change, the lines tried would still be bad lines of a long file.
TEST(RecordingReading, ABadLineAtASliceOrBatchEdgeIsNamed) {
  const Written w = longFile();
  const std::size_t buffer = (std::size_t{1} << 20) + kMaxLineBytes + 2;
  std::vector<std::size_t> starts;  // byte offsets of the lines to spoil
  std::size_t batch_start = w.text.find('\n', w.text.find("t,gx,gy")) + 1;
  for (int batch = 0; batch < 2; ++batch) {
    const std::size_t batch_end = w.text.rfind('\n', batch_start + buffer - 1) + 1;
    const std::size_t middle = w.text.find('\n', batch_start + (batch_end - batch_start) / 2) + 1;
    for (const std::size_t edge : {middle, batch_end}) {
      starts.push_back(w.text.rfind('\n', edge - 2) + 1);  // the line before the edge
      starts.push_back(edge);                              // the line after it
    }
    batch_start = batch_end;
  }
  for (const std::size_t threads : {std::size_t{1}, std::size_t{2}}) {
    const FixedThreads fixed(threads);
    for (const std::size_t at : starts) {
      std::string text = w.text;
      text.replace(at, text.find('\n', at) - at, "0,1,x");
      const auto line =
          static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n')) + 1;
      ReadingTempFile f(text);
      try {
        (void)readRecordingCsv(f.path());
        FAIL() << "accepted a bad value at line " << line;
      } catch (const RecordingError& e) {
        EXPECT_EQ(std::string(e.what()), f.path() + ":" + std::to_string(line) + ": column 'gy': 'x' is not a number")
            << threads << " thread(s)";
      }
    }
  }
}

// One core or two: the same values, lines and records.
TEST(RecordingReading, OneCoreAndTwoCoresReadTheSame) {
  Written w = longFile();
  RecordingLine gap;
  w.text += formatGapLine(gap, 60'000, 1200.0, 3, "fifo_overflow");
  w.text += "1200.06,0.5,0.25\n";
  ReadingTempFile f(w.text);
  std::vector<Recording> read;
  for (const std::size_t threads : {std::size_t{1}, std::size_t{2}}) {
    const FixedThreads fixed(threads);
    read.push_back(readRecordingCsv(f.path()));
  }
  ASSERT_EQ(read[0].size(), w.gy.size() + 1);
  EXPECT_EQ(read[0].t, read[1].t);
  EXPECT_EQ(read[0].axes, read[1].axes);
  EXPECT_EQ(read[0].line_numbers, read[1].line_numbers);
  EXPECT_EQ(read[0].lost, read[1].lost);
  ASSERT_EQ(read[1].lost.size(), 1u);
  EXPECT_EQ(read[1].lost[0].before_sample, w.gy.size());
}

// GAP lines anywhere in a long file: each record keeps its line and the sample after it.
TEST(RecordingReading, GapRecordsKeepTheirPlaceInLongFiles) {
  std::string text = "t,gx\n";
  std::vector<LostSamples> expected;
  std::size_t line = 1, samples = 0;
  for (std::size_t i = 0; i < 200'000; ++i) {
    if (i % 7'919 == 5) {
      RecordingLine gap;
      text += formatGapLine(gap, i, 0.02 * static_cast<double>(i), 3, "fifo_overflow");
      const auto parsed = parseLostSamplesLine(gap.view().substr(0, gap.size - 1));  // without its '\n'
      ASSERT_TRUE(parsed.has_value());
      LostSamples lost = *parsed;
      lost.line = ++line;
      lost.before_sample = samples;
      expected.push_back(lost);
    }
    text += std::to_string(i) + ",0.25\n";
    ++line;
    ++samples;
  }
  ReadingTempFile f(text);
  const Recording rec = readRecordingCsv(f.path());
  EXPECT_EQ(rec.size(), samples);
  EXPECT_EQ(rec.lost, expected);
}

TEST(RecordingReading, ProgressIsReportedEveryMillionLines) {
  std::string text;
  const std::size_t count = kProgressLines * 2 + 10;
  text.reserve(count * 2);
  for (std::size_t i = 0; i < count; ++i) text += "1\n";
  ReadingTempFile f(text);
  std::vector<std::size_t> reported_lines;
  std::vector<std::uint64_t> reported_bytes;
  ReadOptions options;
  options.progress = [&](std::size_t lines, std::uint64_t bytes) {
    reported_lines.push_back(lines);
    reported_bytes.push_back(bytes);
  };
  for (const std::size_t threads : {std::size_t{1}, std::size_t{2}}) {
    const FixedThreads fixed(threads);
    reported_lines.clear();
    reported_bytes.clear();
    const Recording rec = readRecordingCsv(f.path(), options);
    EXPECT_EQ(rec.size(), count);
    EXPECT_EQ(reported_lines, (std::vector<std::size_t>{kProgressLines, 2 * kProgressLines}));
    EXPECT_EQ(reported_bytes, (std::vector<std::uint64_t>{2 * kProgressLines, 4 * kProgressLines}));
  }
}

// Plain lines ("number,number\n") are read in one pass by from_chars; any other form (spaces,
// a '+', CRLF, an empty stream field) by the general path. Both must give the same bits:
// here every value is written plainly in one file and decorated, every other line, in the
// other, across several 1 MiB chunks, and the two readings must agree bit for bit.
TEST(RecordingReading, PlainAndDecoratedLinesGiveTheSameValues) {
  std::ostringstream plain, mixed;
  plain.precision(17);
  mixed.precision(17);
  plain << "t,gx,gy\n";
  mixed << "t,gx,gy\n";
  std::uint64_t state = 20261125;
  const auto next = [&] {  // a deterministic spread of magnitudes and signs
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const double unit = static_cast<double>(state >> 11) / 9007199254740992.0;
    return (unit - 0.5) * std::pow(10.0, static_cast<double>(state % 13) - 6.0);
  };
  const std::size_t count = 90'000;
  for (std::size_t i = 0; i < count; ++i) {
    const double t = 0.02 * static_cast<double>(i), gx = next(), gy = next();
    plain << t << ',' << gx << ',' << gy << '\n';
    if (i % 2 == 0)
      mixed << t << ',' << gx << ',' << gy << '\n';
    else if (i % 6 == 1)
      mixed << ' ' << t << " ,\t" << gx << ", " << gy << " \r\n";
    else if (i % 6 == 3)
      mixed << t << ',' << (gx >= 0 ? "+" : "") << gx << ',' << gy << "\r\n";
    else
      mixed << t << ',' << gx << ',' << (gy >= 0 ? "+" : "") << gy << '\n';
  }
  ASSERT_GT(plain.str().size(), 3u << 20);
  std::vector<Recording> read;
  for (const std::string& text : {plain.str(), mixed.str()}) {
    ReadingTempFile f(text);
    read.push_back(readRecordingCsv(f.path()));
  }
  ASSERT_EQ(read[0].size(), count);
  ASSERT_EQ(read[1].size(), count);
  for (std::size_t i = 0; i < count; ++i) {
    ASSERT_EQ(std::bit_cast<std::uint64_t>(read[0].t[i]), std::bit_cast<std::uint64_t>(read[1].t[i])) << i;
    for (std::size_t a = 0; a < 2; ++a)
      ASSERT_EQ(std::bit_cast<std::uint64_t>(read[0].axes[a][i]), std::bit_cast<std::uint64_t>(read[1].axes[a][i]))
          << "sample " << i << ", axis " << a;
    ASSERT_EQ(read[0].lineOfSample(i), i + 2);
    ASSERT_EQ(read[1].lineOfSample(i), i + 2);
  }
  // And the values are the numbers written (17 digits: the doubles themselves).
  state = 20261125;
  for (std::size_t i = 0; i < count; ++i) {
    ASSERT_EQ(read[0].axes[0][i], next()) << i;
    ASSERT_EQ(read[0].axes[1][i], next()) << i;
  }
}

// A bad value in a plain-looking line is still named with its file:line by the general path.
TEST(RecordingReading, ABadValueAmongPlainLinesIsNamed) {
  std::string text = "t,gx\n";
  for (int i = 0; i < 1000; ++i) text += std::to_string(i) + ".5,0.25\n";
  text += "1000.5,0.2x5\n";
  ReadingTempFile f(text);
  try {
    readRecordingCsv(f.path());
    FAIL() << "no error";
  } catch (const RecordingError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(f.path() + ":1002: column 'gx': "), std::string::npos) << message;
    EXPECT_NE(message.find("0.2x5"), std::string::npos) << message;
    EXPECT_NE(message.find("is not a number"), std::string::npos) << message;
  }
}

}  // namespace
