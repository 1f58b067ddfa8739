// The recording's line format: what the writer's functions produce, byte for byte, reads
// back through readRecordingCsv, GAP and DROPPED lines included as LostSamples records;
// a '#' line that only resembles one stays an ordinary comment.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "formats/recording_csv.hpp"
#include "formats/recording_format.hpp"

using namespace gyrod::recording;
namespace fs = std::filesystem;

namespace {

class TempFile {
 public:
  explicit TempFile(const std::string& text) {
    path_ = (fs::temp_directory_path() /
             ("gyrod-format-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++) + ".csv"))
                .string();
    std::ofstream(path_, std::ios::binary) << text;
  }
  ~TempFile() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  static inline int counter_ = 0;
  std::string path_;
};

LostSamples gap(std::uint64_t seq, double t, std::uint64_t count, std::string reason, std::size_t line,
                std::size_t before) {
  LostSamples l;
  l.kind = LostSamples::Kind::Gap;
  l.seq = seq;
  l.t_s = t;
  l.count = count;
  l.reason = std::move(reason);
  l.line = line;
  l.before_sample = before;
  return l;
}

LostSamples dropped(std::uint64_t count, std::string reason, std::size_t line, std::size_t before) {
  LostSamples l;
  l.kind = LostSamples::Kind::Dropped;
  l.count = count;
  l.reason = std::move(reason);
  l.line = line;
  l.before_sample = before;
  return l;
}

}  // namespace

TEST(RecordingFormat, LinesAreWrittenByteForByte) {
  RecordingLine line;
  EXPECT_EQ(formatSampleLine(line, 0.02, 1, -2.5, 0.1 + 0.2, 25), "0.02,1,-2.5,0.30000000000000004,25\n");
  EXPECT_EQ(formatSampleLine(line, 0.04, std::nan(""), 2, 3, 25), "# NONFINITE 0.04,nan,2,3,25\n");
  EXPECT_EQ(formatGapLine(line, 2, 0.04, 4, "fifo_overflow"), "# GAP seq=2 t=0.04 count=4 reason=fifo_overflow\n");
  EXPECT_EQ(formatGapLine(line, 7, 1.5, 1, ""), "# GAP seq=7 t=1.5 count=1 reason=unknown\n");
  EXPECT_EQ(formatDroppedLine(line, 7, "ring_full"), "# DROPPED count=7 reason=ring_full\n");
  EXPECT_EQ(kColumnsLine, "t,gx,gy,gz,temp\n");
  EXPECT_EQ(recordingHeaderComments(0, "gyro-19700101T000000Z-000000.csv", {"device mock"}),
            "# gyrod recording, opened 1970-01-01T00:00:00Z\n# continues gyro-19700101T000000Z-000000.csv\n"
            "# device mock\n");
  EXPECT_EQ(reasonCharacter('a'), 'a');
  EXPECT_EQ(reasonCharacter(' '), '_');
  EXPECT_EQ(reasonCharacter(','), '_');
}

// 32-bit Debian (armhf, bookworm) has a 32-bit time_t: through gmtime_r a date after
// 2038-01-19T03:14:07Z came out as 1901. The header and the recorder's file names use
// utcCalendarTime, which takes the int64 seconds as they are.
TEST(RecordingFormat, DatesAfter2038AreWrittenOnEveryTarget) {
  EXPECT_EQ(recordingHeaderComments(std::int64_t{1} << 31, "", {}), "# gyrod recording, opened 2038-01-19T03:14:08Z\n");
  EXPECT_EQ(recordingHeaderComments(4102531199, "", {}), "# gyrod recording, opened 2100-01-01T23:59:59Z\n");
  const std::tm leap = utcCalendarTime(951782400);  // 2000-02-29, a Tuesday
  EXPECT_EQ(std::vector<int>({leap.tm_year, leap.tm_mon, leap.tm_mday, leap.tm_hour, leap.tm_wday, leap.tm_yday}),
            std::vector<int>({100, 1, 29, 0, 2, 59}));
  const std::tm before_epoch = utcCalendarTime(-1);  // 1969-12-31T23:59:59, a Wednesday
  EXPECT_EQ(std::vector<int>({before_epoch.tm_year, before_epoch.tm_mon, before_epoch.tm_mday, before_epoch.tm_hour,
                              before_epoch.tm_min, before_epoch.tm_sec, before_epoch.tm_wday, before_epoch.tm_yday}),
            std::vector<int>({69, 11, 31, 23, 59, 59, 3, 364}));
}

TEST(RecordingFormat, TheLongestLinesFit) {
  RecordingLine line;
  const double big = -std::numeric_limits<double>::min();  // "-2.2250738585072014e-308": 24 characters
  const auto sample = formatSampleLine(line, big, big, big, big, std::numeric_limits<double>::infinity());
  EXPECT_EQ(sample.rfind("# NONFINITE ", 0), 0u);
  EXPECT_LT(sample.size(), line.bytes.size());
  const auto g =
      formatGapLine(line, std::numeric_limits<std::uint64_t>::max(), big, 4294967295u, "abcdefghijklmnopqrstuvw");
  EXPECT_EQ(g.back(), '\n');
  EXPECT_LT(g.size(), line.bytes.size());
}

TEST(RecordingFormat, WriterLinesReadBackWithGapAndDroppedRecords) {
  RecordingLine line;
  std::string text = recordingHeaderComments(1735732800, "", {"device mock, rate_hz 50"});
  text += kColumnsLine;                                              // line 3
  text += formatSampleLine(line, 0.00, 0.125, -1.0 / 3.0, 2, 25.5);  // 4
  text += formatSampleLine(line, 0.02, -0.0, 1e-300, 2, 25.5);       // 5
  text += formatGapLine(line, 2, 0.04, 4, "fifo_overflow");          // 6
  text += formatSampleLine(line, 0.12, 1, 2, 3, 25.5);               // 7
  text += formatDroppedLine(line, 3, "ring_full");                   // 8
  text += formatSampleLine(line, 0.2, 1, 2, 3, std::nan(""));        // 9: a comment
  text += formatSampleLine(line, 0.22, 1, 2, 3, 26);                 // 10
  text += formatGapLine(line, 12, 0.24, 1, "bus_error");             // 11
  const TempFile f(text);
  const Recording rec = readRecordingCsv(f.path());
  ASSERT_EQ(rec.size(), 4u);
  EXPECT_EQ(rec.t, (std::vector<double>{0.0, 0.02, 0.12, 0.22}));
  EXPECT_EQ(rec.axes[1][0], -1.0 / 3.0);
  EXPECT_TRUE(std::signbit(rec.axes[0][1]));
  EXPECT_EQ(rec.axes[1][1], 1e-300);
  EXPECT_EQ(rec.line_numbers, (std::vector<std::size_t>{4, 5, 7, 10}));
  ASSERT_EQ(rec.lost.size(), 3u);
  EXPECT_EQ(rec.lost[0], gap(2, 0.04, 4, "fifo_overflow", 6, 2));
  EXPECT_EQ(rec.lost[1], dropped(3, "ring_full", 8, 3));
  EXPECT_EQ(rec.lost[2], gap(12, 0.24, 1, "bus_error", 11, 4));
}

TEST(RecordingFormat, LinesThatOnlyResembleAGapAreOrdinaryComments) {
  for (const std::string comment :
       {"# GAP", "# GAP at 12 s", "# GAP seq=1 t=x count=2 reason=a", "# GAP seq=1 t=0 count=2 reason=a extra",
        "# GAP seq=-1 t=0 count=2 reason=a", "# GAP seq=1 t=0 count=2 reason=", "# GAP seq=1 count=2 reason=a",
        "# GAP t=0 seq=1 count=2 reason=a", "# DROPPED count=two reason=ring_full", "# DROPPED count=2",
        "#GAP seq=1 t=0 count=2 reason=a", "# gap seq=1 t=0 count=2 reason=a", "# DROPPED count=2 reason=a,b"}) {
    const TempFile f("t,gx\n0,1\n" + comment + "\n0.02,2\n");
    const Recording rec = readRecordingCsv(f.path());
    EXPECT_EQ(rec.size(), 2u) << comment;
    EXPECT_TRUE(rec.lost.empty()) << comment;
  }
}

TEST(RecordingFormat, ParsesOnlyWhatTheWriterWrites) {
  const auto g = parseLostSamplesLine("# GAP seq=18446744073709551615 t=-1e-300 count=4294967295 reason=a.b-c_D9");
  ASSERT_TRUE(g);
  EXPECT_EQ(g->kind, LostSamples::Kind::Gap);
  EXPECT_EQ(g->seq, 18446744073709551615u);
  EXPECT_EQ(g->t_s, -1e-300);
  EXPECT_EQ(g->count, 4294967295u);
  EXPECT_EQ(g->reason, "a.b-c_D9");
  EXPECT_FALSE(parseLostSamplesLine("0.02,1,2,3,25"));
  EXPECT_FALSE(parseLostSamplesLine("# NONFINITE 0.04,nan,2,3,25"));
  EXPECT_FALSE(parseLostSamplesLine("#                "));
}

TEST(RecordingFormat, GapLinesBeforeTheHeaderAndInBareNumberFiles) {
  const TempFile before("# GAP seq=0 t=0 count=5 reason=start\nt,gx\n0.1,1\n");
  EXPECT_EQ(readRecordingCsv(before.path()).lost, (std::vector<LostSamples>{gap(0, 0, 5, "start", 1, 0)}));
  const TempFile bare("1.5\n# DROPPED count=2 reason=ring_full\n2.5\n");
  const Recording rec = readRecordingCsv(bare.path());
  EXPECT_EQ(rec.axes[0], (std::vector<double>{1.5, 2.5}));
  EXPECT_EQ(rec.lost, (std::vector<LostSamples>{dropped(2, "ring_full", 2, 1)}));
}

namespace {

SampleValues fullSample(double t) {
  SampleValues v;
  v.t_s = t;
  v.gx_dps = 0.125;
  v.gy_dps = -1.0 / 3.0;
  v.gz_dps = 2;
  v.temp_c = 25.5;
  v.wall_ns = 1'795'000'000'123'456'789;  // 2026-11-18T...: µs decimals, rounded
  v.accel_g = {0.01, -0.02, 1.0 / 3.0};
  v.rate_dps = {0.1 + 0.2, -0.0, 30};
  v.bias_dps = {-3.34, 1.09, -0.5};
  v.still = 1;
  v.attitude = {0.5, -0.5, 0.5, -0.5, 0.1 + 0.2, -0.0, 179.5, 0.25, 12};
  return v;
}

constexpr SampleColumns kAllColumns{true, true, true, true};

}  // namespace

TEST(RecordingFormat, GyrodsColumnsAreWrittenByteForByte) {
  EXPECT_EQ(columnsLine({}), kColumnsLine);
  EXPECT_EQ(columnsLine(kAllColumns),
            "t,gx,gy,gz,temp,time,ax,ay,az,gx_rate,gy_rate,gz_rate,gx_bias,gy_bias,gz_bias,still,"
            "qw,qx,qy,qz,roll,pitch,heading,inclination_std,heading_std\n");
  EXPECT_EQ(columnsLine({true, false, true}),
            "t,gx,gy,gz,temp,time,gx_rate,gy_rate,gz_rate,gx_bias,gy_bias,gz_bias,still\n");
  RecordingLine line;
  EXPECT_EQ(formatSampleLine(line, kAllColumns, fullSample(0.02)),
            "0.02,0.125,-0.3333333333333333,2,25.5,1795000000.123457,0.01,-0.02,0.3333333333333333,"
            "0.30000000000000004,-0,30,-3.34,1.09,-0.5,1,0.5,-0.5,0.5,-0.5,0.30000000000000004,-0,179.5,0.25,12\n");
  // What a sample does not have is an empty field (the start-up estimation, no detector, no accel).
  SampleValues partial = fullSample(0.04);
  partial.wall_ns = 0;
  partial.accel_g[1] = std::nan("");
  partial.rate_dps = partial.bias_dps = {std::nan(""), std::nan(""), std::nan("")};
  partial.still = -1;
  partial.attitude.fill(std::nan(""));
  EXPECT_EQ(formatSampleLine(line, kAllColumns, partial),
            "0.04,0.125,-0.3333333333333333,2,25.5,,0.01,,0.3333333333333333,,,,,,,,,,,,,,,,\n");
  partial.still = 0;
  EXPECT_EQ(formatSampleLine(line, {false, false, true}, partial), "0.04,0.125,-0.3333333333333333,2,25.5,,,,,,,0\n");
  // The five columns decide a NONFINITE comment, as before.
  SampleValues bad = fullSample(0.06);
  bad.temp_c = std::nan("");
  EXPECT_EQ(formatSampleLine(line, {false, false, true}, bad).rfind("# NONFINITE 0.06,", 0), 0u);
}

TEST(RecordingFormat, TheLongestGyrodLineFits) {
  RecordingLine line;
  SampleValues v;
  const double big = -std::numeric_limits<double>::min();  // 24 characters
  v.t_s = v.gx_dps = v.gy_dps = v.gz_dps = big;
  v.temp_c = std::numeric_limits<double>::infinity();
  v.wall_ns = std::numeric_limits<std::int64_t>::max();
  v.accel_g = v.rate_dps = v.bias_dps = {big, big, big};
  v.still = 1;
  v.attitude.fill(big);
  const auto sample = formatSampleLine(line, kAllColumns, v);
  EXPECT_EQ(sample.rfind("# NONFINITE ", 0), 0u);
  EXPECT_EQ(sample.back(), '\n');
  EXPECT_LT(sample.size(), line.bytes.size());
}

TEST(RecordingFormat, GyrodsColumnsReadBackWithEmptyFieldsAsNaN) {
  // Without ax,ay,az: reading them is the accelerometer import's part (kAccelColumns).
  constexpr SampleColumns columns{true, false, true, true};
  RecordingLine line;
  std::string text = columnsLine(columns);
  text += recordingHeaderComments(1735732800, "", {"device mock"});
  text += formatSampleLine(line, columns, fullSample(0.02));
  text += formatGapLine(line, 2, 0.04, 1, "fifo_overflow");
  SampleValues partial = fullSample(0.06);
  partial.rate_dps[2] = std::nan("");
  partial.still = -1;
  text += formatSampleLine(line, columns, partial);
  const TempFile file(text);
  const Recording rec = readRecordingCsv(file.path());
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.t, (std::vector<double>{0.02, 0.06}));
  EXPECT_EQ(rec.time, (std::vector<double>{1795000000.123457, 1795000000.123457}));
  EXPECT_EQ(rec.rate[0], (std::vector<double>{0.1 + 0.2, 0.1 + 0.2}));
  EXPECT_TRUE(std::signbit(rec.rate[1][0]));
  EXPECT_EQ(rec.rate[2][0], 30.0);
  EXPECT_TRUE(std::isnan(rec.rate[2][1]));
  EXPECT_EQ(rec.bias[0], (std::vector<double>{-3.34, -3.34}));
  EXPECT_EQ(rec.bias[2], (std::vector<double>{-0.5, -0.5}));
  EXPECT_EQ(rec.still[0], 1.0);
  EXPECT_TRUE(std::isnan(rec.still[1]));
  const SampleValues full = fullSample(0.02);
  for (std::size_t k = 0; k < full.attitude.size(); ++k) {
    ASSERT_EQ(rec.attitude[k].size(), 2u);
    EXPECT_EQ(rec.attitude[k][0], full.attitude[k]) << kAttitudeColumns[k];
  }
  EXPECT_TRUE(std::signbit(rec.attitude[5][0]));
  ASSERT_EQ(rec.lost.size(), 1u);
  EXPECT_EQ(rec.lost[0].before_sample, 1u);
  // Only gyrod's optional columns may be empty; "nan" is refused there as anywhere.
  const TempFile empty_gyro("t,gx,gx_rate\n0,,1\n");
  EXPECT_THROW(readRecordingCsv(empty_gyro.path()), RecordingError);
  const TempFile nan_rate("t,gx,gx_rate\n0,1,nan\n");
  EXPECT_THROW(readRecordingCsv(nan_rate.path()), RecordingError);
  const TempFile twice("t,gx,still,still\n0,1,1,1\n");
  EXPECT_THROW(readRecordingCsv(twice.path()), RecordingError);
  // An old recording (five columns) has none of them.
  const TempFile old("t,gx,gy,gz,temp\n0,1,2,3,25\n");
  const Recording five = readRecordingCsv(old.path());
  EXPECT_TRUE(five.time.empty() && five.rate[0].empty() && five.bias[2].empty() && five.still.empty() &&
              five.attitude[0].empty());
}

// docs/recording-format.md's column table names the columns columnsLine writes, in order.
TEST(RecordingFormat, TheDocumentedColumnsAreTheOnesWritten) {
  std::ifstream in(fs::path(GYROD_TEST_DATA_DIR).parent_path().parent_path() / "docs" / "recording-format.md");
  ASSERT_TRUE(in) << "cannot read docs/recording-format.md";
  std::string documented;
  bool in_columns = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("## ", 0) == 0) in_columns = line == "## Columns";
    if (!in_columns || line.rfind("| `", 0) != 0) continue;
    const std::string cell = line.substr(1, line.find('|', 1) - 1);  // "`gx`, `gy`, `gz`"
    for (std::size_t open = cell.find('`'); open != std::string::npos; open = cell.find('`', open + 1)) {
      const std::size_t close = cell.find('`', open + 1);
      documented += (documented.empty() ? "" : ",") + cell.substr(open + 1, close - open - 1);
      open = close;
    }
  }
  EXPECT_EQ(documented + "\n", columnsLine(kAllColumns));
}
