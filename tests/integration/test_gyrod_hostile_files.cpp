// Files that are not regular files, named where gyrod and gyroctl read one: the configuration,
// filter.model, mock.motion, mock.replay_file, and gyroctl's model, motion and recording.
// /dev/zero and /dev/urandom never end, a FIFO blocks open() until a writer comes, a directory
// and /proc/self/mem read as empty files. Each is refused at once with one line naming the
// path and what it is, without the memory growing; at SIGHUP gyrod keeps streaming.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <chrono>
#include <csignal>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "gyrod_process.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

// The largest resident size of any child waited for so far, in MB.
double largestChildRssMb() {
  rusage usage{};
  ::getrusage(RUSAGE_CHILDREN, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB
}

double processRssMb(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return -1.0;
}

struct HostilePath {
  std::string path;
  std::string what;  // as the refusal names it
};

// The five kinds of path, the FIFO and the directory made in `dir`.
std::vector<HostilePath> hostilePaths(const ScratchDir& dir) {
  const auto fifo = dir.path() / "fifo";
  ::mkfifo(fifo.c_str(), 0600);
  const auto folder = dir.path() / "folder";
  std::filesystem::create_directories(folder);
  return {{"/dev/zero", "a character device"},
          {"/dev/urandom", "a character device"},
          {fifo.string(), "a FIFO"},
          {folder.string(), "a directory"},
          {"/proc/self/mem", "a file of /proc"}};
}

std::string hostileMockConfig(const std::filesystem::path& dir, const std::string& extra_filter,
                              const std::string& extra_mock) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[bias]\nsource = \"config\"\nvalues = [0, 0, 0]\n"
    << "[filter]\nmean_window = 20\n"
    << extra_filter << "[socket]\npath = \"" << (dir / "gyrod.sock").string() << "\"\n"
    << "[mock]\nspeed = 20\nseed = 5\n"
    << extra_mock;
  return c.str();
}

std::size_t refusalLineCount(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

}  // namespace

// At start-up: as --config, filter.model, mock.motion and mock.replay_file, each path makes
// gyrod exit 78 within a second with one line naming it and what it is.
TEST(GyrodHostileFiles, EveryReaderRefusesAFileThatIsNotRegularAtStart) {
  ScratchDir d;
  const std::vector<HostilePath> paths = hostilePaths(d);
  int run = 0;
  for (const HostilePath& p : paths) {
    const std::string quoted = "\"" + p.path + "\"";
    const std::vector<std::pair<std::string, std::string>> roles = {
        {"--config", ""},
        {"filter.model", hostileMockConfig(d.path(), "model = " + quoted + "\n", "")},
        {"mock.motion", hostileMockConfig(d.path(), "", "motion = " + quoted + "\n")},
        {"mock.replay_file", hostileMockConfig(d.path(), "", "source = \"replay\"\nreplay_file = " + quoted + "\n")}};
    for (const auto& [role, text] : roles) {
      const std::string config = role == "--config" ? p.path : d.write("c.toml", text).string();
      const auto log = d.path() / ("log-" + std::to_string(run++) + ".txt");
      const auto started = std::chrono::steady_clock::now();
      GyrodProcess gyrod({"--config", config, "--backend", "mock"}, log);
      const auto status = gyrod.waitExit(5000ms);
      const auto took = std::chrono::steady_clock::now() - started;
      const std::string out = readWholeFile(log);
      ASSERT_EQ(status, std::optional<int>(78)) << p.path << " as " << role << ": " << out;
      EXPECT_LT(took, 1000ms) << p.path << " as " << role;
      EXPECT_EQ(refusalLineCount(out), 1u) << p.path << " as " << role << ": " << out;
      EXPECT_NE(out.find(p.path + ": cannot read: it is " + p.what), std::string::npos)
          << p.path << " as " << role << ": " << out;
      if (role != "--config") {
        EXPECT_NE(out.find(role), std::string::npos) << out;
      }
    }
  }
  EXPECT_LT(largestChildRssMb(), 100.0);
}

// At SIGHUP: filter.model (read at reload) and the mock's files (checked at reload) become
// each path in turn; every reload is refused with one error line naming it, the stream goes
// on without a missing sequence number, and gyrod's memory stays small.
TEST(GyrodHostileFiles, ASighupToAFileThatIsNotRegularKeepsStreaming) {
  ScratchDir d;
  const std::vector<HostilePath> paths = hostilePaths(d);
  const auto cfg = d.write("gyrod.toml", hostileMockConfig(d.path(), "", ""));
  const auto log_path = d.path() / "log.txt";
  GyrodProcess gyrod({"--config", cfg.string()}, log_path);
  LineClient w((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(w.connected()) << readWholeFile(log_path);
  ASSERT_TRUE(w.readLine());  // VERSION
  ASSERT_TRUE(w.send("{\"cmd\":\"watch\"}\n"));
  std::optional<std::uint64_t> last_seq;
  // Reads `count` RATE lines, each the successor of the one before.
  const auto readOn = [&](std::size_t count) {
    for (std::size_t n = 0; n < count;) {
      const auto line = w.readLine(10s);
      ASSERT_TRUE(line.has_value()) << "the stream stopped; log:\n" << readWholeFile(log_path);
      const json j = json::parse(*line);
      ASSERT_NE(j["class"], "GAP") << *line;
      if (j["class"] != "RATE") continue;
      const auto seq = j["seq"].get<std::uint64_t>();
      if (last_seq) {
        ASSERT_EQ(seq, *last_seq + 1);
      }
      last_seq = seq;
      ++n;
    }
  };
  readOn(50);
  if (HasFatalFailure()) return;
  EXPECT_NE(readWholeFile(log_path).find("configuration: loaded from " + cfg.string()), std::string::npos);
  std::size_t refusals = 0;
  for (const HostilePath& p : paths) {
    const std::string quoted = "\"" + p.path + "\"";
    for (const auto& text : {hostileMockConfig(d.path(), "model = " + quoted + "\n", ""),
                             hostileMockConfig(d.path(), "", "motion = " + quoted + "\n"),
                             hostileMockConfig(d.path(), "", "source = \"replay\"\nreplay_file = " + quoted + "\n")}) {
      d.write("gyrod.toml", text);
      gyrod.signal(SIGHUP);
      const auto sent = std::chrono::steady_clock::now();
      ++refusals;
      std::string log;
      while (std::chrono::steady_clock::now() - sent < 5s) {
        log = readWholeFile(log_path);
        std::size_t found = 0;
        for (auto at = log.find("SIGHUP: keeping the running filter: "); at != std::string::npos;
             at = log.find("SIGHUP: keeping the running filter: ", at + 1))
          ++found;
        if (found >= refusals) break;
        std::this_thread::sleep_for(5ms);
      }
      EXPECT_LT(std::chrono::steady_clock::now() - sent, 1000ms) << p.path;
      const auto at = log.rfind("SIGHUP: keeping the running filter: ");
      ASSERT_NE(at, std::string::npos) << log;
      const std::string line = log.substr(at, log.find('\n', at) - at);
      EXPECT_NE(line.find(p.path + ": cannot read: it is " + p.what), std::string::npos) << line;
      readOn(20);
      if (HasFatalFailure()) return;
    }
  }
  EXPECT_EQ(readWholeFile(log_path).find("filter reloaded"), std::string::npos);
  EXPECT_LT(processRssMb(gyrod.pid()), 100.0);
  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(2000ms), std::optional<int>(0));
}

// gyroctl: simulate --model, simulate --motion, filter --model and analyze refuse each path
// at once, with one line and EX_NOINPUT (66).
TEST(GyrodHostileFiles, GyroctlRefusesAFileThatIsNotRegular) {
  ScratchDir d;
  const std::vector<HostilePath> paths = hostilePaths(d);
  const auto rec = d.write("rec.csv", "t,gx,gy,gz\n0,0,0,0\n0.02,0.1,0,0\n0.04,0,0.1,0\n0.06,0,0,0.1\n");
  for (const HostilePath& p : paths) {
    for (const std::string& args :
         {"simulate --model " + p.path + " --duration 1 -o " + (d.path() / "sim.csv").string(),
          "simulate --motion " + p.path + " --duration 1 -o " + (d.path() / "sim.csv").string(),
          "filter " + rec.string() + " --model " + p.path + " -o " + (d.path() / "f.csv").string(),
          "analyze " + p.path}) {
      const auto started = std::chrono::steady_clock::now();
      const CommandResult r = runGyroctl(args, d.path());
      EXPECT_LT(std::chrono::steady_clock::now() - started, 1000ms) << args;
      EXPECT_EQ(r.exit_status, 66) << args << ": " << r.err;
      EXPECT_EQ(refusalLineCount(r.err), 1u) << args << ": " << r.err;
      EXPECT_NE(r.err.find(p.path + ": cannot read: it is " + p.what), std::string::npos) << args << ": " << r.err;
    }
  }
  EXPECT_LT(largestChildRssMb(), 100.0);
}
