// Conversion of FIFO words to °/s and °C at every FS_SEL, axis order and sign, and
// saturation (including INT16_MIN), against the analog input the mock was given.
#include <gtest/gtest.h>

#include <cmath>

#include "driver/mock/mock_signal_source.hpp"
#include "tests/driver/driver_rig.hpp"

namespace gyrod::driver::test {
namespace {

// Product specification §6.1: LSB per °/s for FS_SEL 0..3 (written here independently of
// the driver's register map).
constexpr double kLsbPerDps[4] = {131.0, 65.5, 32.8, 16.4};
constexpr double kFullScaleDps[4] = {250.0, 500.0, 1000.0, 2000.0};

TEST(Mpu6050DriverConversion, EveryFullScaleConvertsExactlyWithAxisOrderAndSign) {
  for (int fs = 0; fs < 4; ++fs) {
    const double r = kFullScaleDps[fs];
    const std::array<double, 3> input = {0.37 * r, -0.61 * r, 0.05 * r + 0.123};
    ConstantSource source(input, 31.7);
    RigOptions o;
    o.driver.fs_sel = fs;
    DriverRig rig(source, o);
    rig.startStreaming();
    rig.runFor(kNsPerSecond);
    const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), {1'000.0, 0});
    ASSERT_GT(c.matched, 40u);
    for (const GyroSample& s : rig.recorder.samples) {
      for (int a = 0; a < 3; ++a) {
        // Exactly raw / sensitivity, with the mock's raw word (checkStream matched them).
        EXPECT_EQ(s.rate_dps[a], static_cast<double>(s.raw_gyro[a]) / kLsbPerDps[fs]) << "fs " << fs << " axis " << a;
        // And within half an LSB of what the chip was given (a constant passes the DLPF).
        EXPECT_NEAR(s.rate_dps[a], input[a], 0.5 / kLsbPerDps[fs] + 1e-9) << "fs " << fs << " axis " << a;
      }
      // RM Registers 65–66: °C = TEMP_OUT / 340 + 36.53.
      EXPECT_EQ(s.temp_c, static_cast<double>(s.raw_temp) / 340.0 + 36.53);
      EXPECT_NEAR(s.temp_c, 31.7, 0.5 / 340.0 + 1e-9);
    }
  }
}

TEST(Mpu6050DriverConversion, SaturatedWordsKeepTheirSignIncludingInt16Min) {
  for (int fs : {0, 3}) {
    const double beyond = 1.2 * kFullScaleDps[fs];
    ConstantSource source({beyond, -beyond, -0.25 * kFullScaleDps[fs]}, 25.0);
    RigOptions o;
    o.driver.fs_sel = fs;
    DriverRig rig(source, o);
    rig.startStreaming();
    rig.runFor(kNsPerSecond / 2);
    ASSERT_FALSE(rig.recorder.samples.empty());
    const GyroSample& s = rig.recorder.samples.back();
    EXPECT_EQ(s.raw_gyro[0], 32767);
    EXPECT_EQ(s.raw_gyro[1], -32768);
    EXPECT_EQ(s.rate_dps[0], 32767.0 / kLsbPerDps[fs]);
    EXPECT_EQ(s.rate_dps[1], -32768.0 / kLsbPerDps[fs]);  // not +32768 or 0 (a careless negation)
    EXPECT_LT(s.rate_dps[2], 0.0);
    EXPECT_NEAR(s.rate_dps[2], -0.25 * kFullScaleDps[fs], 0.5 / kLsbPerDps[fs] + 1e-9);
  }
}

}  // namespace
}  // namespace gyrod::driver::test
