// gyrod's start-up still period on the accelerated mock: a turn during it is detected,
// logged and shown in STATUS, and the bias comes from the next window at rest, not from the
// one the turn would have spoilt; a still_seconds too short for the rate exits 78 naming
// the file and line.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "gyrod_process.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

// The default mock model, turned about z at 10 °/s from 1 s to 3 s: inside the first 4 s
// still window. Its z bias is −0.5 °/s; the spoilt window's mean would be 4.5 °/s.
std::string turnAtStartConfig(const std::filesystem::path& dir) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[bias]\nsource = \"estimate\"\nstill_seconds = 4\n"
    << "[filter.kalman]\na = 0.9\nq = 0.0001\nr = 0.01\n"
    << "[socket]\npath = \"" << (dir / "gyrod.sock").string() << "\"\n"
    << "[mock]\nspeed = 20\nseed = 5\nmotion = \"constant:axis=z,rate=10,start=1,duration=2\"\n";
  return c.str();
}

json statusReply(const std::filesystem::path& socket) {
  LineClient asker(socket.string());
  if (!asker.connected() || !asker.readLine()) return {};
  asker.send("{\"cmd\":\"status\"}\n");
  const auto line = asker.readLine(5s);
  return line ? json::parse(*line) : json{};
}

}  // namespace

TEST(GyrodStillPeriod, ATurnDuringTheStillPeriodIsReportedAndNotAbsorbedIntoTheBias) {
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", turnAtStartConfig(d.path()));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  const auto socket = d.path() / "gyrod.sock";
  LineClient watcher(socket.string());
  ASSERT_TRUE(watcher.connected()) << readWholeFile(d.path() / "log.txt");
  ASSERT_TRUE(watcher.readLine());  // VERSION
  ASSERT_TRUE(watcher.send("{\"cmd\":\"watch\"}\n"));
  // Until the first rate: two windows of 4 s (the first discarded), then the stream.
  std::optional<json> first_rate;
  std::uint64_t rates = 0;
  while (!first_rate && rates < 1000) {
    const auto line = watcher.readLine(20s);
    ASSERT_TRUE(line.has_value()) << readWholeFile(d.path() / "log.txt");
    json j = json::parse(*line);
    if (j["class"] != "RATE") continue;
    ++rates;
    if (j.contains("rate")) first_rate = std::move(j);
  }
  ASSERT_TRUE(first_rate.has_value());
  EXPECT_GE((*first_rate)["seq"].get<std::uint64_t>(), 399u);  // not after the first window (seq 199)

  const json s = statusReply(socket);
  ASSERT_EQ(s["class"], "STATUS") << s.dump();
  EXPECT_EQ(s["still_check"], "still") << s.dump();
  EXPECT_NE(s["still_check_detail"].get<std::string>().find("window 2 of at most 3"), std::string::npos) << s.dump();
  // The bias is the second window's: the mock's z bias, not the turn's.
  const double bias_z = (*first_rate)["bias"][2].get<double>();
  EXPECT_NEAR(bias_z, -0.5, 0.1);

  gyrod.signal(SIGTERM);
  ASSERT_EQ(gyrod.waitExit(2000ms), std::optional<int>(0));
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find("start-up still period: the board moved (window 1 of at most 3: axis z"), std::string::npos)
      << log;
  EXPECT_NE(log.find("discarding it and estimating again over the next 4 s"), std::string::npos) << log;
  EXPECT_NE(log.find("start-up still period: at rest (window 2 of at most 3"), std::string::npos) << log;
}

TEST(GyrodStillPeriod, AStillPeriodTooShortForTheRateExits78NamingFileAndLine) {
  ScratchDir d;
  const auto cfg = d.write("s.toml", "[device]\nbackend = \"mock\"\n[bias]\nstill_seconds = 1\n");
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  EXPECT_EQ(gyrod.waitExit(5000ms), std::optional<int>(78));
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find(cfg.string() + ":4: key 'bias.still_seconds': must give at least 100 samples"), std::string::npos)
      << log;
}
