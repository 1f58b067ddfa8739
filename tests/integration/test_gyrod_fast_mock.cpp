// The mock at the chip's fast rates, sped up: its virtual clock advances in steps the FIFO
// holds (daemon/gyrod.cpp, maxVirtualStepNs), so it streams at every documented rate and speed.
#include <gtest/gtest.h>

#include <chrono>
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

std::string fastMockConfig(const std::filesystem::path& dir, int rate_hz, double speed) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = " << rate_hz << "\ndlpf = 1\naccel = true\n"
    << "[bias]\nsource = \"config\"\nvalues = [0, 0, 0]\n"
    << "[socket]\npath = \"" << (dir / "gyrod.sock").string() << "\"\n"
    << "[mock]\nspeed = " << speed << "\nseed = 3\n";
  return c.str();
}

}  // namespace

TEST(GyrodFastMock, StreamsAtAKilohertzAtEverySpeedFromOneToTen) {
  struct Case {
    int rate_hz;
    double speed;
  };
  std::vector<Case> cases;
  for (int speed = 1; speed <= 10; ++speed) cases.push_back({1000, static_cast<double>(speed)});
  cases.push_back({500, 10});
  for (const Case& k : cases) {
    ScratchDir d;
    const auto cfg = d.write("gyrod.toml", fastMockConfig(d.path(), k.rate_hz, k.speed));
    const auto log_path = d.path() / "log.txt";
    GyrodProcess gyrod({"--config", cfg.string()}, log_path);
    LineClient w((d.path() / "gyrod.sock").string());
    ASSERT_TRUE(w.connected()) << readWholeFile(log_path);
    ASSERT_TRUE(w.readLine());  // VERSION
    ASSERT_TRUE(w.send("{\"cmd\":\"watch\"}\n"));
    std::size_t rates = 0, gaps = 0;
    std::uint64_t last_seq = 0;
    while (rates < 3000) {
      const auto line = w.readLine(20s);
      ASSERT_TRUE(line.has_value()) << k.rate_hz << " Hz x" << k.speed << ": the stream stopped after " << rates
                                    << " lines; log:\n"
                                    << readWholeFile(log_path);
      const json j = json::parse(*line);
      if (j["class"] == "GAP") ++gaps;
      if (j["class"] != "RATE") continue;
      const auto seq = j["seq"].get<std::uint64_t>();
      if (rates > 0) {
        EXPECT_EQ(seq, last_seq + 1) << k.rate_hz << " Hz x" << k.speed;
      }
      last_seq = seq;
      ++rates;
    }
    EXPECT_EQ(gaps, 0u) << k.rate_hz << " Hz x" << k.speed;
    const std::string log = readWholeFile(log_path);
    EXPECT_EQ(log.find("FIFO overflow"), std::string::npos) << k.rate_hz << " Hz x" << k.speed << ":\n" << log;
    gyrod.signal(SIGTERM);
    EXPECT_EQ(gyrod.waitExit(2000ms), std::optional<int>(0));
  }
}
