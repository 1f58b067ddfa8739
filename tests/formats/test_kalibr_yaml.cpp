// Kalibr's imu.yaml: what kalibrImuYaml writes reads back, and a term that was not estimated
// is a comment, never a number.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "formats/kalibr_yaml.hpp"

using namespace gyrod::formats;

namespace {

std::string kalibrErrorOf(const std::string& text) {
  try {
    parseKalibrImuYaml(text, "imu.yaml");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(KalibrYaml, RoundTripsTheValuesToSixDigits) {
  KalibrImu imu;
  imu.accelerometer_noise_density.value = 1.86e-03;
  imu.accelerometer_random_walk.value = 4.33e-04;
  imu.gyroscope_noise_density.value = 1.8744444e-04;
  imu.gyroscope_random_walk.value = 2.66e-05;
  imu.rostopic = "/imu0/data";
  imu.update_rate_hz = 200.0;
  imu.header_comments = {"made by a test"};
  const std::string text = kalibrImuYaml(imu);
  EXPECT_EQ(text.rfind("# made by a test\n", 0), 0u) << text;
  EXPECT_NE(text.find("gyroscope_noise_density: 0.000187444"), std::string::npos) << text;
  const auto back = parseKalibrImuYaml(text, "imu.yaml");
  EXPECT_EQ(back.accelerometer_noise_density.value, 1.86e-03);
  EXPECT_EQ(back.accelerometer_random_walk.value, 4.33e-04);
  EXPECT_EQ(back.gyroscope_noise_density.value, 1.87444e-04);
  EXPECT_EQ(back.gyroscope_random_walk.value, 2.66e-05);
  EXPECT_EQ(back.rostopic, "/imu0/data");
  EXPECT_EQ(back.update_rate_hz, 200.0);
}

TEST(KalibrYaml, ATermNotEstimatedIsACommentWithItsReason) {
  KalibrImu imu;
  imu.gyroscope_noise_density.value = 2e-4;
  imu.gyroscope_random_walk.note = "too short";
  imu.accelerometer_noise_density.note = "no accelerometer column";
  imu.update_rate_hz = 100.0;
  const std::string text = kalibrImuYaml(imu);
  EXPECT_NE(text.find("# gyroscope_random_walk: not estimated (too short)\n"), std::string::npos) << text;
  EXPECT_NE(text.find("# accelerometer_noise_density: not estimated (no accelerometer column)\n"), std::string::npos);
  const auto back = parseKalibrImuYaml(text, "imu.yaml");
  EXPECT_FALSE(back.gyroscope_random_walk.value);
  EXPECT_FALSE(back.accelerometer_noise_density.value);
  EXPECT_FALSE(back.accelerometer_random_walk.value);
  EXPECT_EQ(back.gyroscope_noise_density.value, 2e-4);
}

TEST(KalibrYaml, BadLinesNameFileLineAndValue) {
  EXPECT_EQ(kalibrErrorOf("update_rate: 100\ngyroscope_noise_density: fast\n"),
            "imu.yaml:2: gyroscope_noise_density: 'fast' is not a number");
  EXPECT_EQ(kalibrErrorOf("# c\nno colon here\n"), "imu.yaml:2: 'no colon here' is not 'key: value'");
  EXPECT_EQ(kalibrErrorOf("gyro_noise: 1\n"), "imu.yaml:1: unknown key 'gyro_noise'");
}
