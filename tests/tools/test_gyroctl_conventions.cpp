// gyroctl's command-line conventions (README "gyroctl"): --version prints the project version
// CMake was given, an unknown command is named with the nearest one, help says "gyroctl".
#include <gtest/gtest.h>

#include <algorithm>
#include <regex>

#include "binary_command.hpp"
#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

const std::filesystem::path kSourceDir = std::filesystem::path(GYROD_TEST_DATA_DIR).parent_path().parent_path();

// The VERSION of the top-level CMakeLists.txt's project() call.
std::string cmakeProjectVersion() {
  const std::string text = readWholeFile(kSourceDir / "CMakeLists.txt");
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(R"(project\(gyrod VERSION ([0-9.]+))"))) return "";
  return m[1];
}

void expectOneLine(const std::string& text) { EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text; }

}  // namespace

TEST(GyroctlConventions, VersionPrintsTheProjectVersion) {
  ScratchDir d;
  const std::string version = cmakeProjectVersion();
  ASSERT_FALSE(version.empty());
  const auto r = runGyroctl("--version", d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(r.out, "gyroctl " + version + "\n");
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(GyroctlConventions, GyrodVersionPrintsTheSameVersion) {
  const auto gyrod = std::filesystem::path(GYROD_BIN_DIR) / "gyrod";
  if (!std::filesystem::exists(gyrod)) GTEST_SKIP() << "gyrod is not built";
  ScratchDir d;
  const auto out = d.path() / "out.txt";
  // Through the cross build's emulator when there is one (binfmt_misc is not assumed).
  const std::string command = gyrod::test::binaryShellCommand("gyrod");
  const int status = std::system((command + " --version >" + out.string() + " 2>&1 </dev/null").c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_EQ(readWholeFile(out), "gyrod " + cmakeProjectVersion() + "\n");
}

TEST(GyroctlConventions, AnUnknownCommandIsNamedWithTheNearestOne) {
  ScratchDir d;
  for (const auto& [typed, meant] : std::vector<std::pair<std::string, std::string>>{{"anlyze", "analyze"},
                                                                                     {"stauts", "status"},
                                                                                     {"wacth", "watch"},
                                                                                     {"model-chek", "model-check"},
                                                                                     {"simulat", "simulate"},
                                                                                     {"Filter", "filter"}}) {
    const auto r = runGyroctl(typed + " x.csv", d.path());
    EXPECT_EQ(r.exit_status, 64) << typed;  // EX_USAGE
    EXPECT_NE(r.err.find("gyroctl: unknown command '" + typed + "'; did you mean '" + meant + "'?"), std::string::npos)
        << r.err;
    expectOneLine(r.err);
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST(GyroctlConventions, AWordFarFromEveryCommandGetsNoSuggestionButTheList) {
  ScratchDir d;
  const auto r = runGyroctl("--json frobnicate", d.path());
  EXPECT_EQ(r.exit_status, 64);
  EXPECT_EQ(
      r.err,
      "gyroctl: unknown command 'frobnicate' (commands: analyze, filter, attitude, import, simulate, watch, allan, "
      "status, effects, model-check, live-check, model, fleet)\n");
}

TEST(GyroctlConventions, AKnownCommandStillParsesItsOwnOptions) {
  ScratchDir d;
  // "watch" is found although an option comes first in the subcommand's arguments.
  const auto r = runGyroctl("watch --decimate 0", d.path());
  EXPECT_EQ(r.exit_status, 64) << r.err;
  EXPECT_EQ(r.err.find("unknown command"), std::string::npos) << r.err;
  const auto missing = runGyroctl("", d.path());
  EXPECT_EQ(missing.exit_status, 64);
  EXPECT_NE(missing.err.find("subcommand"), std::string::npos) << missing.err;
}

TEST(GyroctlConventions, HelpShowsTheProgramNameNotItsPath) {
  ScratchDir d;
  for (const std::string args : {"--help", "analyze --help", "watch --help"}) {
    const auto r = runGyroctl(args, d.path());
    EXPECT_EQ(r.exit_status, 0) << args;
    EXPECT_EQ(r.out.find(GYROD_BIN_DIR), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Usage: gyroctl"), std::string::npos) << r.out;
  }
  const auto sub = runGyroctl("analyze --help", d.path());
  EXPECT_NE(sub.out.find("gyroctl analyze"), std::string::npos) << sub.out;
  EXPECT_NE(runGyroctl("--help", d.path()).out.find("--version"), std::string::npos);
}

// One exit-code scheme (sysexits, as gyrod's), README "Exit statuses" and gyroctl(1): each
// kind of failure has its own status, so a script can tell them apart.
TEST(GyroctlConventions, ExitStatusesFollowSysexits) {
  ScratchDir d;
  std::string rows = "t,gx\n";
  for (int i = 0; i < 200; ++i) rows += std::to_string(i * 0.02) + "," + std::to_string((i * 7919) % 13 * 0.01) + "\n";
  const auto good = d.write("good.csv", rows);
  const auto bad = d.write("bad.csv", "t,gx\n0,1\n0.02,oops\n");
  const auto gappy = d.write("gappy.csv", rows + "10,0.1\n10.02,0.2\n");
  struct Case {
    std::string args;
    int status;
  };
  const std::vector<Case> cases = {
      {"analyze " + good.string() + " --taus 0", 64},                // EX_USAGE: bad option value
      {"analyze " + good.string() + " --no-such-option", 64},        // EX_USAGE
      {"analyze " + bad.string(), 65},                               // EX_DATAERR: malformed input
      {"analyze " + gappy.string() + " --strict-timing", 65},        // EX_DATAERR: --strict-timing
      {"analyze " + (d.path() / "none.csv").string(), 66},           // EX_NOINPUT
      {"analyze " + d.path().string(), 66},                          // EX_NOINPUT: a directory
      {"filter " + good.string() + " -o " + d.path().string(), 73},  // EX_CANTCREAT: a directory
      {"status --socket " + (d.path() / "none.sock").string(), 69},  // EX_UNAVAILABLE
  };
  for (const Case& c : cases) {
    const auto r = runGyroctl(c.args, d.path());
    EXPECT_EQ(r.exit_status, c.status) << c.args << "\n" << r.err;
    expectOneLine(r.err);
  }
}
