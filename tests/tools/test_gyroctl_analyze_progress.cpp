// gyroctl analyze shows its progress on stderr for inputs of more than 2^20 lines when stderr
// is a terminal (issue 15), and writes nothing there for a log or a pipe. The terminal is the
// pseudo-terminal of util-linux `script` (bsdutils, essential in Debian); without it the
// terminal half is skipped.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "run_command.hpp"

namespace {

using gyrod::test::ScratchDir;

// t,gx over 1.1·2^20 lines at 50 Hz: white noise from a seeded generator, six decimals.
std::filesystem::path writeLongRecording(const ScratchDir& dir) {
  const auto path = dir.path() / "long.csv";
  std::ofstream out(path, std::ios::binary);
  out << "t,gx\n";
  std::uint64_t state = 15;
  char line[64];
  const std::size_t lines = (std::size_t{1} << 20) + (std::size_t{1} << 17);
  for (std::size_t i = 0; i < lines; ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const double noise = (static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5) * 0.2;
    std::snprintf(line, sizeof line, "%.2f,%.6f\n", 0.02 * static_cast<double>(i), noise);
    out << line;
  }
  return path;
}

bool haveScript() { return std::system("command -v script >/dev/null 2>&1") == 0; }

TEST(GyroctlAnalyzeProgress, ShownOnATerminalOnly) {
  if (gyrod::test::underEmulator()) GTEST_SKIP() << "a pseudo-terminal under qemu-user is not what is tested here";
  ScratchDir dir;
  const auto file = writeLongRecording(dir);

  // Not a terminal: stderr stays empty, stdout has the analysis.
  const auto plain = gyrod::test::runGyroctl("analyze '" + file.string() + "' --axis gx --json", dir.path());
  ASSERT_EQ(plain.exit_status, 0) << plain.err;
  EXPECT_EQ(plain.err, "");
  EXPECT_NE(plain.out.find("\"allan_after_kalman\""), std::string::npos);

  if (!haveScript()) GTEST_SKIP() << "util-linux script is missing: the terminal half is not checked";
  const auto typescript = dir.path() / "terminal.txt";
  const std::string inner = gyrod::test::binaryShellCommand("gyroctl") + " analyze '" + file.string() +
                            "' --axis gx --json >'" + (dir.path() / "out.json").string() + "'";
  const std::string command = "script -q -e -c \"" + inner + "\" /dev/null >'" + typescript.string() + "' </dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const std::string terminal = gyrod::test::readWholeFile(typescript);
  EXPECT_NE(terminal.find("reading " + file.string() + ": "), std::string::npos) << terminal;
  EXPECT_NE(terminal.find("(1.0 M lines)"), std::string::npos) << terminal;
  EXPECT_NE(terminal.find("analysing gx (1 of 1)..."), std::string::npos) << terminal;
  // The progress line is cleared at the end, and the output is the same as without a terminal.
  EXPECT_NE(terminal.rfind("\r\033[K"), std::string::npos) << terminal;
  EXPECT_EQ(gyrod::test::readWholeFile(dir.path() / "out.json"), plain.out);
}

}  // namespace
