// The mock's FIFO: frame order for FIFO_EN combinations, FIFO_COUNT, overflow at 1024
// bytes with the oldest bytes overwritten, FIFO_RESET and reading an empty FIFO.
#include <gtest/gtest.h>

#include <cerrno>
#include <deque>

#include "driver/mock/mock_signal_source.hpp"
#include "tests/driver/mock_rig.hpp"

namespace gyrod::driver::test {
namespace {

namespace m = mpu6050;

// Known register contents with DLPF bypassed, FS_SEL 0, AFS_SEL 0, no accel noise:
//   gyro (10, −20, 30) °/s → (1310, −2620, 3930); accel (0, 0, 1 g) → (0, 0, 16384);
//   25 °C → round((25 − 36.53) · 340) = round(−3920.2) = −3920.
constexpr std::int16_t kGyro[3] = {1310, -2620, 3930};
constexpr std::int16_t kAccel[3] = {0, 0, 16384};
constexpr std::int16_t kTemp = -3920;

void appendBigEndian(std::vector<std::uint8_t>& out, std::int16_t v) {
  out.push_back(static_cast<std::uint8_t>(static_cast<std::uint16_t>(v) >> 8));
  out.push_back(static_cast<std::uint8_t>(static_cast<std::uint16_t>(v) & 0xFF));
}

// The datasheet's order written out plainly: accel X, Y, Z, then TEMP, then gyro X, Y, Z.
std::vector<std::uint8_t> expectedFrame(std::uint8_t fifo_en) {
  std::vector<std::uint8_t> f;
  if (fifo_en & 0x08)
    for (std::int16_t a : kAccel) appendBigEndian(f, a);
  if (fifo_en & 0x80) appendBigEndian(f, kTemp);
  if (fifo_en & 0x40) appendBigEndian(f, kGyro[0]);
  if (fifo_en & 0x20) appendBigEndian(f, kGyro[1]);
  if (fifo_en & 0x10) appendBigEndian(f, kGyro[2]);
  return f;
}

struct FifoRig : Rig {
  explicit FifoRig(SignalSource& s, MockMpu6050Config c = quietConfig()) : Rig(s, c) {}
  void start(std::uint8_t fifo_en, std::uint8_t int_enable = 0) {
    write(mock, Register::FIFO_EN, fifo_en);
    write(mock, Register::INT_ENABLE, int_enable);
    write(mock, Register::USER_CTRL, m::USER_CTRL_BIT::FIFO_EN | m::FIFO_RESET);
    wake(7, 7);  // 8 kHz / 8 = 1 kHz, DLPF bypassed
  }
};

class FifoOrder : public ::testing::TestWithParam<std::uint8_t> {};

TEST_P(FifoOrder, FramesFollowRegisterOrderOfTheEnabledSensors) {
  const std::uint8_t fifo_en = GetParam();
  ConstantSource source({10.0, -20.0, 30.0}, 25.0);
  FifoRig rig(source);
  rig.start(fifo_en);
  rig.advance(3 * kNsPerMillisecond);  // three samples
  const std::vector<std::uint8_t> frame = expectedFrame(fifo_en);
  ASSERT_EQ(fifoCount(rig.mock), 3 * frame.size());
  const std::vector<std::uint8_t> got = readFifo(rig.mock, 3 * frame.size());
  for (int k = 0; k < 3; ++k) {
    const std::vector<std::uint8_t> one(got.begin() + k * frame.size(), got.begin() + (k + 1) * frame.size());
    EXPECT_EQ(one, frame) << "frame " << k << " with FIFO_EN 0x" << std::hex << int(fifo_en);
  }
  EXPECT_EQ(fifoCount(rig.mock), 0);
  EXPECT_EQ(rig.mock.counters().fifo_frames_written, 3u);
}

INSTANTIATE_TEST_SUITE_P(Combinations, FifoOrder,
                         ::testing::Values(0xF8,    // everything
                                           0xF0,    // temp + gyro (gyrod's layout)
                                           0x70,    // gyro only
                                           0x08,    // accel only
                                           0x80,    // temp only
                                           0x88,    // accel + temp
                                           0x50,    // gyro X and Z
                                           0x20,    // gyro Y
                                           0xA8));  // accel, temp, gyro Y

TEST(MockMpu6050Fifo, NothingIsWrittenUnlessUserCtrlFifoEnIsSet) {
  ConstantSource source({10.0, -20.0, 30.0}, 25.0);
  Rig rig(source);
  write(rig.mock, Register::FIFO_EN, 0xF8);
  rig.wake(7, 7);
  rig.advance(5 * kNsPerMillisecond);
  EXPECT_EQ(fifoCount(rig.mock), 0);
  EXPECT_EQ(rig.mock.counters().samples_produced, 5u);
}

TEST(MockMpu6050Fifo, CountIsBytesAndGrowsByOneFramePerSample) {
  ConstantSource source({10.0, -20.0, 30.0}, 25.0);
  FifoRig rig(source);
  rig.start(0xF8);  // 14-byte frames
  for (int k = 1; k <= 20; ++k) {
    rig.advance(kNsPerMillisecond);
    EXPECT_EQ(fifoCount(rig.mock), 14 * k);
  }
}

TEST(MockMpu6050Fifo, OverflowOverwritesOldestBytesAndSetsTheInterrupt) {
  // 14-byte frames with a changing value so frames can be told apart: the sample index k
  // is the x rate in LSB (a replay of k/131 °/s gives raw k exactly).
  const int n = 100;
  std::vector<double> x(n), zero(n, 0.0), temp(n, 25.0);
  for (int k = 0; k < n; ++k) x[k] = (k + 1) / 131.0;
  // DLPF bypassed at 8 kHz with SMPLRT_DIV 7: each sample takes 8 ticks; the replay
  // repeats each value 8 times so sample k (1-based) carries raw value k.
  std::vector<double> x8, zero8, temp8;
  for (int k = 0; k < n; ++k) {
    for (int t = 0; t < 8; ++t) {
      x8.push_back(x[k]);
      zero8.push_back(0.0);
      temp8.push_back(25.0);
    }
  }
  ReplaySource source(x8, zero8, zero8, temp8, 8000.0);
  FifoRig rig(source);
  rig.start(0xF8, m::FIFO_OFLOW_EN);
  // 73 frames = 1022 bytes fit; the 74th (bytes 1023..1036) overwrites the 12 oldest.
  rig.advance(73 * kNsPerMillisecond);
  EXPECT_EQ(fifoCount(rig.mock), 1022);
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS), 0x00);
  rig.advance(kNsPerMillisecond);
  EXPECT_EQ(fifoCount(rig.mock), 1024);
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS), m::FIFO_OFLOW_INT);
  EXPECT_EQ(rig.mock.counters().fifo_bytes_overwritten, 12u);
  EXPECT_EQ(rig.mock.counters().fifo_overflow_events, 1u);

  // Brute force: the FIFO must hold the last 1024 bytes of the 74 frames' byte stream.
  std::vector<std::uint8_t> stream;
  for (int k = 1; k <= 74; ++k) {
    for (std::int16_t a : kAccel) appendBigEndian(stream, a);
    appendBigEndian(stream, kTemp);
    appendBigEndian(stream, static_cast<std::int16_t>(k));
    appendBigEndian(stream, 0);
    appendBigEndian(stream, 0);
  }
  const std::vector<std::uint8_t> expected(stream.end() - 1024, stream.end());
  const std::vector<std::uint8_t> got = readFifo(rig.mock, 1024);
  EXPECT_EQ(got, expected);
  // 1024 is not a multiple of 14: the first byte read is mid-frame (byte 12 of frame 1).
  EXPECT_NE(1024 % 14, 0);
  EXPECT_EQ(got[0], stream[12]);
}

TEST(MockMpu6050Fifo, FifoResetEmptiesItAndClearsTheOverflowFlag) {
  ConstantSource source({10.0, -20.0, 30.0}, 25.0);
  FifoRig rig(source);
  rig.start(0xF8, m::FIFO_OFLOW_EN);
  rig.advance(80 * kNsPerMillisecond);  // overflowed
  EXPECT_EQ(fifoCount(rig.mock), 1024);
  write(rig.mock, Register::USER_CTRL, m::USER_CTRL_BIT::FIFO_EN | m::FIFO_RESET);
  EXPECT_EQ(fifoCount(rig.mock), 0);
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS) & m::FIFO_OFLOW_INT, 0);
  EXPECT_EQ(rig.mock.counters().fifo_resets, 2u);  // one in start()
  // Frames are aligned again after the reset.
  rig.advance(kNsPerMillisecond);
  EXPECT_EQ(readFifo(rig.mock, 14), expectedFrame(0xF8));
}

TEST(MockMpu6050Fifo, ReadingAnEmptyFifoReturnsTheLastByteRead) {
  // RM §4.31 p.44: "If the FIFO buffer is empty, reading this register will return the
  // last byte that was previously read from the FIFO until new data is available."
  ConstantSource source({10.0, -20.0, 30.0}, 25.0);
  FifoRig rig(source);
  rig.start(0x70);  // gyro only: 05 1E F5 C4 0F 5A
  rig.advance(kNsPerMillisecond);
  const std::vector<std::uint8_t> frame = readFifo(rig.mock, 6);
  ASSERT_EQ(frame, expectedFrame(0x70));
  std::array<std::uint8_t, 4> extra{};
  ASSERT_EQ(rig.mock.readBlock(A(Register::FIFO_R_W), extra), 0);
  for (std::uint8_t b : extra) EXPECT_EQ(b, frame.back());
  EXPECT_EQ(rig.mock.counters().fifo_empty_reads, 4u);
  EXPECT_EQ(rig.mock.counters().fifo_bytes_read, 6u);
}

TEST(MockMpu6050Fifo, BurstFromFifoRwDoesNotAdvanceTheRegisterPointer) {
  ConstantSource source({10.0, -20.0, 30.0}, 25.0);
  FifoRig rig(source);
  rig.start(0xF8);
  rig.advance(2 * kNsPerMillisecond);
  std::array<std::uint8_t, 28> two{};
  ASSERT_EQ(rig.mock.readBlock(A(Register::FIFO_R_W), std::span(two).first(28)), 0);
  std::vector<std::uint8_t> expected = expectedFrame(0xF8);
  const std::vector<std::uint8_t> again = expected;
  expected.insert(expected.end(), again.begin(), again.end());
  EXPECT_TRUE(std::equal(two.begin(), two.end(), expected.begin()));
}

}  // namespace
}  // namespace gyrod::driver::test
