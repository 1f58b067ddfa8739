// The sample recorder: what it writes reads back through the project's CSV reader
// bit-exact; rotation and retention; ring-full drops counted and marked in the file;
// a kill -9 leaves a file of whole lines holding everything flushed before the kill.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <thread>

#include "daemon/recorder.hpp"
#include "formats/recording_csv.hpp"

using namespace gyrod::daemon;
using gyrod::recording::readRecordingCsv;
namespace fs = std::filesystem;

namespace {

class RecorderTempDir {
 public:
  RecorderTempDir() {
    char tmpl[] = "/tmp/gyrod-recorder-test-XXXXXX";
    path_ = mkdtemp(tmpl);
  }
  ~RecorderTempDir() { fs::remove_all(path_); }
  std::string path(const std::string& name = "") const { return (fs::path(path_) / name).string(); }

 private:
  std::string path_;
};

std::string recorderReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> linesOf(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream s(text);
  std::string line;
  while (std::getline(s, line)) lines.push_back(line);
  return lines;
}

RecorderOptions options(const std::string& path) {
  RecorderOptions o;
  o.path = path;
  o.flush_interval_s = 3600.0;  // only flush() and stop() write, so tests are deterministic
  return o;
}

}  // namespace

TEST(Recorder, SamplesReadBackBitExactThroughTheRecordingReader) {
  RecorderTempDir d;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  struct Row {
    double t, gx, gy, gz, temp;
  };
  std::vector<Row> rows;
  for (int i = 0; i < 300; ++i)
    rows.push_back({i * 0.02, noise(rng) * 0.05, noise(rng) * 1e-7, noise(rng) * 250.0, 25.0 + noise(rng)});
  // Values that need all 17 significant digits, and extremes of the format.
  rows.push_back({6.0, 0.1 + 0.2, -1.0 / 3.0, std::numeric_limits<double>::denorm_min(), -40.0});
  rows.push_back({6.02, 1e300, -0.0, 2.0 / 3.0 * 1e-300, 85.0});
  {
    auto o = options(d.path("gyro.csv"));
    o.header_comments = {"device mock, rate_hz 50"};
    Recorder rec(o);
    for (const auto& r : rows) ASSERT_TRUE(rec.pushSample(r.t, r.gx, r.gy, r.gz, r.temp));
    rec.stop();
    EXPECT_EQ(rec.stats().written, rows.size());
    EXPECT_EQ(rec.stats().pushed, rows.size());
    EXPECT_EQ(rec.stats().dropped, 0u);
  }
  const auto files = fs::directory_iterator(d.path());
  std::vector<std::string> names;
  for (const auto& e : files) names.push_back(e.path().string());
  ASSERT_EQ(names.size(), 1u);
  const auto rec = readRecordingCsv(names[0]);
  ASSERT_EQ(rec.size(), rows.size());
  ASSERT_EQ(rec.axis_names, (std::vector<std::string>{"gx", "gy", "gz"}));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rec.t[i], rows[i].t) << i;
    EXPECT_EQ(rec.axes[0][i], rows[i].gx) << i;
    EXPECT_EQ(rec.axes[1][i], rows[i].gy) << i;
    EXPECT_EQ(rec.axes[2][i], rows[i].gz) << i;
    EXPECT_EQ(rec.temp[i], rows[i].temp) << i;
  }
  EXPECT_TRUE(std::signbit(rec.axes[1].back()));  // -0 survives
  const auto text = recorderReadText(names[0]);
  EXPECT_NE(text.find("# device mock, rate_hz 50\n"), std::string::npos);
  // The column line first (numpy's genfromtxt(names=True) takes the first line), then the comments.
  EXPECT_EQ(linesOf(text)[0], "t,gx,gy,gz,temp");
  EXPECT_EQ(linesOf(text)[1].rfind("# gyrod recording, opened ", 0), 0u);
}

TEST(Recorder, GapsAreCommentLinesInStreamOrder) {
  RecorderTempDir d;
  std::string file;
  {
    Recorder rec(options(d.path("gyro.csv")));
    file = rec.currentFile();
    rec.pushSample(0.00, 1, 2, 3, 25);
    rec.pushSample(0.02, 1, 2, 3, 25);
    rec.pushGap(2, 0.04, 4, "fifo_overflow");
    rec.pushSample(0.12, 1, 2, 3, 25);
    rec.pushGap(7, 0.14, 1, "weird reason\nwith newline, comma");
    rec.stop();
  }
  const auto lines = linesOf(recorderReadText(file));
  std::vector<std::string> tail(lines.end() - 5, lines.end());
  EXPECT_EQ(tail,
            (std::vector<std::string>{"0,1,2,3,25", "0.02,1,2,3,25", "# GAP seq=2 t=0.04 count=4 reason=fifo_overflow",
                                      "0.12,1,2,3,25", "# GAP seq=7 t=0.14 count=1 reason=weird_reason_with_newli"}));
  const auto rec = readRecordingCsv(file);
  EXPECT_EQ(rec.t, (std::vector<double>{0.0, 0.02, 0.12}));
}

TEST(Recorder, NonFiniteSamplesAreKeptAsCommentsSoTheFileStaysReadable) {
  RecorderTempDir d;
  std::string file;
  {
    Recorder rec(options(d.path("gyro.csv")));
    file = rec.currentFile();
    rec.pushSample(0.0, 1, 2, 3, 25);
    rec.pushSample(0.02, std::nan(""), 2, 3, 25);
    rec.pushSample(0.04, 1, 2, 3, 25);
  }
  EXPECT_NE(recorderReadText(file).find("\n# NONFINITE 0.02,nan,2,3,25\n"), std::string::npos);
  EXPECT_EQ(readRecordingCsv(file).t, (std::vector<double>{0.0, 0.04}));
}

TEST(Recorder, RingFullDropsAreCountedAndMarkedWhereTheyHappened) {
  RecorderTempDir d;
  auto o = options(d.path("gyro.csv"));
  o.ring_capacity = 16;
  std::string file;
  {
    Recorder rec(o);
    file = rec.currentFile();
    int accepted = 0, refused = 0;
    for (int i = 0; i < 20; ++i) (rec.pushSample(i, i, 0, 0, 25) ? accepted : refused)++;
    EXPECT_EQ(accepted, 16);
    EXPECT_EQ(refused, 4);
    EXPECT_EQ(rec.stats().dropped, 4u);
    rec.flush();  // the writer empties the ring
    EXPECT_EQ(rec.stats().written, 16u);
    EXPECT_TRUE(rec.pushSample(100, 100, 0, 0, 25));  // carries "4 dropped before me"
    for (int i = 0; i < 15; ++i) EXPECT_TRUE(rec.pushSample(101 + i, 0, 0, 0, 25));
    EXPECT_FALSE(rec.pushSample(200, 0, 0, 0, 25));  // full again: 16 in the ring
    EXPECT_FALSE(rec.pushSample(201, 0, 0, 0, 25));
    rec.stop();
    EXPECT_EQ(rec.stats().dropped, 6u);
    EXPECT_EQ(rec.stats().written, 32u);
  }
  const auto lines = linesOf(recorderReadText(file));
  const auto at = [&](const std::string& l) { return std::find(lines.begin(), lines.end(), l) - lines.begin(); };
  const auto drop4 = at("# DROPPED count=4 reason=ring_full");
  ASSERT_LT(drop4, static_cast<long>(lines.size()));
  EXPECT_EQ(lines[drop4 - 1], "15,15,0,0,25");
  EXPECT_EQ(lines[drop4 + 1], "100,100,0,0,25");
  EXPECT_EQ(lines.back(), "# DROPPED count=2 reason=ring_full");  // drops after the last record, at stop
  EXPECT_EQ(readRecordingCsv(file).size(), 32u);
}

TEST(Recorder, GapsAndDropsReadBackAsLostSampleRecords) {
  RecorderTempDir d;
  auto o = options(d.path("gyro.csv"));
  o.ring_capacity = 16;
  std::string file;
  {
    Recorder rec(o);
    file = rec.currentFile();
    rec.pushSample(0.00, 1, 2, 3, 25);
    rec.pushGap(1, 0.02, 3, "fifo overflow");
    for (int i = 0; i < 16; ++i) rec.pushSample(0.08 + 0.02 * i, 1, 2, 3, 25);  // the last two are dropped
    rec.stop();
  }
  const auto rec = readRecordingCsv(file);
  ASSERT_EQ(rec.size(), 15u);
  ASSERT_EQ(rec.lost.size(), 2u);
  EXPECT_EQ(rec.lost[0].kind, gyrod::recording::LostSamples::Kind::Gap);
  EXPECT_EQ(rec.lost[0].seq, 1u);
  EXPECT_EQ(rec.lost[0].t_s, 0.02);
  EXPECT_EQ(rec.lost[0].count, 3u);
  EXPECT_EQ(rec.lost[0].reason, "fifo_overflow");
  EXPECT_EQ(rec.lost[0].before_sample, 1u);
  EXPECT_EQ(rec.lost[0].line, rec.line_numbers[0] + 1);
  EXPECT_EQ(rec.lost[1].kind, gyrod::recording::LostSamples::Kind::Dropped);
  EXPECT_EQ(rec.lost[1].count, 2u);
  EXPECT_EQ(rec.lost[1].reason, "ring_full");
  EXPECT_EQ(rec.lost[1].before_sample, 15u);
}

TEST(Recorder, NoLineCrossesAPageBoundaryOfTheFile) {
  // The property that makes kill -9 safe: each write() stays inside one page.
  RecorderTempDir d;
  std::string file;
  {
    Recorder rec(options(d.path("gyro.csv")));
    file = rec.currentFile();
    std::mt19937_64 rng(3);
    std::normal_distribution<double> noise(0.0, 1.0);
    for (int i = 0; i < 2000; ++i) {
      rec.pushSample(i * 0.02, noise(rng), noise(rng), noise(rng), 25 + noise(rng));
      if (i % 300 == 0) rec.flush();
    }
  }
  const auto text = recorderReadText(file);
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  ASSERT_GT(text.size(), 10 * page);
  for (std::size_t boundary = page; boundary <= text.size(); boundary += page)
    EXPECT_EQ(text[boundary - 1], '\n') << "byte " << boundary - 1;
  EXPECT_EQ(text.back(), '\n');
  EXPECT_EQ(readRecordingCsv(file).size(), 2000u);
}

TEST(Recorder, RotatesBySizeAndEveryFileStandsAlone) {
  RecorderTempDir d;
  auto o = options(d.path("gyro.csv"));
  o.rotate_bytes = 3000;
  const int n = 1000;
  std::vector<std::string> files;
  {
    Recorder rec(o);
    for (int i = 0; i < n; ++i) {
      ASSERT_TRUE(rec.pushSample(i * 0.02, i, -i, 0.5 * i, 25));
      if (i % 100 == 99) rec.flush();
    }
    rec.stop();
    files = rec.files();
    EXPECT_EQ(rec.stats().files_opened, files.size());
  }
  ASSERT_GT(files.size(), 5u);
  std::vector<double> gx;
  for (std::size_t k = 0; k < files.size(); ++k) {
    EXPECT_TRUE(isRecordingFileName(fs::path(files[k]).filename().string(), "gyro", ".csv")) << files[k];
    EXPECT_LE(fs::file_size(files[k]), 3000u) << files[k];
    const auto r = readRecordingCsv(files[k]);  // each file has its own header
    gx.insert(gx.end(), r.axes[0].begin(), r.axes[0].end());
    if (k > 0) {
      EXPECT_NE(recorderReadText(files[k]).find("# continues " + fs::path(files[k - 1]).filename().string() + "\n"),
                std::string::npos);
    }
  }
  // Name order is recording order, and nothing is lost or repeated at the seams.
  ASSERT_EQ(gx.size(), static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) EXPECT_EQ(gx[i], i);
}

TEST(Recorder, KeepsOnlyTheNewestFilesAndLeavesOtherFilesAlone) {
  RecorderTempDir d;
  std::ofstream(d.path("gyro.csv")) << "not ours\n";
  std::ofstream(d.path("gyro-notes.csv")) << "not ours\n";
  std::ofstream(d.path("other-20200101T000000Z-000000.csv")) << "not ours\n";
  auto o = options(d.path("gyro.csv"));
  o.rotate_bytes = 2000;
  o.keep = 3;
  const int n = 1000;
  std::vector<std::string> files;
  {
    Recorder rec(o);
    for (int i = 0; i < n; ++i) {
      rec.pushSample(i * 0.02, i, 0, 0, 25);
      if (i % 50 == 49) rec.flush();
    }
    rec.stop();
    files = rec.files();
    EXPECT_GT(rec.stats().files_opened, 3u);
  }
  ASSERT_EQ(files.size(), 3u);
  EXPECT_TRUE(fs::exists(d.path("gyro.csv")));
  EXPECT_TRUE(fs::exists(d.path("gyro-notes.csv")));
  EXPECT_TRUE(fs::exists(d.path("other-20200101T000000Z-000000.csv")));
  // The three kept files are the last ones: they end with the last sample and are contiguous.
  std::vector<double> gx;
  for (const auto& f : files) {
    const auto r = readRecordingCsv(f);
    gx.insert(gx.end(), r.axes[0].begin(), r.axes[0].end());
  }
  ASSERT_FALSE(gx.empty());
  EXPECT_EQ(gx.back(), n - 1);
  for (std::size_t i = 1; i < gx.size(); ++i) EXPECT_EQ(gx[i], gx[i - 1] + 1);
}

TEST(Recorder, RotatesByTime) {
  RecorderTempDir d;
  auto o = options(d.path("gyro.csv"));
  o.rotate_after_s = 0.001;
  Recorder rec(o);
  rec.pushSample(0, 0, 0, 0, 25);
  rec.flush();
  EXPECT_EQ(rec.files().size(), 1u);
  std::this_thread::sleep_for(std::chrono::milliseconds(5));  // ≥ rotate_after_s since opening
  rec.pushSample(1, 1, 0, 0, 25);
  rec.flush();
  rec.stop();
  const auto files = rec.files();
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(readRecordingCsv(files[0]).t, std::vector<double>{0.0});
  EXPECT_EQ(readRecordingCsv(files[1]).t, std::vector<double>{1.0});
}

// A 32-bit time_t (armhf, bookworm) cannot hold 2^31 s; the name must not wrap to 1901.
TEST(Recorder, FileNamesAfter2038OnEveryTarget) {
  EXPECT_EQ(recordingFileName("gyro", ".csv", std::int64_t{1} << 31, 3), "gyro-20380119T031408Z-000003.csv");
}

TEST(Recorder, FileNames) {
  // 2025-01-02 03:04:05 UTC = 1735787045 s since the epoch.
  EXPECT_EQ(recordingFileName("gyro", ".csv", 1735787045, 7), "gyro-20250102T030405Z-000007.csv");
  EXPECT_TRUE(isRecordingFileName("gyro-20250102T030405Z-000007.csv", "gyro", ".csv"));
  EXPECT_TRUE(isRecordingFileName("gyro-20250102T030405Z-1234567.csv", "gyro", ".csv"));
  EXPECT_FALSE(isRecordingFileName("gyro-20250102T030405Z-000007.csv", "gyr", ".csv"));
  EXPECT_FALSE(isRecordingFileName("gyro-20250102T030405Z-00007.csv", "gyro", ".csv"));
  EXPECT_FALSE(isRecordingFileName("gyro-2025010xT030405Z-000007.csv", "gyro", ".csv"));
  EXPECT_FALSE(isRecordingFileName("gyro.csv", "gyro", ".csv"));
  EXPECT_TRUE(isRecordingFileName("log-20250102T030405Z-000000", "log", ""));
}

TEST(Recorder, CannotCreateTheFileIsAnErrorNamingThePath) {
  RecorderTempDir d;
  const auto path = d.path("missing-dir/gyro.csv");
  try {
    Recorder rec(options(path));
    FAIL() << "no error";
  } catch (const RecorderError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos) << e.what();
  }
  auto bad = options(d.path("gyro.csv"));
  bad.flush_interval_s = 0;
  EXPECT_THROW(Recorder{bad}, std::invalid_argument);
}

TEST(Recorder, OptionsFromConfig) {
  RecordConfig c;
  c.path = "/var/lib/gyrod/gyro.csv";
  c.rotate_mb = 1.5;
  c.rotate_minutes = 2;
  c.flush_interval_s = 0.5;
  c.keep = 4;
  const auto o = recorderOptions(c, 50.0);
  EXPECT_EQ(o.path, c.path);
  EXPECT_EQ(o.rotate_bytes, 1500000u);
  EXPECT_EQ(o.rotate_after_s, 120.0);
  EXPECT_EQ(o.flush_interval_s, 0.5);
  EXPECT_EQ(o.keep, 4u);
  EXPECT_GE(static_cast<double>(o.ring_capacity), 4 * 50.0 * 0.5);
  EXPECT_GE(static_cast<double>(recorderOptions(c, 8000.0).ring_capacity), 4 * 8000.0 * 0.5);
}

// ---- crash ---------------------------------------------------------------------------

namespace {

// Child: records as fast as it can (gx = index of the accepted sample) and reports the
// recorder's `written` count through the pipe each time it grows. Never returns.
[[noreturn]] void recordUntilKilled(const std::string& path, int report_fd) {
  RecorderOptions o;
  o.path = path;
  o.flush_interval_s = 0.1;
  o.ring_capacity = 1 << 16;
  Recorder rec(o);
  std::uint64_t accepted = 0, reported = 0;
  // Bursts of 100 samples with a 1 ms pause: ~10^5 samples/s, 2000 times gyrod's rate,
  // so that flushes are large and a kill often lands while the writer is writing.
  while (true) {
    for (int i = 0; i < 100; ++i)
      if (rec.pushSample(static_cast<double>(accepted) * 1e-3, static_cast<double>(accepted), -1.0, 0.5, 25.0))
        ++accepted;
    const auto written = rec.stats().written;
    if (written != reported) {
      reported = written;
      if (::write(report_fd, &reported, sizeof reported) != sizeof reported) _exit(3);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

}  // namespace

TEST(RecorderCrash, KillNineLeavesWholeLinesAndEverythingFlushedBeforeIt) {
  // Kill at different moments: after 3, 6 and 9 reported flushes.
  for (int flushes_before_kill : {3, 6, 9}) {
    RecorderTempDir d;
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    std::fflush(stdout);  // the child must not inherit (and later print) buffered output
    std::fflush(stderr);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(fds[0]);
      recordUntilKilled(d.path("crash.csv"), fds[1]);
    }
    ::close(fds[1]);
    std::uint64_t last_reported = 0;
    int reports = 0;
    while (reports < flushes_before_kill) {
      std::uint64_t v = 0;
      ASSERT_EQ(::read(fds[0], &v, sizeof v), static_cast<ssize_t>(sizeof v)) << "child died early";
      last_reported = v;
      ++reports;
    }
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
    // Reports the child managed to send before it died raise the bound further.
    std::uint64_t v = 0;
    while (::read(fds[0], &v, sizeof v) == static_cast<ssize_t>(sizeof v)) last_reported = v;
    ::close(fds[0]);

    std::vector<std::string> files;
    for (const auto& e : fs::directory_iterator(d.path())) files.push_back(e.path().string());
    ASSERT_EQ(files.size(), 1u);
    const auto text = recorderReadText(files[0]);
    EXPECT_EQ(text.back(), '\n') << "torn last line";
    const auto rec = readRecordingCsv(files[0]);  // throws on a torn or malformed line
    ASSERT_GE(rec.size(), last_reported) << "lost records the recorder reported written";
    const auto& gx = rec.axes[0];
    for (std::size_t i = 0; i < gx.size(); ++i)
      ASSERT_EQ(gx[i], static_cast<double>(i)) << "line " << rec.line_numbers[i];
    std::cout << "kill after " << flushes_before_kill << " flushes: " << last_reported << " reported written, "
              << rec.size() << " in the file\n";
  }
}

namespace {

gyrod::recording::SampleValues gyrodSample(int i, bool accel) {
  gyrod::recording::SampleValues v;
  v.t_s = i * 0.02;
  v.gx_dps = 0.01 * i;
  v.gy_dps = -1.0 / (i + 3);
  v.gz_dps = 0.5;
  v.temp_c = 25.0 + 0.001 * i;
  v.wall_ns = 1'795'000'000'000'000'000 + std::int64_t{20'000'000} * i;
  if (accel) v.accel_g = {0.001 * i, -0.002, 1.0};
  if (i >= 5) {  // before: the start-up estimation (no rate yet)
    v.rate_dps = {v.gx_dps + 3.34, v.gy_dps - 1.09, 1.0};
    v.bias_dps = {-3.34, 1.09, -0.5};
    v.still = static_cast<std::int8_t>(i % 2);
  }
  return v;
}

RecorderOptions gyrodOptions(const std::string& path) {
  auto o = options(path);
  o.columns.time = true;
  o.columns.rate = true;
  return o;
}

}  // namespace

TEST(RecorderColumns, TheRateStreamAndTheWallClockAreRecordedAndReadBack) {
  RecorderTempDir d;
  std::string file;
  {
    Recorder rec(gyrodOptions(d.path("gyro.csv")));
    file = rec.currentFile();
    for (int i = 0; i < 20; ++i) ASSERT_TRUE(rec.pushSample(gyrodSample(i, false)));
  }
  const auto lines = linesOf(recorderReadText(file));
  EXPECT_EQ(lines[0], "t,gx,gy,gz,temp,time,gx_rate,gy_rate,gz_rate,gx_bias,gy_bias,gz_bias,still");
  EXPECT_EQ(lines[2], "0,0,-0.3333333333333333,0.5,25,1795000000.000000,,,,,,,");
  const auto rec = readRecordingCsv(file);
  ASSERT_EQ(rec.size(), 20u);
  for (int i = 0; i < 20; ++i) {
    const auto v = gyrodSample(i, false);
    EXPECT_EQ(rec.t[i], v.t_s);
    EXPECT_EQ(rec.axes[1][i], v.gy_dps);
    EXPECT_NEAR(rec.time[i], 1795000000.0 + 0.02 * i, 1e-6) << i;
    for (int a = 0; a < 3; ++a) {
      if (i < 5) {
        EXPECT_TRUE(std::isnan(rec.rate[a][i]) && std::isnan(rec.bias[a][i])) << i;
      } else {
        EXPECT_EQ(rec.rate[a][i], v.rate_dps[a]) << i;  // bit for bit
        EXPECT_EQ(rec.bias[a][i], v.bias_dps[a]) << i;
      }
    }
    if (i < 5)
      EXPECT_TRUE(std::isnan(rec.still[i]));
    else
      EXPECT_EQ(rec.still[i], i % 2);
  }
}

TEST(RecorderColumns, TheFirstSampleDecidesTheAccelColumns) {
  RecorderTempDir d;
  std::string file;
  {
    Recorder rec(gyrodOptions(d.path("gyro.csv")));
    file = rec.currentFile();
    // A gap before any sample waits for the column line, which must stay the first line.
    rec.pushGap(0, 0.0, 2, "fifo_overflow");
    rec.flush();
    EXPECT_EQ(recorderReadText(file), "");
    for (int i = 2; i < 10; ++i) ASSERT_TRUE(rec.pushSample(gyrodSample(i, true)));
  }
  const auto lines = linesOf(recorderReadText(file));
  EXPECT_EQ(lines[0], "t,gx,gy,gz,temp,time,ax,ay,az,gx_rate,gy_rate,gz_rate,gx_bias,gy_bias,gz_bias,still");
  EXPECT_EQ(lines[2], "# GAP seq=0 t=0 count=2 reason=fifo_overflow");
  EXPECT_EQ(lines[3], "0.04,0.02,-0.2,0.5,25.002,1795000000.040000,0.002,-0.002,1,,,,,,,");
  try {
    const auto rec = readRecordingCsv(file);
    EXPECT_EQ(rec.size(), 8u);
    EXPECT_EQ(rec.time.size(), 8u);
  } catch (const gyrod::recording::RecordingError& e) {
    // Reading ax,ay,az is the accelerometer import's (kalibr's) part of issue 12; until it is merged
    // the reader does not know them. The Python readers' test checks the values meanwhile.
    if (std::string(e.what()).find("unknown column 'ax'") == std::string::npos) throw;
    GTEST_SKIP() << "the CSV reader does not read ax,ay,az yet: " << e.what();
  }
}

TEST(RecorderColumns, AFileWithoutSamplesStillHasItsHeader) {
  RecorderTempDir d;
  std::string file;
  {
    auto o = gyrodOptions(d.path("gyro.csv"));
    o.header_comments = {"device mock"};
    Recorder rec(o);
    file = rec.currentFile();
  }
  const auto lines = linesOf(recorderReadText(file));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "t,gx,gy,gz,temp,time,gx_rate,gy_rate,gz_rate,gx_bias,gy_bias,gz_bias,still");
  EXPECT_EQ(lines[2], "# device mock");
}
