// The accelerometer through the FIFO: 14-byte frames (accel, temperature, gyro), the exact
// scaling at every AFS_SEL, saturation, the gyro unchanged bit for bit by the longer frame,
// the frame-alignment check on the longer frame, and accel off giving the 8-byte frame.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "driver/fifo_frame.hpp"
#include "driver/mock/mock_signal_source.hpp"
#include "driver/mock/simulator_signal_source.hpp"
#include "tests/driver/driver_rig.hpp"

namespace gyrod::driver::test {
namespace {

namespace m = mpu6050;
using m::Register;

// Product specification §6.2: LSB per g for AFS_SEL 0..3 and the ranges (written here
// independently of the driver's register map).
constexpr double kLsbPerG[4] = {16384.0, 8192.0, 4096.0, 2048.0};
constexpr double kRangeG[4] = {2.0, 4.0, 8.0, 16.0};

std::uint8_t readReg(MockMpu6050& mock, Register r) {
  std::uint8_t v = 0;
  EXPECT_EQ(mock.readByte(m::address(r), v), 0);
  return v;
}

RigOptions withAccel(int afs_sel, std::array<double, 3> accel_g) {
  RigOptions o;
  o.driver.accel = true;
  o.driver.afs_sel = afs_sel;
  o.mock.accel_g = accel_g;
  return o;
}

TEST(Mpu6050DriverAccel, EveryRangeScalesExactlyAndMatchesTheChipsWords) {
  for (int afs = 0; afs < 4; ++afs) {
    const double r = kRangeG[afs];
    const std::array<double, 3> input = {0.31 * r, -0.47 * r, 0.05 * r + 0.0123};
    ConstantSource source({1.0, -2.0, 3.0}, 28.0);
    DriverRig rig(source, withAccel(afs, input));
    rig.startStreaming();
    rig.runFor(kNsPerSecond);
    EXPECT_EQ(readReg(rig.mock, Register::FIFO_EN), 0xF8) << "ACCEL, TEMP, XG, YG, ZG";
    EXPECT_EQ(readReg(rig.mock, Register::ACCEL_CONFIG), afs << 3);
    const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), {1'000.0, 0});
    ASSERT_GT(c.matched, 40u);
    std::map<std::uint64_t, const SampleRecord*> by_time;
    for (const SampleRecord& t : rig.truth) by_time[static_cast<std::uint64_t>(t.time_ns)] = &t;
    for (const GyroSample& s : rig.recorder.samples) {
      for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(s.accel_g[a], static_cast<double>(s.raw_accel[a]) / kLsbPerG[afs]) << "afs " << afs << " axis " << a;
        EXPECT_NEAR(s.accel_g[a], input[a], 0.5 / kLsbPerG[afs] + 1e-12) << "afs " << afs << " axis " << a;
      }
    }
    // The words are the chip's: every mock sample written to the FIFO shows up with its accel.
    std::size_t compared = 0;
    for (const GyroSample& s : rig.recorder.samples) {
      for (const SampleRecord& t : rig.truth) {
        if (t.written_to_fifo && t.gyro == s.raw_gyro && t.temperature == s.raw_temp) {
          EXPECT_EQ(t.accel, s.raw_accel);
          ++compared;
          break;
        }
      }
    }
    EXPECT_GT(compared, 40u);
  }
}

TEST(Mpu6050DriverAccel, SaturatesAtTheRangeKeepingTheSign) {
  ConstantSource source({0.0, 0.0, 0.0}, 25.0);
  DriverRig rig(source, withAccel(0, {2.5, -3.0, 0.25}));
  rig.startStreaming();
  rig.runFor(kNsPerSecond / 2);
  ASSERT_FALSE(rig.recorder.samples.empty());
  const GyroSample& s = rig.recorder.samples.back();
  EXPECT_EQ(s.raw_accel[0], 32767);
  EXPECT_EQ(s.raw_accel[1], -32768);
  EXPECT_EQ(s.accel_g[1], -2.0);
  EXPECT_EQ(s.accel_g[2], 0.25);
}

TEST(Mpu6050DriverAccel, TheGyroStreamIsTheSameBitsWithAndWithoutAccel) {
  std::map<std::uint64_t, GyroSample> without;
  {
    SinusoidSource source({{{0.5, 40.0, 2.0, 0.0}, {-1.0, 25.0, 3.1, 1.0}, {0.25, 10.0, 0.7, 2.0}}}, 27.0);
    DriverRig rig(source);
    rig.startStreaming();
    rig.runFor(3 * kNsPerSecond);
    for (const GyroSample& s : rig.recorder.samples) {
      EXPECT_TRUE(std::isnan(s.accel_g[0]) && std::isnan(s.accel_g[1]) && std::isnan(s.accel_g[2]));
      EXPECT_EQ(s.raw_accel, (std::array<std::int16_t, 3>{}));
      without[s.seq] = s;
    }
    EXPECT_EQ(readReg(rig.mock, Register::FIFO_EN), 0xF0);
    EXPECT_EQ(rig.driver.registerTable().size(), kRegisterTableSize);
  }
  SinusoidSource source({{{0.5, 40.0, 2.0, 0.0}, {-1.0, 25.0, 3.1, 1.0}, {0.25, 10.0, 0.7, 2.0}}}, 27.0);
  DriverRig rig(source, withAccel(1, {0.0, 0.0, 1.0}));
  rig.startStreaming();
  rig.runFor(3 * kNsPerSecond);
  std::size_t compared = 0;
  for (const GyroSample& s : rig.recorder.samples) {
    const auto it = without.find(s.seq);
    if (it == without.end()) continue;
    EXPECT_EQ(s.raw_gyro, it->second.raw_gyro) << "seq " << s.seq;
    for (int a = 0; a < 3; ++a) EXPECT_EQ(s.rate_dps[a], it->second.rate_dps[a]) << "seq " << s.seq;
    EXPECT_EQ(s.raw_temp, it->second.raw_temp);
    ++compared;
  }
  EXPECT_GT(compared, 100u);
}

TEST(Mpu6050DriverAccel, AMisalignedBurstOfLongFramesIsStillCaught) {
  for (int stray_bytes : {1, 2, 6}) {
    SinusoidSource source({{{0.5, 40.0, 2.0, 0.0}, {-1.0, 25.0, 3.1, 1.0}, {0.25, 10.0, 0.7, 2.0}}}, 27.0);
    DriverRig rig(source, withAccel(0, {0.02, -0.03, 0.99}));
    rig.startStreaming();
    rig.runFor(kNsPerSecond + 3 * kNsPerMillisecond);
    // Stray bytes in the FIFO (the host may write FIFO_R_W): every later frame is shifted, so
    // an accel or gyro word (or half of one) sits where the temperature word belongs.
    for (int i = 0; i < stray_bytes; ++i) ASSERT_EQ(rig.mock.writeByte(m::address(Register::FIFO_R_W), 0x5A), 0);
    rig.runFor(3 * kNsPerSecond);
    const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), {1'000.0, 0});
    EXPECT_GT(c.matched, 100u);
    EXPECT_EQ(rig.driver.counters().misaligned_bursts, 1u) << stray_bytes << " stray bytes";
    ASSERT_EQ(rig.recorder.gaps.size(), 1u);
    EXPECT_EQ(rig.recorder.gaps[0].cause, GapCause::MisalignedFrames);
  }
}

TEST(Mpu6050DriverAccel, TheRegisterTableWritesAccelConfigAfterGyroConfig) {
  Mpu6050Config c;
  c.accel = true;
  c.afs_sel = 3;
  const std::vector<RegisterSetting> t = registerTableFor(c);
  ASSERT_EQ(t.size(), kRegisterTableSize + 1);
  EXPECT_EQ(t[4].reg, Register::GYRO_CONFIG);
  EXPECT_EQ(t[5].reg, Register::ACCEL_CONFIG);
  EXPECT_EQ(t[5].set, 0x18);
  EXPECT_EQ(t[5].clear, m::XA_ST | m::YA_ST | m::ZA_ST);
  for (const RegisterSetting& s : t) {
    if (s.reg == Register::FIFO_EN) {
      EXPECT_EQ(s.set, 0xF8);
      EXPECT_EQ(s.clear, 0x07);
    }
    if (s.reg == Register::PWR_MGMT_2) {
      EXPECT_EQ(s.clear, 0x3F);  // no axis in standby
    }
  }
  c.afs_sel = 4;
  try {
    validateConfig(c);
    ADD_FAILURE() << "afs_sel 4 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("afs_sel"), std::string::npos) << e.what();
  }
  EXPECT_EQ(afsSelForRangeG(2), 0);
  EXPECT_EQ(afsSelForRangeG(16), 3);
  EXPECT_FALSE(afsSelForRangeG(3));
  EXPECT_FALSE(afsSelForRangeG(32));
}

TEST(Mpu6050DriverAccel, TheFifoHoldsFewerLongFramesAndTheBoundsFollow) {
  Mpu6050Config c;
  c.accel = true;
  c.max_frames_per_wakeup = 73;  // 1024 / 14
  EXPECT_NO_THROW(validateConfig(c));
  c.max_frames_per_wakeup = 74;
  EXPECT_THROW(validateConfig(c), std::invalid_argument);
  c.accel = false;
  EXPECT_NO_THROW(validateConfig(c));
}

// With the simulator's motion, the mock's accel is gravity at the attitude integrated from the
// true rates: a quarter turn about x takes (0, 0, 1) g to (0, 1, 0) g.
TEST(Mpu6050DriverAccel, TheMocksAccelTiltsWithTheSimulatedMotion) {
  processing::SimulationModel model;
  const processing::MotionProfile quarter_turn = processing::MotionProfile::constant(0, 30.0, 1.0, 3.0);  // 90°
  SimulatorSignalSource source(model, 4, 7, 60.0, quarter_turn);
  RigOptions o = withAccel(0, {0.0, 0.0, 1.0});
  o.mock.accel_noise_g = 0.002;
  o.mock.accel_bias_g = {0.01, -0.02, 0.005};
  DriverRig rig(source, o);
  rig.startStreaming();
  rig.runFor(6 * kNsPerSecond);
  ASSERT_GT(rig.recorder.samples.size(), 200u);
  const auto meanAccel = [&](double from_s, double to_s) {
    std::array<double, 3> sum{};
    int n = 0;
    const double t0 = static_cast<double>(rig.recorder.samples.front().t_ns) * 1e-9;
    for (const GyroSample& s : rig.recorder.samples) {
      const double t = static_cast<double>(s.t_ns) * 1e-9 - t0;
      if (t < from_s || t >= to_s) continue;
      for (int a = 0; a < 3; ++a) sum[a] += s.accel_g[a];
      ++n;
    }
    for (double& v : sum) v /= n;
    return sum;
  };
  // Streaming starts a little after the mock's first tick, so the windows keep clear of the turn.
  const auto before = meanAccel(0.0, 0.5);
  const auto after = meanAccel(4.5, 5.5);
  // 25+ samples of 2 mg noise: the mean is within 1.5 mg; plus the bias.
  EXPECT_NEAR(before[0], 0.01, 2e-3);
  EXPECT_NEAR(before[1], -0.02, 2e-3);
  EXPECT_NEAR(before[2], 1.005, 2e-3);
  EXPECT_NEAR(after[0], 0.01, 2e-3);
  EXPECT_NEAR(after[1], 1.0 - 0.02, 2e-3);
  EXPECT_NEAR(after[2], 0.005, 2e-3);
}

}  // namespace
}  // namespace gyrod::driver::test
