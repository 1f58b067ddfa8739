// Recording losses to failed writes: counted (stats, lastError) and announced in the file by a
// "# DROPPED count=N reason=..." line at the next write that succeeds. The failure is real:
// RLIMIT_FSIZE at the file's size makes the kernel refuse the next write with EFBIG (SIGXFSZ
// ignored), as a full disk refuses it with ENOSPC.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "daemon/recorder.hpp"
#include "formats/recording_csv.hpp"

using namespace gyrod::daemon;
namespace fs = std::filesystem;

namespace {

class ErrorsTempDir {
 public:
  ErrorsTempDir() {
    char tmpl[] = "/tmp/gyrod-recorder-errors-XXXXXX";
    path_ = mkdtemp(tmpl);
  }
  ~ErrorsTempDir() { fs::remove_all(path_); }
  std::string path(const std::string& name) const { return (fs::path(path_) / name).string(); }

 private:
  std::string path_;
};

// Files may not grow past `bytes` while it lives (the process's soft limit; the hard one stays).
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    old_handler_ = ::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    ok_ = ::setrlimit(RLIMIT_FSIZE, &limit) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    ::signal(SIGXFSZ, old_handler_);
  }
  bool ok() const { return ok_; }

 private:
  rlimit saved_{};
  sighandler_t old_handler_ = SIG_DFL;
  bool ok_ = false;
};

}  // namespace

TEST(RecorderWriteErrors, LossesAreCountedAndAnnouncedWhenWritingWorksAgain) {
  ErrorsTempDir d;
  RecorderOptions o;
  o.path = d.path("gyro.csv");
  o.flush_interval_s = 3600.0;  // only flush() and stop() write
  Recorder rec(o);
  const std::string file = rec.currentFile();
  for (int i = 0; i < 100; ++i) rec.pushSample(0.02 * i, i, 0, 0, 25);
  rec.flush();
  ASSERT_EQ(rec.stats().written, 100u);
  EXPECT_EQ(rec.lastError(), "");

  RecorderStats during;
  std::string error_during;
  {
    FileSizeLimit limit(fs::file_size(file));
    ASSERT_TRUE(limit.ok());
    for (int i = 100; i < 300; ++i) rec.pushSample(0.02 * i, i, 0, 0, 25);
    rec.flush();
    during = rec.stats();
    error_during = rec.lastError();
  }
  EXPECT_EQ(during.written, 100u);
  EXPECT_EQ(during.lost_to_errors, 200u);
  EXPECT_GE(during.write_errors, 1u);
  EXPECT_EQ(during.lost_announced, 0u);
  EXPECT_EQ(error_during, "write to " + file + ": File too large");

  for (int i = 300; i < 350; ++i) rec.pushSample(0.02 * i, i, 0, 0, 25);
  rec.stop();
  const RecorderStats after = rec.stats();
  EXPECT_EQ(after.written, 150u);
  EXPECT_EQ(after.lost_to_errors, 200u);
  EXPECT_EQ(after.lost_announced, 200u);

  const auto recording = gyrod::recording::readRecordingCsv(file);
  ASSERT_EQ(recording.size(), 150u);
  ASSERT_EQ(recording.lost.size(), 1u);
  EXPECT_EQ(recording.lost[0].kind, gyrod::recording::LostSamples::Kind::Dropped);
  EXPECT_EQ(recording.lost[0].count, 200u);
  EXPECT_EQ(recording.lost[0].reason, "write_error");
  EXPECT_EQ(recording.lost[0].before_sample, 100u);  // where the hole in t is
  EXPECT_EQ(recording.t[100], 0.02 * 300);
}

TEST(RecorderWriteErrors, AFileThatCannotBeCreatedLosesRecordsWithTheCause) {
  ErrorsTempDir d;
  RecorderOptions o;
  o.path = d.path("sub/gyro.csv");
  fs::create_directory(d.path("sub"));
  o.flush_interval_s = 3600.0;
  o.rotate_bytes = 1;  // a new file before every record: each needs a create
  Recorder rec(o);
  fs::remove_all(d.path("sub"));  // the folder vanishes: creating the next file fails
  for (int i = 0; i < 10; ++i) rec.pushSample(i, i, 0, 0, 25);
  rec.stop();
  EXPECT_EQ(rec.stats().written, 1u);  // into the open file (its name is gone, not the file)
  EXPECT_EQ(rec.stats().lost_to_errors, 9u);
  EXPECT_NE(rec.lastError().find("No such file or directory"), std::string::npos) << rec.lastError();
}

// A real full disk where the test may mount a 64 KiB tmpfs (root); skipped elsewhere.
TEST(RecorderWriteErrors, AFullDiskIsADroppedLineWithReasonDiskFullOnceThereIsRoomAgain) {
  ErrorsTempDir d;
  const fs::path tiny = d.path("tiny");
  fs::create_directories(tiny);
  if (::mount("tmpfs", tiny.c_str(), "tmpfs", 0, "size=64k") != 0) GTEST_SKIP() << "cannot mount a tmpfs here";
  struct Unmount {
    fs::path dir;
    ~Unmount() { ::umount2(dir.c_str(), MNT_DETACH); }
  } unmount{tiny};
  {
    std::ofstream ballast(tiny / "ballast", std::ios::binary);
    ballast << std::string(48 * 1024, 'b');
  }
  RecorderOptions o;
  o.path = (tiny / "gyro.csv").string();
  o.flush_interval_s = 3600.0;
  Recorder rec(o);
  const std::string file = rec.currentFile();
  for (int i = 0; i < 1000; ++i) rec.pushSample(0.02 * i, 0.001 * i, -0.5, 0.25, 25.5);  // ~30 kB of lines
  rec.flush();
  const RecorderStats full = rec.stats();
  EXPECT_GT(full.lost_to_errors, 0u);
  EXPECT_EQ(full.written + full.lost_to_errors, 1000u);
  EXPECT_NE(rec.lastError().find("No space left on device"), std::string::npos) << rec.lastError();
  fs::remove(tiny / "ballast");
  for (int i = 1000; i < 1010; ++i) rec.pushSample(0.02 * i, 0.0, 0.0, 0.0, 25.5);
  rec.stop();
  EXPECT_EQ(rec.stats().lost_announced, full.lost_to_errors);
  const auto recording = gyrod::recording::readRecordingCsv(file);
  EXPECT_EQ(recording.size(), full.written + 10);
  ASSERT_EQ(recording.lost.size(), 1u);
  EXPECT_EQ(recording.lost[0].reason, "disk_full");
  EXPECT_EQ(recording.lost[0].count, full.lost_to_errors);
}
