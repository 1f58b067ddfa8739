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
