// gyroctl's outputs (README "Output files"): what sits at -o or --write-model is refused
// unless it is a regular file, the input is never the output, modes are kept, a killed
// simulate leaves neither a temporary file nor a partial target, and simulate refuses
// what cannot fit on the disk. Plus the small input messages of issue 16.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "tools/run_command.hpp"

extern char** environ;

namespace fs = std::filesystem;
using gyrod::test::binaryArgv;
using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

std::string noiseCsv(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::string s = "t,gx\n";
  char buf[64];
  for (std::size_t i = 0; i < n; ++i) {
    std::snprintf(buf, sizeof buf, "%.17g,%.17g\n", static_cast<double>(i) / 50.0, noise(rng));
    s += buf;
  }
  return s;
}

std::string imucal() { return "Fs,100\nLogging Type,1\nax,ay,az,gx,gy,gz\n1,2,3,4,5,6\n1,2,3,7,8,9\n"; }

struct FileState {
  bool exists = false;
  mode_t type_and_mode = 0;
  ino_t inode = 0;
  std::string content;  // regular files only
  bool operator==(const FileState&) const = default;
};

FileState stateOf(const fs::path& p) {
  FileState s;
  struct stat st {};
  if (::lstat(p.c_str(), &st) != 0) return s;
  s.exists = true;
  s.type_and_mode = st.st_mode;
  s.inode = st.st_ino;
  if (S_ISREG(st.st_mode)) s.content = readWholeFile(p);
  return s;
}

std::size_t tempFilesIn(const fs::path& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-gyroctl") != std::string::npos) ++n;
  return n;
}

// Each writer, writing to `target` (a valid input made in `d` where one is needed).
std::vector<std::string> everyWriter(const ScratchDir& d, const std::string& target) {
  const auto rec = d.write("rec.csv", noiseCsv(300, 1)).string();
  const auto raw = d.write("raw.txt", imucal()).string();
  return {
      "filter " + rec + " -o " + target,
      "import " + raw + " -o " + target,
      "simulate --arw 1 --duration 2 -o " + target,
      "analyze " + rec + " --write-model " + target,
      "model-check " + rec + " --replicas 8 --write-model " + target,
  };
}

void expectRefusal(const std::string& args, const ScratchDir& d, const fs::path& target,
                   std::initializer_list<std::string> parts) {
  const FileState before = stateOf(target);
  const auto r = runGyroctl(args, d.path());
  EXPECT_NE(r.exit_status, 0) << args;
  for (const std::string& part : parts)
    EXPECT_NE(r.err.find(part), std::string::npos) << args << ": missing '" << part << "' in: " << r.err;
  EXPECT_EQ(stateOf(target), before) << args << " changed " << target;
  EXPECT_EQ(tempFilesIn(d.path()), 0u) << args;
}

}  // namespace

TEST(GyroctlOutputFiles, ADeviceNodeIsRefusedByEveryWriter) {
  ScratchDir d;
  for (const std::string& args : everyWriter(d, "/dev/null"))
    expectRefusal(args, d, "/dev/null", {"/dev/null: refusing to write: it is a character device"});
}

TEST(GyroctlOutputFiles, AFifoIsRefusedByEveryWriter) {
  ScratchDir d;
  const auto fifo = d.path() / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& args : everyWriter(d, fifo.string()))
    expectRefusal(args, d, fifo, {fifo.string() + ": refusing to write: it is a FIFO"});
}

TEST(GyroctlOutputFiles, ADirectoryIsRefusedByEveryWriter) {
  ScratchDir d;
  const auto folder = d.path() / "folder";
  fs::create_directory(folder);
  for (const std::string& args : everyWriter(d, folder.string())) {
    // model-check keeps its own earlier message for a folder ("it is a folder").
    const bool model_check = args.rfind("model-check", 0) == 0;
    expectRefusal(args, d, folder, {folder.string(), model_check ? "it is a folder" : "it is a directory"});
    EXPECT_TRUE(fs::is_empty(folder));
  }
}

TEST(GyroctlOutputFiles, TheInputIsNeverTheOutputUnderAnyName) {
  ScratchDir d;
  const auto rec = d.write("rec.csv", noiseCsv(300, 2));
  const auto raw = d.write("raw.txt", imucal());
  ASSERT_EQ(::chmod(rec.c_str(), 0600), 0);
  const auto link = d.path() / "link.csv";
  fs::create_symlink(rec, link);
  const auto hard = d.path() / "hard.csv";
  fs::create_hard_link(rec, hard);
  for (const fs::path& out : {rec, link, hard}) {
    const std::string both = out.string() + ": refusing to write the output over the input " + rec.string();
    expectRefusal("filter " + rec.string() + " -o " + out.string(), d, out, {both});
    expectRefusal("analyze " + rec.string() + " --write-model " + out.string(), d, out, {both});
    expectRefusal("model-check " + rec.string() + " --replicas 8 --write-model " + out.string(), d, out, {both});
  }
  // The input named through the link, the output by its own name.
  expectRefusal("filter " + link.string() + " -o " + rec.string(), d, rec,
                {rec.string() + ": refusing to write the output over the input " + link.string()});
  expectRefusal("import " + raw.string() + " -o " + raw.string(), d, raw,
                {raw.string() + ": refusing to write the output over the input " + raw.string()});
  const auto model = d.write("m.toml", "rate_hz = 10\n");
  expectRefusal("simulate --model " + model.string() + " --duration 1 -o " + model.string(), d, model,
                {model.string() + ": refusing to write the output over the input " + model.string()});
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(fs::hard_link_count(rec), 2u);
}

TEST(GyroctlOutputFiles, SimulateNeverWritesOverItsMotionFile) {
  ScratchDir d;
  const auto motion = d.write("turns.csv", "t,wz\n0,0\n1,90\n2,0\n");
  expectRefusal("simulate --arw 0.5 --duration 2 --motion " + motion.string() + " -o " + motion.string(), d, motion,
                {motion.string() + ": refusing to write the output over the input " + motion.string()});
  // A profile written as text is no file, so it names no input.
  const auto out = d.path() / "sim.csv";
  const auto r =
      runGyroctl("simulate --arw 0.5 --duration 2 --motion step:axis=z,at=1,rate=10 -o " + out.string(), d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
}

TEST(GyroctlOutputFiles, ASymbolicLinkToARegularFileIsWrittenThrough) {
  ScratchDir d;
  const auto rec = d.write("rec.csv", noiseCsv(300, 3));
  const auto real = d.write("real.csv", "old\n");
  const auto link = d.path() / "link.csv";
  fs::create_symlink(real, link);
  const auto r = runGyroctl("filter " + rec.string() + " -o " + link.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(readWholeFile(real).rfind("t,gx,gx_mean,gx_kalman\n", 0), 0u);
  const auto dangling = d.path() / "dangling.csv";
  fs::create_symlink(d.path() / "nowhere.csv", dangling);
  expectRefusal("filter " + rec.string() + " -o " + dangling.string(), d, dangling,
                {dangling.string() + ": refusing to write: it is a symbolic link to nothing"});
  EXPECT_FALSE(fs::exists(d.path() / "nowhere.csv"));
}

TEST(GyroctlOutputFiles, AnExistingFileKeepsItsModeAndANewOneIs0644LessTheUmask) {
  ScratchDir d;
  const auto rec = d.write("rec.csv", noiseCsv(300, 4));
  const auto secret = d.write("secret.csv", "old\n");
  ASSERT_EQ(::chmod(secret.c_str(), 0600), 0);
  for (const std::string& args :
       {"filter " + rec.string() + " -o " + secret.string(), "simulate --arw 1 --duration 2 -o " + secret.string(),
        "analyze " + rec.string() + " --write-model " + secret.string()}) {
    const auto r = runGyroctl(args, d.path());
    ASSERT_EQ(r.exit_status, 0) << args << ": " << r.err;
    EXPECT_EQ(fs::status(secret).permissions(), fs::perms::owner_read | fs::perms::owner_write) << args;
  }
  for (const mode_t mask : {mode_t{022}, mode_t{077}}) {
    const mode_t previous = ::umask(mask);  // the child inherits it
    const auto fresh = d.path() / ("fresh-" + std::to_string(mask) + ".csv");
    const auto r = runGyroctl("simulate --arw 1 --duration 2 -o " + fresh.string(), d.path());
    ::umask(previous);
    ASSERT_EQ(r.exit_status, 0) << r.err;
    struct stat st {};
    ASSERT_EQ(::stat(fresh.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0644u & ~mask) << "umask " << mask;
  }
  EXPECT_EQ(tempFilesIn(d.path()), 0u);
}

// ---- a simulate killed while it writes ----------------------------------------------------

namespace {

pid_t spawnGyroctl(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv_text = binaryArgv("gyroctl");
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  // Default dispositions and no blocked signal, whatever the test runner ignores (a shell's
  // background job ignores SIGINT).
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t defaults, none;
  sigemptyset(&defaults);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&defaults, sig);
  sigemptyset(&none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  return rc == 0 ? pid : -1;
}

bool waitForTempFile(const fs::path& dir, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (tempFilesIn(dir) > 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

}  // namespace

TEST(GyroctlOutputFiles, ASignalDuringSimulateLeavesNoTemporaryFileAndNoPartialTarget) {
  ScratchDir d;
  struct statvfs vfs {};
  ASSERT_EQ(::statvfs(d.path().c_str(), &vfs), 0);
  const double free_bytes = static_cast<double>(vfs.f_bavail) * static_cast<double>(vfs.f_frsize);
  // Long enough to be still writing when killed, and well within the free space (the bound
  // counts 125 bytes a line): 20 000 s at 1 kHz, or less on a small disk.
  const double duration_s = std::min(20000.0, free_bytes / 4.0 / 125.0 / 1000.0);
  if (duration_s < 200.0) GTEST_SKIP() << "too little free space for a long simulate";
  for (const int sig : {SIGTERM, SIGINT}) {
    const auto out = d.write("out.csv", "precious\n");
    const FileState before = stateOf(out);
    const pid_t pid = spawnGyroctl(
        {"simulate", "--arw", "1", "--rate", "1000", "--duration", std::to_string(duration_s), "-o", out.string()},
        d.path() / "log.txt");
    ASSERT_GT(pid, 0);
    const bool started = waitForTempFile(d.path(), std::chrono::seconds(20));
    ::kill(pid, sig);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(started) << readWholeFile(d.path() / "log.txt");
    ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << status << ": " << readWholeFile(d.path() / "log.txt");
    EXPECT_EQ(WTERMSIG(status), sig);
    EXPECT_EQ(tempFilesIn(d.path()), 0u) << "signal " << sig;
    EXPECT_EQ(stateOf(out), before) << "signal " << sig;
  }
}

TEST(GyroctlOutputFiles, SimulateRefusesWhatCannotFit) {
  ScratchDir d;
  const auto out = d.path() / "big.csv";
  // Within the documented maximum duration, but 8e10 lines (up to 10 TB): more than the
  // test folder's filesystem has free.
  auto r = runGyroctl("simulate --arw 1 --rate 8000 --duration 1e7 -o " + out.string(), d.path());
  EXPECT_EQ(r.exit_status, 73) << r.err;  // EX_CANTCREAT: no room
  EXPECT_NE(
      r.err.find(out.string() + ": 80000000000 samples need up to 10 TB (125 bytes a line) but its filesystem has "),
      std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(" free"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(tempFilesIn(d.path()), 0u);
  // Beyond the maximum duration (the 1e9 of issue 16 and more).
  for (const char* duration : {"1e9", "1e12"}) {
    r = runGyroctl(std::string("simulate --arw 1 --duration ") + duration + " -o " + out.string(), d.path());
    EXPECT_EQ(r.exit_status, 64) << r.err;  // EX_USAGE
    EXPECT_NE(r.err.find("is longer than simulate writes (at most 1e+07 s)"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// ---- the small input messages -------------------------------------------------------------

TEST(GyroctlInputMessages, ADirectoryAsTheInputIsCalledADirectory) {
  ScratchDir d;
  const auto folder = d.path() / "in";
  fs::create_directory(folder);
  for (const std::string& cmd :
       {"analyze " + folder.string(), "filter " + folder.string() + " -o " + (d.path() / "o.csv").string(),
        "import " + folder.string() + " -o " + (d.path() / "o.csv").string(), "model-check " + folder.string()}) {
    const auto r = runGyroctl(cmd, d.path());
    EXPECT_EQ(r.exit_status, 66) << cmd;  // EX_NOINPUT
    EXPECT_NE(r.err.find(folder.string() + ": cannot read: it is a directory"), std::string::npos) << cmd << r.err;
    EXPECT_EQ(r.err.find("empty file"), std::string::npos) << cmd << r.err;
  }
}

TEST(GyroctlInputMessages, ImportOfAMissingFileSaysWhy) {
  ScratchDir d;
  const auto missing = (d.path() / "nope.txt").string();
  const auto r = runGyroctl("import " + missing + " -o " + (d.path() / "o.csv").string(), d.path());
  EXPECT_EQ(r.exit_status, 66);  // EX_NOINPUT
  EXPECT_NE(r.err.find(missing + ": cannot open: No such file or directory"), std::string::npos) << r.err;
}

TEST(GyroctlInputMessages, FilterNeedsEnoughSamplesToIdentifyTheFilter) {
  ScratchDir d;
  const auto few = d.write("few.csv", "t,gx\n0,1\n0.02,1.5\n0.04,1.25\n");
  const auto out = d.path() / "o.csv";
  auto r = runGyroctl("filter " + few.string() + " -o " + out.string(), d.path());
  EXPECT_EQ(r.exit_status, 65);  // EX_DATAERR
  EXPECT_NE(r.err.find(few.string() + ": 3 samples are too few to identify the filter (need at least 100"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));
  // One parameter given is not enough: the others are still identified.
  r = runGyroctl("filter " + few.string() + " -o " + out.string() + " --ar-phi 0.5", d.path());
  EXPECT_EQ(r.exit_status, 65);
  // All three given: nothing is identified, any length runs (as gyrod runs sample by sample).
  r = runGyroctl("filter " + few.string() + " -o " + out.string() + " --ar-phi 0.5 --kalman-q 1 --kalman-r 1",
                 d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  // 100 samples are enough.
  const auto enough = d.write("enough.csv", noiseCsv(100, 5));
  r = runGyroctl("filter " + enough.string() + " -o " + out.string(), d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
}

// The same refusal against a real small filesystem, where the test may mount one (root).
TEST(GyroctlOutputFiles, SimulateOnASmallFilesystem) {
  ScratchDir d;
  const auto tiny = d.path() / "tiny";
  fs::create_directories(tiny);
  if (::mount("tmpfs", tiny.c_str(), "tmpfs", 0, "size=64k") != 0) GTEST_SKIP() << "cannot mount a tmpfs here";
  const auto out = tiny / "sim.csv";
  // 100 s at 50 Hz: 5000 lines, up to 625 kB, on 64 KiB.
  auto r = runGyroctl("simulate --arw 1 --duration 100 -o " + out.string(), d.path());
  EXPECT_EQ(r.exit_status, 73) << r.err;  // EX_CANTCREAT
  EXPECT_NE(r.err.find(out.string() + ": 5000 samples need up to 625 kB (125 bytes a line) but its filesystem has "),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(tempFilesIn(tiny), 0u);
  // 2 s: 100 lines, up to 12.5 kB: written.
  r = runGyroctl("simulate --arw 1 --duration 2 -o " + out.string(), d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(out));
  ::umount2(tiny.c_str(), MNT_DETACH);
}
