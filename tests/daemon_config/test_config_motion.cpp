// [mock] motion: the spec is validated when the configuration is read, so a bad one stops
// gyrod at start (exit 78) with the file and line of the key and the problem named.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "daemon/config.hpp"

using namespace gyrod::daemon;

namespace {

std::string motionErrorOf(const std::string& text) {
  try {
    parseConfig(text, "x.toml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ConfigMockMotion, ProfileTextIsKeptAsWritten) {
  const GyrodConfig c =
      parseConfig("[mock]\nmotion = \"constant:axis=z,rate=30,start=10 + sine:axis=x,freq=1,amp=2\"\n", "x.toml");
  EXPECT_EQ(c.mock.motion, "constant:axis=z,rate=30,start=10 + sine:axis=x,freq=1,amp=2");
  EXPECT_TRUE(GyrodConfig{}.mock.motion.empty());  // at rest by default
  EXPECT_TRUE(parseConfig("[mock]\nmotion = \"\"\n", "x.toml") == GyrodConfig{});
}

TEST(ConfigMockMotion, BadSpecNamesFileLineKeyAndProblem) {
  EXPECT_EQ(motionErrorOf("[mock]\nseed = 3\nmotion = \"step:axis=z,at=5,rat=10\"\n"),
            "x.toml:3: key 'mock.motion': motion: step: unknown key 'rat' (keys: axis, at, rate) "
            "(got \"step:axis=z,at=5,rat=10\")");
  EXPECT_EQ(motionErrorOf("[mock]\nmotion = \"sine:axis=x,freq=-1,amp=20\"\n"),
            "x.toml:2: key 'mock.motion': motion: sine: freq must be finite and > 0, got -1 "
            "(got \"sine:axis=x,freq=-1,amp=20\")");
  EXPECT_NE(motionErrorOf("[mock]\nmotion = 30\n").find("x.toml:2: key 'mock.motion'"), std::string::npos);
  EXPECT_EQ(
      motionErrorOf("[mock]\nsource = \"replay\"\nreplay_file = \"r.csv\"\nmotion = \"constant:axis=z,rate=1\"\n"),
      "x.toml:4: key 'mock.motion': applies to source = \"simulator\" only (a replayed recording already "
      "holds its motion) (got \"constant:axis=z,rate=1\")");
}

TEST(ConfigMockMotion, CsvSpecIsReadAndItsErrorsNameBothFiles) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "gyrod-config-motion-test";
  std::filesystem::create_directories(dir);
  const std::string good = (dir / "good.csv").string(), bad = (dir / "bad.csv").string();
  std::ofstream(good) << "t,wz\n0,0\n10,30\n";
  std::ofstream(bad) << "t,wz\n0,0\n1,fast\n";
  EXPECT_EQ(parseConfig("[mock]\nmotion = \"" + good + "\"\n", "x.toml").mock.motion, good);
  const std::string err = motionErrorOf("[mock]\n\nmotion = \"" + bad + "\"\n");
  EXPECT_EQ(err.rfind("x.toml:3: key 'mock.motion': " + bad + ":3: column 'wz': 'fast' is not a number", 0), 0u) << err;
  EXPECT_NE(motionErrorOf("[mock]\nmotion = \"" + (dir / "none.csv").string() + "\"\n").find("none.csv: cannot open"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(ConfigMockWarmUp, WarmUpAndCouplingAreReadAndChecked) {
  const GyrodConfig c =
      parseConfig("[mock]\nwarm_up = \"15,300\"\ntemperature_coefficient_dps_per_c = [0.03, -0.02, 0.015]\n", "x.toml");
  EXPECT_EQ(c.mock.warm_up, "15,300");
  EXPECT_EQ(c.mock.temperature_coefficient_dps_per_c, (std::vector<double>{0.03, -0.02, 0.015}));
  EXPECT_EQ(parseConfig("[mock]\ntemperature_coefficient_dps_per_c = 0.01\n", "x.toml")
                .mock.temperature_coefficient_dps_per_c,
            (std::vector<double>{0.01, 0.01, 0.01}));
  EXPECT_TRUE(GyrodConfig{}.mock.warm_up.empty());
  EXPECT_TRUE(GyrodConfig{}.mock.temperature_coefficient_dps_per_c.empty());
  EXPECT_EQ(
      motionErrorOf("[mock]\nwarm_up = \"15\"\n"),
      "x.toml:2: key 'mock.warm_up': warm-up: expected DELTA_C,TAU_S[,START_S] (e.g. 15,300 or 8,300,3600), got '15' (got \"15\")");
  EXPECT_EQ(
      motionErrorOf("[mock]\n\nwarm_up = \"15,-1\"\n"),
      "x.toml:3: key 'mock.warm_up': warm-up: the time constant TAU_S must be > 0 s, got '15,-1' (got \"15,-1\")");
  EXPECT_NE(motionErrorOf("[mock]\ntemperature_coefficient_dps_per_c = [1, 2]\n")
                .find("x.toml:2: key 'mock.temperature_coefficient_dps_per_c'"),
            std::string::npos);
  EXPECT_NE(motionErrorOf("[mock]\nsource = \"replay\"\nreplay_file = \"r.csv\"\nwarm_up = \"15,300\"\n")
                .find("applies to source = \"simulator\" only"),
            std::string::npos);
}
