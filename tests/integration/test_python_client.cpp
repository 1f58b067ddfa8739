// The Python client module (clients/python/gyrod_client.py) against the real gyrod on the mock:
// tests/python/check_gyrod_client.py does the checks, run by Debian's /usr/bin/python3 with the
// module's folder on PYTHONPATH, as installed it is on sys.path (-B: no __pycache__ in the source tree).
#include <gtest/gtest.h>

#include <sstream>

#include "gyrod_process.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using namespace std::chrono_literals;

namespace {

const std::filesystem::path kSourceDir = std::filesystem::path(GYROD_TEST_DATA_DIR).parent_path().parent_path();

std::string pythonMockConfig(const std::filesystem::path& dir) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[bias]\nsource = \"config\"\nvalues = [-3.34, 1.09, -0.5]\n"
    << "[socket]\npath = \"" << (dir / "gyrod.sock").string() << "\"\n"
    << "[mock]\nspeed = 10\nseed = 5\n";
  return c.str();
}

}  // namespace

TEST(PythonClient, WatchesStatusAndAllanAgainstGyrodOnTheMock) {
  const std::filesystem::path python = "/usr/bin/python3";
  if (!std::filesystem::exists(python)) GTEST_SKIP() << "no " << python;
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", pythonMockConfig(d.path()));
  const auto sock = (d.path() / "gyrod.sock").string();
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  {
    LineClient ready(sock);  // waits until gyrod listens
    ASSERT_TRUE(ready.connected()) << readWholeFile(d.path() / "log.txt");
  }
  const auto out = d.path() / "python.out";
  const std::string cmd = "PYTHONPATH='" + (kSourceDir / "clients/python").string() + "' " + python.string() +
                          " -B -s -X dev '" + (kSourceDir / "tests/python/check_gyrod_client.py").string() + "' '" +
                          sock + "' >'" + out.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  const std::string output = readWholeFile(out);
  ASSERT_TRUE(WIFEXITED(status)) << output;
  EXPECT_EQ(WEXITSTATUS(status), 0) << output << readWholeFile(d.path() / "log.txt");
  EXPECT_NE(output.find("ok"), std::string::npos) << output;
}
