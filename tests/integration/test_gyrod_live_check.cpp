// gyrod runs the live check on its still samples (docs/live-check.md): on the accelerated mock
// at rest with a sensor model (the still detector), a 12.5 Hz vibration that starts after the
// baseline (a sine "motion" of 0.02 °/s on y, far inside what the still detector calls still)
// reaches a watching client as an EFFECT line whatever its decimation, is in STATUS's
// live_check and in the journal; without filter.model the check is off and says why.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "gyrod_process.hpp"
#include "live_sensor_model.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

constexpr double kLiveOnsetS = 300.0;  // after the baseline (two 60 s intervals) and a few more

std::string liveConfig(const ScratchDir& d, const std::string& model_line) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << model_line << "[socket]\npath = \"" << (d.path() / "gyrod.sock").string() << "\"\n"
    << "[check]\ninterval_s = 60\nbaseline_s = 120\n"
    << "[mock]\nspeed = 100\nseed = 4\nmotion = \"sine:axis=y,freq=12.5,amp=0.02,start=" << kLiveOnsetS << "\"\n";
  return c.str();
}

}  // namespace

TEST(GyrodLiveCheck, AVibrationThatStartsReachesWatchersStatusAndTheJournal) {
  ScratchDir d;
  const auto model = d.write("model.toml", liveCheckSensorModel());
  const auto cfg = d.write("gyrod.toml", liveConfig(d, "[filter]\nmodel = \"" + model.string() + "\"\n"));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient watcher((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(watcher.connected()) << readWholeFile(d.path() / "log.txt");
  ASSERT_TRUE(watcher.readLine());  // VERSION
  // Every 1000th sample (one RATE line per 20 s of data): the EFFECT line comes all the same.
  ASSERT_TRUE(watcher.send("{\"cmd\":\"watch\",\"decimate\":1000}\n"));
  double mock_start = std::nan("");
  json effect;
  const auto until = std::chrono::steady_clock::now() + 60s;
  while (std::chrono::steady_clock::now() < until && effect.is_null()) {
    const auto line = watcher.readLine(20s);
    ASSERT_TRUE(line.has_value()) << readWholeFile(d.path() / "log.txt");
    const json j = json::parse(*line);
    if (j["class"] == "RATE" && std::isnan(mock_start))
      mock_start = j["t"].get<double>() - j["seq"].get<double>() / 50.0;
    if (j["class"] == "EFFECT") effect = j;
  }
  ASSERT_FALSE(effect.is_null()) << readWholeFile(d.path() / "log.txt");
  EXPECT_EQ(effect["state"], "new") << effect;
  EXPECT_EQ(effect["effect"], "line") << effect;
  EXPECT_EQ(effect["axis"], "y") << effect;
  EXPECT_NEAR(effect["params"]["centre_hz"].get<double>(), 12.5, 0.125) << effect;
  ASSERT_FALSE(std::isnan(mock_start));
  // Named after the vibration's start, on the clock of RATE's t, within five intervals (the
  // still detector's flicker leaves an interval out now and then), its onset's interval holding
  // the start.
  const double named_at = effect["t"].get<double>() - mock_start;
  std::cout << "12.5 Hz from " << kLiveOnsetS << " s of data: named at " << named_at << " s, onset "
            << effect["onset_t"].get<double>() - mock_start << " s ("
            << effect["onset_t_95"][0].get<double>() - mock_start << "-"
            << effect["onset_t_95"][1].get<double>() - mock_start << ")\n";
  EXPECT_GT(named_at, kLiveOnsetS) << effect;
  EXPECT_LE(named_at, kLiveOnsetS + 300.0 + 1.0) << effect;
  EXPECT_LE(effect["onset_t_95"][0].get<double>() - mock_start, kLiveOnsetS + 1.0) << effect;
  EXPECT_GE(effect["onset_t_95"][1].get<double>() - mock_start, kLiveOnsetS - 1.0) << effect;

  LineClient asker((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(asker.readLine());  // VERSION
  ASSERT_TRUE(asker.send("{\"cmd\":\"status\"}\n"));
  const auto status = asker.readLine(10s);
  ASSERT_TRUE(status.has_value());
  const json s = json::parse(*status);
  ASSERT_TRUE(s.contains("live_check")) << *status;
  EXPECT_TRUE(s["live_check"]["baseline_ready"].get<bool>()) << *status;
  EXPECT_GE(s["live_check"]["intervals"].get<int>(), 3) << *status;
  EXPECT_GE(s["live_check"]["named"].get<int>(), 1) << *status;
  ASSERT_GE(s["live_check"]["current"].size(), 1u) << *status;
  EXPECT_EQ(s["live_check"]["current"][0]["axis"], "y") << *status;
  const CommandResult shown = runGyroctl("status --socket " + (d.path() / "gyrod.sock").string(), d.path());
  EXPECT_EQ(shown.exit_status, 0) << shown.err;
  EXPECT_NE(shown.out.find("baseline ready"), std::string::npos) << shown.out;
  EXPECT_NE(shown.out.find("now: line on y at 12.5"), std::string::npos) << shown.out;

  gyrod.signal(SIGTERM);
  ASSERT_EQ(gyrod.waitExit(5000ms), std::optional<int>(0)) << readWholeFile(d.path() / "log.txt");
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find("live check: every 60 s of still data at 50 Hz against a baseline of the first 120 s"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("live check: new line on y: 12.5"), std::string::npos) << log;
}

TEST(GyrodLiveCheck, WithoutASensorModelItIsOffAndSaysWhy) {
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", liveConfig(d, ""));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient asker((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(asker.connected()) << readWholeFile(d.path() / "log.txt");
  ASSERT_TRUE(asker.readLine());  // VERSION
  ASSERT_TRUE(asker.send("{\"cmd\":\"status\"}\n"));
  const auto status = asker.readLine(10s);
  ASSERT_TRUE(status.has_value());
  EXPECT_FALSE(json::parse(*status).contains("live_check")) << *status;
  gyrod.signal(SIGTERM);
  ASSERT_EQ(gyrod.waitExit(5000ms), std::optional<int>(0));
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find("live check: off (it runs on still samples, and the still detector needs filter.model)"),
            std::string::npos)
      << log;
}

// ---- The replays: 2 h of data at 50 Hz on the mock at speed 100, the check at its
// defaults (300 s intervals, 1800 s of baseline), an effect beginning at t = 3600 s of data. Each
// must be named, on its axis, within 10 min of data time after its onset.
namespace {

constexpr double kReplayOnsetS = 3600.0;

std::string replayConfig(const ScratchDir& d, const std::string& model, const std::string& mock_lines) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n[filter]\nmodel = \"" << model << "\"\n"
    << "[socket]\npath = \"" << (d.path() / "gyrod.sock").string() << "\"\n"
    << "[mock]\nspeed = 100\nseed = 7\n"
    << mock_lines;
  return c.str();
}

struct Replayed {
  json effect;               // the first EFFECT line ("new"), null when none came
  double mock_start = 0.0;   // RATE's t at the mock's time 0
  double white_sigma = 0.0;  // of the raw y samples, from first differences (slow noise cancels)
  std::string log;
};

// Runs gyrod on `mock_lines` until the first EFFECT line or `until_s` of data; the first 2000
// samples are watched whole (the white noise's σ), then every 1000th.
Replayed replayUntilEffect(const std::string& mock_lines, double until_s) {
  ScratchDir d;
  const auto model = d.write("model.toml", liveCheckSensorModel());
  const auto cfg = d.write("gyrod.toml", replayConfig(d, model.string(), mock_lines));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  Replayed r;
  LineClient watcher((d.path() / "gyrod.sock").string());
  if (!watcher.connected() || !watcher.readLine()) {
    r.log = readWholeFile(d.path() / "log.txt");
    return r;
  }
  watcher.send("{\"cmd\":\"watch\"}\n");
  double mock_start = std::nan(""), last_y = std::nan(""), sum_d2 = 0.0;
  std::size_t diffs = 0, whole = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(until_s / 100.0 + 60.0);
  while (std::chrono::steady_clock::now() < deadline && r.effect.is_null()) {
    const auto line = watcher.readLine(20s);
    if (!line) break;
    const json j = json::parse(*line);
    if (j["class"] == "RATE") {
      if (std::isnan(mock_start)) mock_start = j["t"].get<double>() - j["seq"].get<double>() / 50.0;
      if (whole < 2000) {
        const double y = j["raw"][1].get<double>();
        if (!std::isnan(last_y)) {
          sum_d2 += (y - last_y) * (y - last_y);
          ++diffs;
        }
        last_y = y;
        if (++whole == 2000) watcher.send("{\"cmd\":\"watch\",\"decimate\":1000}\n");
      }
      if (j["t"].get<double>() - mock_start > until_s) break;
    }
    if (j["class"] == "EFFECT" && j["state"] == "new") r.effect = j;
  }
  r.mock_start = mock_start;
  r.white_sigma = diffs > 0 ? std::sqrt(sum_d2 / static_cast<double>(diffs) / 2.0) : 0.0;
  gyrod.signal(SIGTERM);
  gyrod.waitExit(5000ms);
  r.log = readWholeFile(d.path() / "log.txt");
  return r;
}

// The named effect's data times, relative to the mock's start.
double dataTime(const Replayed& r, const char* key) { return r.effect[key].get<double>() - r.mock_start; }
double dataTime95(const Replayed& r, int end) { return r.effect["onset_t_95"][end].get<double>() - r.mock_start; }

void expectNamedInTime(const Replayed& r, double onset_s) {
  std::cout << r.effect["effect"].get<std::string>() << " from " << onset_s << " s of data: named at "
            << dataTime(r, "t") << " s, onset " << dataTime(r, "onset_t") << " s (" << dataTime95(r, 0) << "-"
            << dataTime95(r, 1) << "); params " << r.effect["params"] << "\n";
  EXPECT_GT(dataTime(r, "t"), onset_s) << r.effect;
  EXPECT_LE(dataTime(r, "t"), onset_s + 600.0) << r.effect;
}

}  // namespace

// A 12.5 Hz line of 0.1 × the white noise's per-sample σ on y from 3600 s: named a line, on
// y, its centre within 1 %. σ is the model's angle random walk at the sample rate,
// σ = N·√rate with N = ARW/60 °/s/√Hz (IEEE 952), as bench/live_check_false_alarms has it; the
// raw samples' own σ is lower (the paper's 20 Hz DLPF takes the noise above 20 Hz off) and is
// printed beside it.
TEST(GyrodLiveCheckReplay, ALineOfATenthOfTheNoiseIsNamedWithin10Minutes) {
  const double kAmplitude = 0.1 * 0.95164 / 60.0 * std::sqrt(50.0);  // liveCheckSensorModel's ARW
  std::ostringstream mock;
  mock << "motion = \"sine:axis=y,freq=12.5,amp=" << kAmplitude << ",start=" << kReplayOnsetS << "\"\n";
  const Replayed r = replayUntilEffect(mock.str(), kReplayOnsetS + 900.0);
  std::cout << "amplitude " << kAmplitude << " deg/s; the raw y's own sigma " << r.white_sigma << " deg/s per sample\n";
  ASSERT_FALSE(r.effect.is_null()) << r.log;
  EXPECT_EQ(r.effect["effect"], "line") << r.effect;
  EXPECT_EQ(r.effect["axis"], "y") << r.effect;
  EXPECT_NEAR(r.effect["params"]["centre_hz"].get<double>(), 12.5, 0.125) << r.effect;
  expectNamedInTime(r, kReplayOnsetS);
  EXPECT_LE(dataTime95(r, 0), kReplayOnsetS + 1.0) << r.effect;
  EXPECT_GE(dataTime95(r, 1), kReplayOnsetS - 1.0) << r.effect;
}

// The board starts turning at 0.03 °/s about z (gravity's axis: the accelerometer does not
// see it, and neither can any gyro tell it from a bias step) at 3600 s: named a bias step on z,
// its size and onset inside their intervals.
TEST(GyrodLiveCheckReplay, ABiasStepIsNamedWithItsSizeWithin10Minutes) {
  constexpr double kStep = 0.03;
  std::ostringstream mock;
  mock << "motion = \"step:axis=z,at=" << kReplayOnsetS << ",rate=" << kStep << "\"\n";
  const Replayed r = replayUntilEffect(mock.str(), kReplayOnsetS + 900.0);
  ASSERT_FALSE(r.effect.is_null()) << r.log;
  EXPECT_EQ(r.effect["effect"], "bias_step") << r.effect;
  EXPECT_EQ(r.effect["axis"], "z") << r.effect;
  expectNamedInTime(r, kReplayOnsetS);
  EXPECT_LE(r.effect["params"]["size_dps_95"][0].get<double>(), kStep) << r.effect;
  EXPECT_GE(r.effect["params"]["size_dps_95"][1].get<double>(), kStep) << r.effect;
  EXPECT_LE(dataTime95(r, 0), kReplayOnsetS) << r.effect;
  EXPECT_GE(dataTime95(r, 1), kReplayOnsetS) << r.effect;
}

// 30 samples of x corrupted over a minute from 3600 s (bit 8: 1.95 °/s, some 25 σ): named an
// outlier burst on x with its count, its onset interval holding the first.
TEST(GyrodLiveCheckReplay, AnOutlierBurstIsNamedWithin10Minutes) {
  std::ostringstream mock;
  mock << "[mock.faults]\nglitch_burst = [{ at_s = " << kReplayOnsetS
       << ", duration_s = 60, count = 30, axis = \"x\", bit = 8 }]\n";
  const Replayed r = replayUntilEffect(mock.str(), kReplayOnsetS + 900.0);
  ASSERT_FALSE(r.effect.is_null()) << r.log;
  EXPECT_EQ(r.effect["effect"], "outlier_burst") << r.effect;
  EXPECT_EQ(r.effect["axis"], "x") << r.effect;
  expectNamedInTime(r, kReplayOnsetS);
  EXPECT_GE(r.effect["params"]["count"].get<int>(), 20) << r.effect;  // a burst across two intervals: the first's
  EXPECT_LE(r.effect["params"]["count"].get<int>(), 30) << r.effect;
  EXPECT_LE(dataTime95(r, 0), kReplayOnsetS + 0.1) << r.effect;
}

// The board warms by 8 °C from 3600 s (time constant 300 s) and the bias of y follows at
// 0.02 °/s per °C where the model says it does not: named a temperature bias on y, its
// coefficient inside its interval.
TEST(GyrodLiveCheckReplay, ATemperatureCouplingTheModelLacksIsNamedWithin10Minutes) {
  constexpr double kCoupling = 0.02;
  std::ostringstream mock;
  mock << "warm_up = \"8,300," << kReplayOnsetS << "\"\ntemperature_coefficient_dps_per_c = [0.0, " << kCoupling
       << ", 0.0]\n";
  const Replayed r = replayUntilEffect(mock.str(), kReplayOnsetS + 900.0);
  ASSERT_FALSE(r.effect.is_null()) << r.log;
  EXPECT_EQ(r.effect["effect"], "temperature_bias") << r.effect;
  EXPECT_EQ(r.effect["axis"], "y") << r.effect;
  expectNamedInTime(r, kReplayOnsetS);
  EXPECT_LE(r.effect["params"]["coefficient_dps_per_c_95"][0].get<double>(), kCoupling) << r.effect;
  EXPECT_GE(r.effect["params"]["coefficient_dps_per_c_95"][1].get<double>(), kCoupling) << r.effect;
}
