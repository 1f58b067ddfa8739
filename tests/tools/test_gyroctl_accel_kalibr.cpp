// gyroctl analyze on accelerometer columns, the SI keys of its JSON, and --kalibr's imu.yaml,
// on files whose truth is known (a seeded model) and on the shipped real recording.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <set>
#include <string>

#include "formats/kalibr_yaml.hpp"
#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;
using nlohmann::json;

namespace {

constexpr double kG0 = 9.80665;
constexpr double kRateHz = 50.0;

// t, gx (white, °/s) and ax, ay, az (g): white noise of density `density_g` [g/√Hz] plus a
// bias random walk of strength `walk_g` [g/s^1.5] on ax; white only on ay, az (az about 1 g).
std::string accelRecording(std::size_t n, double density_g, double walk_g, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  const double dt = 1.0 / kRateHz, white = density_g * std::sqrt(kRateHz), step = walk_g * std::sqrt(dt);
  std::string text = "t,gx,ax,ay,az\n";
  text.reserve(n * 48);
  double bias = 0.0;
  char line[160];
  for (std::size_t i = 0; i < n; ++i) {
    bias += step * unit(rng);
    const double gx = 0.05 * unit(rng);
    const double ax = bias + white * unit(rng), ay = white * unit(rng), az = 1.0 + white * unit(rng);
    std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%.9g,%.9g\n", static_cast<double>(i) * dt, gx, ax, ay, az);
    text += line;
  }
  return text;
}

std::string realRecording(const ScratchDir& d) {
  const std::string src = std::string(GYROD_TEST_DATA_DIR) + "/mpu6050-arduino-100hz/imu_static_test.csv";
  const auto out = d.path() / "real.csv";
  const auto r = runGyroctl("import " + src + " -o " + out.string(), d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  return out.string();
}

}  // namespace

// White noise of 2 mg/√Hz plus a random walk of 2e-4 g/s^1.5 on ax, 3000 s at 50 Hz: the fit
// must find both, in the units its keys name, within its own intervals.
TEST(GyroctlAnalyzeAccel, FindsVelocityAndAccelerationRandomWalkInSiAndPaperStyleUnits) {
  ScratchDir d;
  const double density_g = 0.002, walk_g = 2e-4;
  const auto rec = d.write("acc.csv", accelRecording(150'000, density_g, walk_g, 11));
  const auto r = runGyroctl("analyze " + rec.string() + " --json", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const json doc = json::parse(r.out);
  for (const char* axis : {"gx", "ax", "ay", "az"}) EXPECT_TRUE(doc["axes"].contains(axis)) << axis;
  const json& ax = doc["axes"]["ax"];
  EXPECT_EQ(ax["unit"], "g");
  const json& noise = ax["noise"];
  const json& sigma = ax["noise_uncertainty"];
  const double vrw_si = noise["vrw_m_per_s2_sqrt_hz"].get<double>();
  EXPECT_NEAR(vrw_si, density_g * kG0, 0.03 * density_g * kG0);
  EXPECT_NEAR(vrw_si, density_g * kG0, 4.0 * sigma["vrw_m_per_s2_sqrt_hz"].get<double>() + 1e-3 * vrw_si);
  EXPECT_DOUBLE_EQ(noise["vrw_m_per_s_per_sqrt_h"].get<double>(), 60.0 * vrw_si);
  const double walk_si = noise["accel_random_walk_m_per_s3_sqrt_hz"].get<double>();
  EXPECT_NEAR(walk_si, walk_g * kG0, 0.35 * walk_g * kG0);
  EXPECT_NEAR(walk_si, walk_g * kG0, 4.0 * sigma["accel_random_walk_m_per_s3_sqrt_hz"].get<double>());
  EXPECT_DOUBLE_EQ(noise["accel_random_walk_m_per_s_per_h_sqrt_h"].get<double>(), 216000.0 * walk_si);
  EXPECT_DOUBLE_EQ(noise["bias_instability_m_per_s2"].get<double>(),
                   noise["bias_instability_mg"].get<double>() * 1e-3 * kG0);
  // No gyro key on an accelerometer column, and the gyro keeps its pinned keys beside SI.
  EXPECT_FALSE(noise.contains("arw_deg_per_sqrt_h"));
  const json& gx = doc["axes"]["gx"]["noise"];
  EXPECT_DOUBLE_EQ(gx["arw_rad_per_s_sqrt_hz"].get<double>(),
                   gx["arw_deg_per_sqrt_h"].get<double>() * std::numbers::pi / 180.0 / 60.0);
  EXPECT_TRUE(doc["axes"]["gx"]["noise_uncertainty"].contains("rrw_rad_per_s2_sqrt_hz"));
  EXPECT_TRUE(ax["trend_removed"].contains("offset_g"));
  EXPECT_TRUE(ax["mean_filter"].contains("threshold_g"));
}

TEST(GyroctlAnalyzeAccel, OneAccelAxisAndItsTextNameTheUnits) {
  ScratchDir d;
  const auto rec = d.write("acc.csv", accelRecording(2'000, 0.002, 0.0, 3));
  const auto j = runGyroctl("analyze " + rec.string() + " --json --axis ay", d.path());
  ASSERT_EQ(j.exit_status, 0) << j.err;
  const json doc = json::parse(j.out);
  EXPECT_EQ(doc["axes"].size(), 1u);
  EXPECT_TRUE(doc["axes"].contains("ay"));
  const auto t = runGyroctl("analyze " + rec.string() + " --axis az", d.path());
  ASSERT_EQ(t.exit_status, 0) << t.err;
  for (const char* s : {"== az ==", "Allan deviation (g;", "velocity random walk [m/s/sqrt(h)]",
                        "velocity random walk [m/s^2/sqrt(Hz)]", "bias instability [mg]",
                        "acceleration random walk [m/s^3/sqrt(Hz)]", " g, z = "})
    EXPECT_NE(t.out.find(s), std::string::npos) << s << "\n" << t.out;
  EXPECT_EQ(t.out.find("deg"), std::string::npos) << t.out;
}

TEST(GyroctlAnalyzeAccel, AMissingAccelColumnIsNamed) {
  ScratchDir d;
  const auto rec = d.write("g.csv", "t,gx\n0,1\n0.02,2\n");
  const auto r = runGyroctl("analyze " + rec.string() + " --axis az", d.path());
  EXPECT_EQ(r.exit_status, 64);  // EX_USAGE: a bad --axis value
  EXPECT_NE(r.err.find("--axis 'az': " + rec.string() + " has no column 'az' (the file has gx; or all)"),
            std::string::npos)
      << r.err;
}

// The shipped real recording: imu.yaml holds the means of the JSON's SI values per sensor.
TEST(GyroctlKalibr, RealRecordingGivesTheMeanOfTheAxesInSi) {
  ScratchDir d;
  const auto real = realRecording(d);
  const auto yaml = d.path() / "imu.yaml";
  const auto r = runGyroctl("analyze " + real + " --json --kalibr " + yaml.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const json doc = json::parse(r.out);
  const auto mean = [&](const char* a, const char* b, const char* c, const char* key) {
    return (doc["axes"][a]["noise"][key].get<double>() + doc["axes"][b]["noise"][key].get<double>() +
            doc["axes"][c]["noise"][key].get<double>()) /
           3.0;
  };
  const std::string text = readWholeFile(yaml);
  const auto imu = gyrod::formats::parseKalibrImuYaml(text, yaml.string());
  ASSERT_TRUE(imu.gyroscope_noise_density.value) << text;
  EXPECT_NEAR(*imu.gyroscope_noise_density.value, mean("gx", "gy", "gz", "arw_rad_per_s_sqrt_hz"),
              1e-5 * *imu.gyroscope_noise_density.value);
  ASSERT_TRUE(imu.accelerometer_noise_density.value) << text;
  EXPECT_NEAR(*imu.accelerometer_noise_density.value, mean("ax", "ay", "az", "vrw_m_per_s2_sqrt_hz"),
              1e-5 * *imu.accelerometer_noise_density.value);
  EXPECT_EQ(imu.update_rate_hz, 100.0);
  EXPECT_EQ(imu.rostopic, "/imu0");
  EXPECT_NE(text.find("NOT inflated"), std::string::npos) << text;
  // 100 s never reach the gyro's +1/2 slope: gyroscope_random_walk is a number all the same,
  // the upper bound min over tau of oadev * sqrt(3 / tau), the largest of the three axes, in
  // rad/s^2/sqrt(Hz), said so in its comment and on stderr (Kalibr cannot read a missing key).
  ASSERT_TRUE(imu.gyroscope_random_walk.value) << text;
  double bound = 0.0;
  for (const char* axis : {"gx", "gy", "gz"}) {
    EXPECT_EQ(doc["axes"][axis]["noise"]["rrw_rad_per_s2_sqrt_hz"].get<double>(), 0.0) << axis;
    double axis_bound = 1e300;
    for (const auto& p : doc["axes"][axis]["allan"])
      axis_bound = std::min(axis_bound, p["oadev"].get<double>() * std::sqrt(3.0 / p["tau_s"].get<double>()));
    bound = std::max(bound, axis_bound);
  }
  EXPECT_NEAR(*imu.gyroscope_random_walk.value, bound * std::numbers::pi / 180.0, 1e-5 * bound * 0.0175);
  EXPECT_NE(text.find("gyroscope_random_walk: "), std::string::npos) << text;
  EXPECT_EQ(text.find("# gyroscope_random_walk"), std::string::npos) << text;
  EXPECT_NE(text.find("upper bound, not a fit"), std::string::npos) << text;
  EXPECT_NE(r.err.find("gyroscope_random_walk: upper bound, not a fit"), std::string::npos) << r.err;
}

TEST(GyroctlKalibr, AGyroOnlyRecordingSaysTheAccelIsMissingAndWritesNoNumberForIt) {
  ScratchDir d;
  std::string text = "t,gx,gy,gz\n";
  std::mt19937_64 rng(5);
  std::normal_distribution<double> unit(0.0, 0.1);
  for (int i = 0; i < 3000; ++i)
    text += std::to_string(i * 0.02) + "," + std::to_string(unit(rng)) + "," + std::to_string(unit(rng)) + "," +
            std::to_string(unit(rng)) + "\n";
  const auto rec = d.write("g.csv", text);
  const auto yaml = d.path() / "imu.yaml";
  const auto r = runGyroctl("analyze " + rec.string() + " --kalibr " + yaml.string() +
                                " --kalibr-inflate 10 "
                                "--kalibr-rostopic /imu/data",
                            d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.err.find("accelerometer_noise_density: not estimated (no accelerometer column"), std::string::npos)
      << r.err;
  const std::string out = readWholeFile(yaml);
  EXPECT_NE(out.find("# accelerometer_noise_density: not estimated"), std::string::npos) << out;
  EXPECT_NE(out.find("ARE inflated: x 10"), std::string::npos) << out;
  const auto imu = gyrod::formats::parseKalibrImuYaml(out, yaml.string());
  EXPECT_FALSE(imu.accelerometer_noise_density.value);
  EXPECT_FALSE(imu.accelerometer_random_walk.value);
  EXPECT_EQ(imu.rostopic, "/imu/data");
  // White noise of 0.1 deg/s per sample at 50 Hz: density 0.1/√50 deg/s/√Hz, ×10 inflated.
  ASSERT_TRUE(imu.gyroscope_noise_density.value) << out;
  const double truth = 10.0 * 0.1 / std::sqrt(50.0) * std::numbers::pi / 180.0;
  EXPECT_NEAR(*imu.gyroscope_noise_density.value, truth, 0.1 * truth);
}

// A bad factor is a usage error; a target that cannot be written is refused before the
// analysis, as --write-model's is.
TEST(GyroctlKalibr, BadOptionsAreRefusedBeforeTheAnalysis) {
  ScratchDir d;
  const auto rec = d.write("g.csv", "t,gx\n0,1\n0.02,2\n");
  EXPECT_EQ(runGyroctl("analyze " + rec.string() + " --kalibr-inflate 0", d.path()).exit_status, 64);  // EX_USAGE
  const auto model = runGyroctl("analyze " + rec.string() + " --write-model " + d.path().string(), d.path());
  const auto kalibr = runGyroctl("analyze " + rec.string() + " --kalibr " + d.path().string(), d.path());
  EXPECT_NE(kalibr.exit_status, 0);
  EXPECT_EQ(kalibr.exit_status, model.exit_status);
  EXPECT_NE(kalibr.err.find("refusing to write: it is a directory"), std::string::npos) << kalibr.err;
}

// docs/coming-from.md lists every noise key analyze writes, gyro and accelerometer, and no other.
TEST(GyroctlAnalyzeAccel, TheDocumentedNoiseKeysAreTheJsonKeys) {
  ScratchDir d;
  const auto rec = d.write("acc.csv", accelRecording(2'000, 0.002, 0.0, 4));
  const auto r = runGyroctl("analyze " + rec.string() + " --json --axis all", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const json doc = json::parse(r.out);
  std::set<std::string> written;
  for (const char* axis : {"gx", "ax"})
    for (const auto& [key, value] : doc["axes"][axis]["noise"].items()) written.insert(key);

  std::ifstream in(std::string(GYROD_TEST_DATA_DIR) + "/../../docs/coming-from.md");
  ASSERT_TRUE(in) << "docs/coming-from.md";
  std::set<std::string> documented;
  std::string line;
  bool in_section = false;
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0) in_section = line == "## gyroctl's noise keys";
    if (in_section && line.rfind("| `", 0) == 0) documented.insert(line.substr(3, line.find('`', 3) - 3));
  }
  EXPECT_EQ(documented, written);
}
