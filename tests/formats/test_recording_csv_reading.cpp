// Reading long recordings: the chunked reader must give the same samples and the same line
// numbers across its 1 MiB chunk boundaries, keep the line limit there, answer a sample's
// line without the per-sample table, and report progress.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "formats/csv_fields.hpp"
#include "formats/recording_csv.hpp"
#include "formats/recording_format.hpp"

using namespace gyrod::recording;
namespace fs = std::filesystem;

namespace {

class TempFile {
 public:
  explicit TempFile(const std::string& text) {
    path_ = (fs::temp_directory_path() / ("gyrod-reading-test-" + std::to_string(::getpid()) + ".csv")).string();
    std::ofstream(path_, std::ios::binary) << text;
  }
  ~TempFile() { std::remove(path_.c_str()); }
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
  TempFile f(w.text);
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
  TempFile f(w.text);
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
    TempFile f(withBadSample(w.text, sample));
    try {
      (void)readRecordingCsv(f.path());
      FAIL() << "accepted a bad value at sample " << sample;
    } catch (const RecordingError& e) {
      EXPECT_EQ(std::string(e.what()),
                f.path() + ":" + std::to_string(w.lines[sample]) + ": column 'gy': 'x' is not a number");
    }
  }
  // Two bad lines a few kB apart (one chunk, most likely in both of its slices): the first.
  TempFile two(withBadSample(withBadSample(w.text, 30'000), 25'000));
  try {
    (void)readRecordingCsv(two.path());
    FAIL() << "accepted two bad values";
  } catch (const RecordingError& e) {
    EXPECT_EQ(std::string(e.what()),
              two.path() + ":" + std::to_string(w.lines[25'000]) + ": column 'gy': 'x' is not a number");
  }
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
  TempFile f(text);
  const Recording rec = readRecordingCsv(f.path());
  EXPECT_EQ(rec.size(), samples);
  EXPECT_EQ(rec.lost, expected);
}

TEST(RecordingReading, ProgressIsReportedEveryMillionLines) {
  std::string text;
  const std::size_t count = kProgressLines * 2 + 10;
  text.reserve(count * 2);
  for (std::size_t i = 0; i < count; ++i) text += "1\n";
  TempFile f(text);
  std::vector<std::size_t> reported_lines;
  std::vector<std::uint64_t> reported_bytes;
  ReadOptions options;
  options.progress = [&](std::size_t lines, std::uint64_t bytes) {
    reported_lines.push_back(lines);
    reported_bytes.push_back(bytes);
  };
  const Recording rec = readRecordingCsv(f.path(), options);
  EXPECT_EQ(rec.size(), count);
  EXPECT_EQ(reported_lines, (std::vector<std::size_t>{kProgressLines, 2 * kProgressLines}));
  EXPECT_EQ(reported_bytes, (std::vector<std::uint64_t>{2 * kProgressLines, 4 * kProgressLines}));
}

}  // namespace
