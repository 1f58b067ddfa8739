// Register behaviour of the mock MPU-6050, through the I2cBus interface only. Expected
// values are the register map's (RM-MPU-6000A-00 rev 4.2), written out here.
#include <gtest/gtest.h>

#include <cerrno>

#include "driver/mock/mock_signal_source.hpp"
#include "tests/driver/mock_rig.hpp"

namespace gyrod::driver::test {
namespace {

TEST(MockMpu6050Registers, PowerOnValuesAreZeroExceptPwrMgmt1AndWhoAmI) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  // RM §3 p.8: "The reset value is 0x00 for all registers other than ... Register 107:
  // 0x40. Register 117: 0x68."
  for (int r = 0x0D; r <= 0x75; ++r) {
    std::uint8_t v = 0xEE;
    ASSERT_EQ(rig.mock.readByte(static_cast<std::uint8_t>(r), v), 0) << "register " << r;
    const std::uint8_t expected = r == 0x6B ? 0x40 : r == 0x75 ? 0x68 : 0x00;
    EXPECT_EQ(v, expected) << "register 0x" << std::hex << r;
  }
}

TEST(MockMpu6050Registers, WhoAmIIs0x68AndWritesToItAreIgnored) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  EXPECT_EQ(read(rig.mock, Register::WHO_AM_I), 0x68);
  ASSERT_EQ(rig.mock.writeByte(0x75, 0x12), 0);  // ACKed, but read-only
  EXPECT_EQ(read(rig.mock, Register::WHO_AM_I), 0x68);
  EXPECT_EQ(rig.mock.counters().writes_ignored, 1u);
}

TEST(MockMpu6050Registers, OtherAddressesNack) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  ASSERT_EQ(rig.mock.selectDevice(0x69), 0);
  std::uint8_t v = 0;
  EXPECT_EQ(rig.mock.readByte(0x75, v), -EREMOTEIO);
  EXPECT_EQ(rig.mock.writeByte(0x6B, 0x00), -EREMOTEIO);
  EXPECT_EQ(rig.mock.counters().nacks_absent_address, 2u);
  EXPECT_EQ(rig.mock.selectDevice(0x80), -EINVAL);
  ASSERT_EQ(rig.mock.selectDevice(0x68), 0);
  EXPECT_EQ(read(rig.mock, Register::WHO_AM_I), 0x68);
  EXPECT_EQ(read(rig.mock, Register::PWR_MGMT_1), 0x40);  // the failed write did nothing
}

TEST(MockMpu6050Registers, ChipAtAd0HighAnswersOnlyAt0x69) {
  ConstantSource source({0, 0, 0});
  MockMpu6050Config config;
  config.address = 0x69;
  Rig rig(source, config);
  std::uint8_t v = 0;
  EXPECT_EQ(rig.mock.readByte(0x75, v), 0);  // selected by default
  EXPECT_EQ(v, 0x68);                        // WHO_AM_I does not follow AD0
  ASSERT_EQ(rig.mock.selectDevice(0x68), 0);
  EXPECT_EQ(rig.mock.readByte(0x75, v), -EREMOTEIO);
}

TEST(MockMpu6050Registers, DeviceResetSelfClearsAndLeavesTheChipAsleep) {
  ConstantSource source({1, 2, 3});
  MockMpu6050Config config = Rig::quietConfig();
  config.reset_duration_ns = 100 * kNsPerMillisecond;
  Rig rig(source, config);
  rig.wake(3, 4);
  write(rig.mock, Register::GYRO_CONFIG, mpu6050::FS_SEL_2000_DPS);
  EXPECT_EQ(read(rig.mock, Register::PWR_MGMT_1), 0x01);

  write(rig.mock, Register::PWR_MGMT_1, mpu6050::DEVICE_RESET);
  EXPECT_EQ(read(rig.mock, Register::PWR_MGMT_1), 0xC0);  // DEVICE_RESET still set
  write(rig.mock, Register::SMPLRT_DIV, 9);               // lost: the chip is resetting
  EXPECT_EQ(rig.mock.counters().writes_ignored, 1u);

  rig.advance(99 * kNsPerMillisecond);
  EXPECT_EQ(read(rig.mock, Register::PWR_MGMT_1), 0xC0);
  rig.advance(1 * kNsPerMillisecond);
  EXPECT_EQ(read(rig.mock, Register::PWR_MGMT_1), 0x40);  // self-cleared, asleep
  EXPECT_EQ(read(rig.mock, Register::SMPLRT_DIV), 0x00);
  EXPECT_EQ(read(rig.mock, Register::CONFIG), 0x00);
  EXPECT_EQ(read(rig.mock, Register::GYRO_CONFIG), 0x00);
  EXPECT_EQ(rig.mock.counters().device_resets, 1u);

  // Asleep: no samples however long we wait.
  const std::uint64_t before = rig.mock.counters().samples_produced;
  rig.advance(1 * kNsPerSecond);
  EXPECT_EQ(rig.mock.counters().samples_produced, before);
  EXPECT_FALSE(rig.mock.nextSampleTimeNs().has_value());
}

TEST(MockMpu6050Registers, SleepStopsSamplingAndWakeRestartsIt) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  rig.advance(kNsPerSecond);
  EXPECT_EQ(rig.mock.counters().samples_produced, 0u);  // asleep after power-on
  rig.wake(1, 0);                                       // 1 kHz
  rig.advance(10 * kNsPerMillisecond);
  EXPECT_EQ(rig.mock.counters().samples_produced, 10u);
  write(rig.mock, Register::PWR_MGMT_1, mpu6050::SLEEP);
  rig.advance(10 * kNsPerMillisecond);
  EXPECT_EQ(rig.mock.counters().samples_produced, 10u);
  write(rig.mock, Register::PWR_MGMT_1, 0x00);
  rig.advance(10 * kNsPerMillisecond);
  EXPECT_EQ(rig.mock.counters().samples_produced, 20u);
}

TEST(MockMpu6050Registers, IntStatusIsClearedByReadingIt) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  write(rig.mock, Register::INT_ENABLE, mpu6050::DATA_RDY_EN);
  rig.wake(1, 0);
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS), 0x00);  // no sample yet
  rig.advance(kNsPerMillisecond);
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS), mpu6050::DATA_RDY_INT);
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS), 0x00);  // cleared by the first read
  // Reading another register does not clear it while INT_RD_CLEAR = 0 ...
  rig.advance(kNsPerMillisecond);
  (void)read(rig.mock, Register::GYRO_XOUT_H);
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS), mpu6050::DATA_RDY_INT);
  // ... but does with INT_RD_CLEAR = 1 ("cleared on any read operation").
  write(rig.mock, Register::INT_PIN_CFG, mpu6050::INT_RD_CLEAR);
  rig.advance(kNsPerMillisecond);
  (void)read(rig.mock, Register::GYRO_XOUT_H);
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS), 0x00);
}

TEST(MockMpu6050Registers, DisabledInterruptsDoNotSetStatusBits) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  rig.wake(1, 0);
  rig.advance(5 * kNsPerMillisecond);
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS), 0x00);
  EXPECT_EQ(rig.mock.counters().samples_produced, 5u);
}

TEST(MockMpu6050Registers, OutputRegistersAreBigEndianTwosComplement) {
  // −10 °/s at FS_SEL 0: −10 · 131 = −1310 = 0xFAE2. +1 g at AFS_SEL 0: 16384 = 0x4000.
  ConstantSource source({-10.0, 250.0, 0.0}, 36.53 + 1.0);
  Rig rig(source);
  rig.wake(7, 0);  // DLPF bypassed: the rate reaches the registers unfiltered
  rig.advance(kNsPerMillisecond);
  EXPECT_EQ(read(rig.mock, Register::GYRO_XOUT_H), 0xFA);
  EXPECT_EQ(read(rig.mock, Register::GYRO_XOUT_L), 0xE2);
  std::uint16_t word = 0;
  ASSERT_EQ(rig.mock.readWordBigEndian(A(Register::GYRO_XOUT_H), word), 0);
  EXPECT_EQ(word, 0xFAE2);
  // 250 · 131 = 32750 = 0x7FEE
  ASSERT_EQ(rig.mock.readWordBigEndian(A(Register::GYRO_YOUT_H), word), 0);
  EXPECT_EQ(word, 0x7FEE);
  ASSERT_EQ(rig.mock.readWordBigEndian(A(Register::ACCEL_ZOUT_H), word), 0);
  EXPECT_EQ(word, 0x4000);
  // Temperature 1 °C above the offset: 340 = 0x0154.
  ASSERT_EQ(rig.mock.readWordBigEndian(A(Register::TEMP_OUT_H), word), 0);
  EXPECT_EQ(word, 0x0154);
  // A 14-byte burst from ACCEL_XOUT_H gives the same bytes in register order.
  std::array<std::uint8_t, 14> b{};
  ASSERT_EQ(rig.mock.readBlock(A(Register::ACCEL_XOUT_H), b), 0);
  const std::array<std::uint8_t, 14> expected = {0x00, 0x00, 0x00, 0x00, 0x40, 0x00, 0x01,
                                                 0x54, 0xFA, 0xE2, 0x7F, 0xEE, 0x00, 0x00};
  EXPECT_EQ(b, expected);
}

TEST(MockMpu6050Registers, BurstLongerThanTheAdapterAllowsIsRefused) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  EXPECT_EQ(rig.mock.maxBurstLength(), 32u);
  std::array<std::uint8_t, 33> too_long{};
  EXPECT_EQ(rig.mock.readBlock(0x3B, too_long), -EINVAL);
  EXPECT_EQ(rig.mock.readBlock(0x3B, std::span<std::uint8_t>()), -EINVAL);

  MockMpu6050Config config = Rig::quietConfig();
  config.max_burst_length = 1024;  // an I2C_RDWR adapter
  Rig rdwr(source, config);
  std::vector<std::uint8_t> long_read(1024);
  EXPECT_EQ(rdwr.mock.readBlock(A(Register::FIFO_R_W), long_read), 0);
}

TEST(MockMpu6050Registers, FifoCountLowAloneReturnsTheValueLatchedByTheHighRead) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  write(rig.mock, Register::FIFO_EN, mpu6050::XG_FIFO_EN | mpu6050::YG_FIFO_EN | mpu6050::ZG_FIFO_EN);
  write(rig.mock, Register::USER_CTRL, mpu6050::USER_CTRL_BIT::FIFO_EN);
  rig.wake(1, 0);
  rig.advance(10 * kNsPerMillisecond);  // 10 frames of 6 bytes
  EXPECT_EQ(read(rig.mock, Register::FIFO_COUNTH), 0);
  EXPECT_EQ(read(rig.mock, Register::FIFO_COUNTL), 60);
  rig.advance(10 * kNsPerMillisecond);
  EXPECT_EQ(read(rig.mock, Register::FIFO_COUNTL), 60);  // stale: H not read (RM §4.30)
  EXPECT_EQ(read(rig.mock, Register::FIFO_COUNTH), 0);
  EXPECT_EQ(read(rig.mock, Register::FIFO_COUNTL), 120);
}

TEST(MockMpu6050Registers, SelfClearingBitsReadBackAsZero) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  write(rig.mock, Register::USER_CTRL, mpu6050::USER_CTRL_BIT::FIFO_EN | mpu6050::FIFO_RESET | mpu6050::SIG_COND_RESET);
  EXPECT_EQ(read(rig.mock, Register::USER_CTRL), mpu6050::USER_CTRL_BIT::FIFO_EN);
  write(rig.mock, Register::SIGNAL_PATH_RESET, 0x07);
  EXPECT_EQ(read(rig.mock, Register::SIGNAL_PATH_RESET), 0x00);
}

TEST(MockMpu6050Registers, BadConfigurationIsRejected) {
  ConstantSource source({0, 0, 0});
  VirtualClock clock;
  MockMpu6050Config c;
  c.clock_error_ppm = 200'000;
  EXPECT_THROW(MockMpu6050(clock, source, c), std::invalid_argument);
  c = {};
  c.address = 0x80;
  EXPECT_THROW(MockMpu6050(clock, source, c), std::invalid_argument);
  c = {};
  c.max_burst_length = 0;
  EXPECT_THROW(MockMpu6050(clock, source, c), std::invalid_argument);
  c = {};
  c.data_ready_queue_depth = 0;
  EXPECT_THROW(MockMpu6050(clock, source, c), std::invalid_argument);
  EXPECT_THROW(clock.advanceNs(-1), std::invalid_argument);
}

TEST(MockMpu6050Registers, WordReadsAreNotLimitedByTheBurstLength) {
  ConstantSource source({0, 0, 0});
  MockMpu6050Config config = Rig::quietConfig();
  config.max_burst_length = 1;  // an adapter with byte and word transfers only
  Rig rig(source, config);
  std::uint16_t w = 0;
  EXPECT_EQ(rig.mock.readWordBigEndian(A(Register::PWR_MGMT_1), w), 0);
  EXPECT_EQ(w, 0x4000);  // PWR_MGMT_1 = 0x40, PWR_MGMT_2 = 0x00
  std::array<std::uint8_t, 2> two{};
  EXPECT_EQ(rig.mock.readBlock(A(Register::PWR_MGMT_1), two), -EINVAL);
}

TEST(MockMpu6050Registers, BurstAcrossIntStatusAndOutputsClearsTheStatusOnce) {
  // A common driver pattern: one 15-byte burst from INT_STATUS through GYRO_ZOUT_L.
  ConstantSource source({-10.0, 0.0, 0.0});
  Rig rig(source);
  write(rig.mock, Register::INT_ENABLE, mpu6050::DATA_RDY_EN);
  rig.wake(7, 0);
  rig.advance(kNsPerMillisecond);
  std::array<std::uint8_t, 15> b{};
  ASSERT_EQ(rig.mock.readBlock(A(Register::INT_STATUS), b), 0);
  EXPECT_EQ(b[0], mpu6050::DATA_RDY_INT);
  EXPECT_EQ(be16(b[9], b[10]), -1310);  // GYRO_XOUT at offset 0x43 − 0x3A = 9
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS), 0x00);
}

}  // namespace
}  // namespace gyrod::driver::test
