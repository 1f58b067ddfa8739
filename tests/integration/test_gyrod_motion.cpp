// gyrod on the accelerated mock turned by a [mock] motion: the RATE stream's raw values
// follow the true rate within the noise, the paper's kalman stream is still exactly the
// offline filter of the recording (its code and parameters untouched by the motion), and the
// recording holds what the chip measured, no truth columns.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <csignal>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "formats/recording_csv.hpp"
#include "gyrod_process.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

constexpr double kMotionStartS = 4.0;
constexpr double kMotionRateDps = 30.0;
constexpr std::array<double, 3> kBias = {-3.34, 1.09, -0.5};  // the default mock model's

// The default mock model turned about z at 30 °/s from t = 4 s; bias.values are its biases.
std::string motionConfig(const std::filesystem::path& dir) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[bias]\nsource = \"config\"\nvalues = [-3.34, 1.09, -0.5]\n"
    << "[filter]\nmean_window = 20\nmean_threshold_dps = 0.3\n"
    << "[filter.kalman]\na = 0.9\nq = 0.0001\nr = 0.01\n"
    << "[socket]\npath = \"" << (dir / "gyrod.sock").string() << "\"\n"
    << "[record]\npath = \"" << (dir / "rec.csv").string() << "\"\nflush_interval_s = 0.1\n"
    << "[mock]\nspeed = 50\nseed = 5\nmotion = \"constant:axis=z,rate=" << kMotionRateDps << ",start=" << kMotionStartS
    << "\"\n";
  return c.str();
}

struct Moments {
  double mean = 0.0, std = 0.0;
  std::size_t n = 0;
};
Moments momentsOf(const std::vector<double>& v) {
  Moments m;
  m.n = v.size();
  for (double x : v) m.mean += x / static_cast<double>(v.size());
  for (double x : v) m.std += (x - m.mean) * (x - m.mean) / static_cast<double>(v.size() - 1);
  m.std = std::sqrt(m.std);
  return m;
}

std::vector<std::array<double, 3>> offlineKalman(const std::string& rec_path, const ScratchDir& d) {
  const auto filtered = d.path() / "filtered.csv";
  const auto r = runGyroctl("filter " + rec_path + " -o " + filtered.string() +
                                " --bias=-3.34,1.09,-0.5 --mean-window 20 --mean-threshold 0.3"
                                " --ar-phi 0.9 --kalman-q 0.0001 --kalman-r 0.01",
                            d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  std::ifstream f(filtered);
  std::string line;
  std::getline(f, line);  // t,gx,gx_mean,gx_kalman,gy,...
  std::vector<std::array<double, 3>> kalman;
  while (std::getline(f, line)) {
    std::stringstream ls(line);
    std::string field;
    std::vector<double> v;
    while (std::getline(ls, field, ',')) v.push_back(std::stod(field));
    kalman.push_back({v[3], v[6], v[9]});
  }
  return kalman;
}

}  // namespace

TEST(GyrodMotion, RawFollowsTheMockMotionAndKalmanIsStillThePapersFilter) {
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", motionConfig(d.path()));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient watcher((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(watcher.connected()) << readWholeFile(d.path() / "log.txt");
  ASSERT_TRUE(watcher.readLine());  // VERSION
  ASSERT_TRUE(watcher.send("{\"cmd\":\"watch\"}\n"));
  std::vector<json> rates;
  while (rates.size() < 600) {  // 12 s of sensor time
    const auto line = watcher.readLine(20s);
    ASSERT_TRUE(line.has_value()) << readWholeFile(d.path() / "log.txt");
    json j = json::parse(*line);
    if (j["class"] == "RATE") rates.push_back(std::move(j));
  }
  gyrod.signal(SIGTERM);
  ASSERT_EQ(gyrod.waitExit(2000ms), std::optional<int>(0)) << readWholeFile(d.path() / "log.txt");

  // Still before the start, turning 1 s after it (the 20 Hz DLPF has settled by then); the
  // half second around the start is left out, the sample times being the driver's.
  std::array<std::vector<double>, 3> still, turning;
  for (const json& r : rates) {
    const double t = r["t"].get<double>();
    for (int a = 0; a < 3; ++a) {
      if (t > 0.5 && t < kMotionStartS - 0.5) still[a].push_back(r["raw"][a].get<double>());
      if (t > kMotionStartS + 1.0) turning[a].push_back(r["raw"][a].get<double>());
    }
  }
  // raw is the chip's reading, bias included: the still part is the reference, as a start-up
  // bias estimate would take it.
  for (int a = 0; a < 3; ++a) {
    const Moments before = momentsOf(still[a]), during = momentsOf(turning[a]);
    ASSERT_GE(before.n, 100u);
    ASSERT_GE(during.n, 200u);
    EXPECT_NEAR(before.mean, kBias[a], 0.1) << "axis " << a;
    EXPECT_LT(before.std, 0.5) << "axis " << a;
    // White noise of the still part's spread, both means averaged: 5 σ·√(1/n1 + 1/n2), plus
    // one quantum (1/131 °/s).
    const double tolerance =
        5.0 * before.std * std::sqrt(1.0 / static_cast<double>(before.n) + 1.0 / static_cast<double>(during.n)) +
        1.0 / 131.0;
    const double truth = a == 2 ? kMotionRateDps : 0.0;
    EXPECT_NEAR(during.mean - before.mean, truth, tolerance) << "axis " << a;
  }

  // The recording: what the chip measured (no truth columns), and the kalman stream is the
  // offline paper filter of it, sample for sample.
  std::string rec_path;
  for (const auto& e : std::filesystem::directory_iterator(d.path()))
    if (e.path().filename().string().rfind("rec-", 0) == 0) rec_path = e.path().string();
  ASSERT_FALSE(rec_path.empty());
  std::ifstream rec_file(rec_path);
  std::string header;
  while (std::getline(rec_file, header) && (header.empty() || header.front() == '#')) {}
  EXPECT_EQ(header.find("wx"), std::string::npos) << header;
  const auto kalman = offlineKalman(rec_path, d);
  for (const json& r : rates) {
    const auto seq = r["seq"].get<std::size_t>();
    ASSERT_LT(seq, kalman.size());
    for (int a = 0; a < 3; ++a) ASSERT_EQ(r["kalman"][a].get<double>(), kalman[seq][a]) << "seq " << seq;
  }
}

TEST(GyrodMotion, BadMotionSpecExitsWithExConfigNamingFileLineAndKey) {
  ScratchDir d;
  const auto cfg =
      d.write("gyrod.toml", "[device]\nbackend = \"mock\"\n[mock]\nmotion = \"sine:axis=x,freq=1,ampl=20\"\n");
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  EXPECT_EQ(gyrod.waitExit(5000ms), std::optional<int>(78));
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find(cfg.string() + ":4"), std::string::npos) << log;
  EXPECT_NE(log.find("mock.motion"), std::string::npos) << log;
  EXPECT_NE(log.find("unknown key 'ampl'"), std::string::npos) << log;
}

// [mock] warm_up and temperature_coefficient_dps_per_c: the die warms up (+20 °C, τ = 4 s of
// sensor time, so that 12 s show it) and x's bias follows at 0.1 °/s per °C, the others stay.
TEST(GyrodMotion, MockWarmUpMovesTheBiasWithTheTemperature) {
  ScratchDir d;
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[bias]\nsource = \"config\"\nvalues = [-3.34, 1.09, -0.5]\n"
    << "[filter.kalman]\na = 0.9\nq = 0.0001\nr = 0.01\n"
    << "[socket]\npath = \"" << (d.path() / "gyrod.sock").string() << "\"\n"
    << "[mock]\nspeed = 50\nseed = 6\nwarm_up = \"20,4\"\ntemperature_coefficient_dps_per_c = [0.1, 0.0, 0.0]\n";
  const auto cfg = d.write("gyrod.toml", c.str());
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient watcher((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(watcher.connected()) << readWholeFile(d.path() / "log.txt");
  ASSERT_TRUE(watcher.readLine());  // VERSION
  ASSERT_TRUE(watcher.send("{\"cmd\":\"watch\"}\n"));
  std::vector<json> rates;
  while (rates.size() < 600) {  // 12 s of sensor time
    const auto line = watcher.readLine(20s);
    ASSERT_TRUE(line.has_value()) << readWholeFile(d.path() / "log.txt");
    json j = json::parse(*line);
    if (j["class"] == "RATE") rates.push_back(std::move(j));
  }
  gyrod.signal(SIGTERM);
  ASSERT_EQ(gyrod.waitExit(2000ms), std::optional<int>(0)) << readWholeFile(d.path() / "log.txt");
  std::array<std::vector<double>, 3> early, late;
  std::vector<double> early_temp, late_temp;
  // The first second watched and the last three (the watch starts a little after gyrod).
  for (std::size_t i = 0; i < rates.size(); ++i) {
    const bool is_early = i < 50, is_late = i >= rates.size() - 150;
    if (!is_early && !is_late) continue;
    (is_early ? early_temp : late_temp).push_back(rates[i]["temp"].get<double>());
    for (int a = 0; a < 3; ++a) (is_early ? early : late)[a].push_back(rates[i]["raw"][a].get<double>());
  }
  const double warmed = momentsOf(late_temp).mean - momentsOf(early_temp).mean;
  EXPECT_GT(warmed, 5.0);  // 28 °C + 20·(1 − e^{−t/4 s}) rises by 8–14 °C between the two windows
  for (int a = 0; a < 3; ++a) {
    const Moments e = momentsOf(early[a]), l = momentsOf(late[a]);
    ASSERT_GE(e.n, 20u);
    const double tolerance =
        5.0 * e.std * std::sqrt(1.0 / static_cast<double>(e.n) + 1.0 / static_cast<double>(l.n)) + 1.0 / 131.0;
    EXPECT_NEAR(l.mean - e.mean, a == 0 ? 0.1 * warmed : 0.0, tolerance) << "axis " << a;
  }
}
