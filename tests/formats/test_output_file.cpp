// formats/output_file: what sits at the target is refused unless it is a regular file (or a
// symbolic link to one), never the input, modes kept or 0644 less the umask, and the
// temporary file gone on every way out, signals included.
#include "formats/output_file.hpp"

#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using gyrod::formats::AtomicOutputFile;
using gyrod::formats::checkOutputTarget;
using gyrod::formats::OutputTargetError;
using gyrod::formats::writeFileAtomically;

namespace {

class OutputFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    dir_ = fs::temp_directory_path() / ("gyrod-output-" + std::to_string(rd()) + std::to_string(rd()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name), std::ios::binary) << text;
    return path(name);
  }
  // Every file of the folder whose name starts with `prefix`.
  std::size_t countStartingWith(const std::string& prefix) const {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir_))
      if (e.path().filename().string().rfind(prefix, 0) == 0) ++n;
    return n;
  }
  fs::path dir_;
};

std::string readAll(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

mode_t permissions(const std::string& p) {
  struct stat st {};
  EXPECT_EQ(::stat(p.c_str(), &st), 0) << p;
  return st.st_mode & 07777;
}

// Runs `body`, expecting an OutputTargetError whose message contains every part.
template <typename Body>
void expectRefused(Body body, std::initializer_list<std::string> parts) {
  try {
    body();
    ADD_FAILURE() << "not refused";
  } catch (const OutputTargetError& e) {
    for (const std::string& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << "missing '" << part << "' in: " << e.what();
  }
}

}  // namespace

TEST_F(OutputFileTest, CommitReplacesTheTargetAndLeavesNoTemporaryFile) {
  const auto out = write("out.csv", "old\n");
  writeFileAtomically(out, "new\n", {});
  EXPECT_EQ(readAll(out), "new\n");
  EXPECT_EQ(countStartingWith("out.csv.tmp-gyroctl"), 0u);
}

TEST_F(OutputFileTest, WithoutCommitTheTargetIsUntouchedAndTheTemporaryFileRemoved) {
  const auto out = write("out.csv", "precious\n");
  {
    AtomicOutputFile f(out, {});
    f.write("half a file");
    EXPECT_TRUE(fs::exists(f.tempPath()));
    EXPECT_EQ(f.tempPath(), out + ".tmp-gyroctl-" + std::to_string(::getpid()));
  }
  EXPECT_EQ(readAll(out), "precious\n");
  EXPECT_EQ(countStartingWith("out.csv.tmp-gyroctl"), 0u);
}

TEST_F(OutputFileTest, AnExistingFileKeepsItsMode) {
  const auto out = write("secret.csv", "old\n");
  ASSERT_EQ(::chmod(out.c_str(), 0600), 0);
  writeFileAtomically(out, "new\n", {});
  EXPECT_EQ(permissions(out), 0600u);
  ASSERT_EQ(::chmod(out.c_str(), 0640), 0);
  writeFileAtomically(out, "newer\n", {});
  EXPECT_EQ(permissions(out), 0640u);
}

TEST_F(OutputFileTest, ANewFileIs0644LessTheUmask) {
  for (const mode_t mask : {mode_t{022}, mode_t{077}, mode_t{002}, mode_t{0}}) {
    const mode_t previous = ::umask(mask);
    const auto out = path("new-" + std::to_string(mask) + ".csv");
    writeFileAtomically(out, "x\n", {});
    ::umask(previous);
    EXPECT_EQ(permissions(out), 0644u & ~mask) << "umask " << mask;
  }
}

TEST_F(OutputFileTest, NonRegularTargetsAreRefusedAndLeftAsTheyWere) {
  expectRefused([] { checkOutputTarget("/dev/null", {}); }, {"/dev/null", "a character device"});
  const auto fifo = path("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expectRefused([&] { AtomicOutputFile f(fifo, {}); }, {fifo, "a FIFO"});
  EXPECT_TRUE(fs::is_fifo(fifo));
  const auto folder = path("folder");
  fs::create_directory(folder);
  expectRefused([&] { writeFileAtomically(folder, "x", {}); }, {folder, "a directory"});
  EXPECT_TRUE(fs::is_directory(folder));
  EXPECT_TRUE(fs::is_empty(folder));
  EXPECT_EQ(countStartingWith("fifo.tmp"), 0u);
  EXPECT_EQ(countStartingWith("folder.tmp"), 0u);
}

TEST_F(OutputFileTest, SymbolicLinks) {
  // To a regular file: written through, the link stays a link.
  const auto real = write("real.csv", "old\n");
  const auto link = path("link.csv");
  fs::create_symlink(real, link);
  writeFileAtomically(link, "new\n", {});
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(readAll(real), "new\n");
  EXPECT_EQ(countStartingWith("real.csv.tmp"), 0u);
  EXPECT_EQ(countStartingWith("link.csv.tmp"), 0u);
  // To a FIFO, or to nothing: refused, the link unchanged.
  const auto fifo = path("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto to_fifo = path("to-fifo");
  fs::create_symlink(fifo, to_fifo);
  expectRefused([&] { checkOutputTarget(to_fifo, {}); }, {to_fifo, "a symbolic link to a FIFO"});
  const auto dangling = path("dangling");
  fs::create_symlink(path("nothing-here"), dangling);
  expectRefused([&] { checkOutputTarget(dangling, {}); }, {dangling, "a symbolic link to nothing"});
  EXPECT_TRUE(fs::is_symlink(dangling));
  EXPECT_FALSE(fs::exists(path("nothing-here")));
}

TEST_F(OutputFileTest, TheInputIsRefusedAsTheOutputUnderAnyName) {
  const auto in = write("in.csv", "t,gx\n0,1\n");
  ASSERT_EQ(::chmod(in.c_str(), 0600), 0);
  const auto link = path("link.csv");
  fs::create_symlink(in, link);
  const auto hard = path("hard.csv");
  fs::create_hard_link(in, hard);
  expectRefused([&] { writeFileAtomically(in, "x", {in}); }, {in, "over the input " + in});
  expectRefused([&] { writeFileAtomically(link, "x", {in}); }, {link, "over the input " + in});
  expectRefused([&] { writeFileAtomically(hard, "x", {in}); }, {hard, "over the input " + in});
  expectRefused([&] { writeFileAtomically(in, "x", {"/nonexistent", link}); }, {in, "over the input " + link});
  EXPECT_EQ(readAll(in), "t,gx\n0,1\n");
  EXPECT_EQ(permissions(in), 0600u);
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(fs::hard_link_count(in), 2u);
  EXPECT_EQ(countStartingWith("in.csv.tmp"), 0u);
}

TEST_F(OutputFileTest, AMissingFolderIsNamed) {
  const auto out = path("no-such-folder/out.csv");
  expectRefused([&] { checkOutputTarget(out, {}); }, {out, "no-such-folder"});
}

TEST_F(OutputFileTest, AvailableBytesIsTheFilesystemsFreeSpace) {
  AtomicOutputFile f(path("o.csv"), {});
  EXPECT_GT(f.availableBytes(), 0u);
}

// The handler removes the temporary file and the process still dies of the signal.
TEST_F(OutputFileTest, SigtermAndSigintRemoveTheTemporaryFile) {
  for (const int sig : {SIGTERM, SIGINT, SIGHUP}) {
    struct sigaction current {};
    ::sigaction(sig, nullptr, &current);
    if (current.sa_handler == SIG_IGN) continue;  // ignored (nohup): documented to stay ignored
    const auto out = write("out.csv", "precious\n");
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      AtomicOutputFile f(out, {});
      f.write("partial");
      std::fflush(f.stream());
      ::raise(sig);
      ::_exit(0);  // not reached: the signal's default action ends the process
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "signal " << sig << ", status " << status;
    EXPECT_EQ(WTERMSIG(status), sig);
    EXPECT_EQ(readAll(out), "precious\n");
    EXPECT_EQ(countStartingWith("out.csv.tmp-gyroctl"), 0u) << "signal " << sig;
  }
}

// ---- a full disk: a 64 KiB tmpfs where the test may mount one (root), skipped elsewhere ----

namespace {

class TinyFilesystem {
 public:
  explicit TinyFilesystem(const fs::path& dir) : dir_(dir) {
    fs::create_directories(dir_);
    mounted_ = ::mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=64k") == 0;
  }
  ~TinyFilesystem() {
    if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
  }
  TinyFilesystem(const TinyFilesystem&) = delete;
  TinyFilesystem& operator=(const TinyFilesystem&) = delete;
  bool mounted() const { return mounted_; }

 private:
  fs::path dir_;
  bool mounted_ = false;
};

}  // namespace

TEST_F(OutputFileTest, AFullDiskFailsTheCommitAndKeepsTheTarget) {
  TinyFilesystem tiny(dir_ / "tiny");
  if (!tiny.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here (not root)";
  const auto out = write("tiny/out.csv", "precious\n");
  {
    AtomicOutputFile f(out, {});
    EXPECT_LT(f.availableBytes(), 70000u);
    f.write(std::string(200000, 'x'));
    try {
      f.commit();
      ADD_FAILURE() << "200 kB committed on a 64 KiB filesystem";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(out + ": write failed: No space left on device (the target is unchanged)"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(readAll(out), "precious\n");
  std::size_t temps = 0;
  for (const auto& e : fs::directory_iterator(dir_ / "tiny"))
    if (e.path().filename().string().find(".tmp-gyroctl") != std::string::npos) ++temps;
  EXPECT_EQ(temps, 0u);
}
