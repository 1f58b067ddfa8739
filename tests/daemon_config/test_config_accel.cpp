// The accelerometer keys of [device]: defaults, every accepted range, and the errors naming
// file, line, key and value.
#include <gtest/gtest.h>

#include <string>

#include "daemon/config.hpp"
#include "driver/mpu6050_config.hpp"

using namespace gyrod::daemon;

namespace {

std::string accelErrorOf(const std::string& text) {
  try {
    parseConfig(text, "x.toml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ConfigAccel, OnAtTwoGByDefault) {
  const GyrodConfig c = parseConfig("", "x.toml");
  EXPECT_TRUE(c.device.accel);
  EXPECT_EQ(c.device.accel_range_g, 2);
}

TEST(ConfigAccel, EveryRangeMapsToItsAfsSel) {
  for (int range : {2, 4, 8, 16}) {
    const GyrodConfig c = parseConfig("[device]\naccel_range_g = " + std::to_string(range) + "\n", "x.toml");
    EXPECT_EQ(c.device.accel_range_g, range);
    ASSERT_TRUE(gyrod::driver::afsSelForRangeG(range));
    // 16384 / 2^AFS_SEL LSB per g: the range times the LSB per g is always 32768.
    EXPECT_EQ(gyrod::driver::mpu6050::kAccelLsbPerG.at(*gyrod::driver::afsSelForRangeG(range)) * range, 32768.0);
  }
  EXPECT_FALSE(parseConfig("[device]\naccel = false\n", "x.toml").device.accel);
}

TEST(ConfigAccel, BadValuesNameFileLineKeyAndValue) {
  EXPECT_EQ(accelErrorOf("[device]\naccel_range_g = 3\n"),
            "x.toml:2: key 'device.accel_range_g': must be 2, 4, 8 or 16 (got 3)");
  EXPECT_EQ(accelErrorOf("[device]\nrate_hz = 50\naccel_range_g = 32\n"),
            "x.toml:3: key 'device.accel_range_g': must be 2, 4, 8 or 16 (got 32)");
  const std::string not_bool = accelErrorOf("[device]\naccel = 1\n");
  EXPECT_EQ(not_bool.rfind("x.toml:2: key 'device.accel'", 0), 0u) << not_bool;
  EXPECT_EQ(exitCodeForConfigError(), 78);
}
