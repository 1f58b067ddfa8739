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
#include "tools/run_command.hpp"

using namespace gyrod::test;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

constexpr double kLiveOnsetS = 300.0;  // after the baseline (two 60 s intervals) and a few more

std::string liveSensorModel() {
  std::ostringstream m;
  m << "rate_hz = 50\n[temperature]\nstart_c = 30\nfinal_c = 30\ntime_constant_s = 900.0\nnoise_std_c = 0.02\n";
  for (const char* axis : {"x", "y", "z"}) {
    m << "[" << axis << "]\nquantization_urad = 0.1663\narw_deg_per_sqrt_h = 0.95164\n"
      << "bias_instability_deg_per_h = 0.60565\nrrw_deg_per_h_sqrt_h = 0.07759\nbias_dps = 0.5\n"
      << "[" << axis << ".calibration]\nbias_std_dps = 0.02\ntemperature_coefficient_dps_per_c = 0.0\n"
      << "temperature_coefficient_std_dps_per_c = 0.05\ntemperature_reference_c = 25.0\n";
  }
  return m.str();
}

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
  const auto model = d.write("model.toml", liveSensorModel());
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
