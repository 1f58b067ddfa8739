// Decoding FIFO bytes into frames: big-endian words with their sign, the frame layout
// (temperature, then gyro X, Y, Z), the alignment check and the conversion to °/s and °C.
#include "driver/fifo_frame.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace gyrod::driver::test {
namespace {

using Bytes = std::array<std::uint8_t, kFrameBytes>;

FifoFrame decode(const Bytes& bytes) { return decodeFifoFrame(std::span<const std::uint8_t, kFrameBytes>(bytes)); }

TEST(FifoFrame, TheDriversFrameIsTemperatureThenGyroEightBytes) {
  EXPECT_EQ(kFrameBytes, 8u);
  EXPECT_EQ(kFifoEnable, 0xF0);
}

TEST(FifoFrame, WordsAreBigEndianInRegisterOrder) {
  const FifoFrame f = decode({0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08});
  EXPECT_EQ(f.temp, 0x0102);
  EXPECT_EQ(f.gyro[0], 0x0304);
  EXPECT_EQ(f.gyro[1], 0x0506);
  EXPECT_EQ(f.gyro[2], 0x0708);
}

TEST(FifoFrame, NegativeWordsAreSignExtended) {
  const FifoFrame f = decode({0xFF, 0xFF, 0xFF, 0xFE, 0xFE, 0xD4, 0x80, 0x01});
  EXPECT_EQ(f.temp, -1);
  EXPECT_EQ(f.gyro[0], -2);
  EXPECT_EQ(f.gyro[1], -300);  // 0xFED4
  EXPECT_EQ(f.gyro[2], -32767);
}

TEST(FifoFrame, ExtremesDecodeToInt16MinAndMax) {
  const FifoFrame f = decode({0x80, 0x00, 0x7F, 0xFF, 0x80, 0x00, 0x00, 0x00});
  EXPECT_EQ(f.temp, INT16_MIN);
  EXPECT_EQ(f.gyro[0], INT16_MAX);
  EXPECT_EQ(f.gyro[1], -32768);
  EXPECT_EQ(f.gyro[2], 0);
  // The low byte never carries the sign: 0x00FF is +255, not −1.
  EXPECT_EQ(decode({0x00, 0xFF, 0, 0, 0, 0, 0, 0}).temp, 255);
}

TEST(FifoFrame, FramesIndexWholeFramesAndIgnoreATrailingPartialOne) {
  const std::vector<std::uint8_t> bytes = {0x00, 0x01, 0, 0, 0, 0, 0, 0,     // frame 0
                                           0x00, 0x02, 0, 0, 0, 0, 0, 0x09,  // frame 1
                                           0x00, 0x03, 0};                   // partial
  const FifoFrames frames{std::span<const std::uint8_t>(bytes)};
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].temp, 1);
  EXPECT_EQ(frames[1].temp, 2);
  EXPECT_EQ(frames[1].gyro[2], 9);
}

TEST(FifoFrame, AlignmentCheckFindsTheFirstFrameOutsideTheBound) {
  // TEMP_OUT −3400 (26.53 °C); bound 340 LSB (1 °C).
  const std::vector<std::uint8_t> bytes = {
      0xF2, 0xB8, 0, 0, 0, 0, 0, 0,  // −3400: equal
      0xF4, 0x0C, 0, 0, 0, 0, 0, 0,  // −3060: exactly at the bound, passes
      0x12, 0x34, 0, 0, 0, 0, 0, 0,  // a gyro word where the temperature belongs
      0xF2, 0xB8, 0, 0, 0, 0, 0, 0,
  };
  const FifoFrames frames{std::span<const std::uint8_t>(bytes)};
  EXPECT_EQ(firstMisalignedFrame(frames, -3400, 340), std::optional<std::size_t>(2));
  const FifoFrames first_two{std::span<const std::uint8_t>(bytes).first(2 * kFrameBytes)};
  EXPECT_EQ(firstMisalignedFrame(first_two, -3400, 340), std::nullopt);
  EXPECT_EQ(firstMisalignedFrame(first_two, -3400, 339), std::optional<std::size_t>(1));
}

TEST(FifoFrame, ConversionToDegreesPerSecondAndCelsius) {
  GyroSample s;
  s.seq = 7;
  s.t_ns = 123;
  FifoFrame f;
  f.temp = -3400;
  f.gyro = {131, INT16_MIN, INT16_MAX};
  convertFifoFrame(f, 131.0, s);
  EXPECT_EQ(s.seq, 7u);  // untouched
  EXPECT_EQ(s.t_ns, 123);
  EXPECT_EQ(s.raw_temp, -3400);
  EXPECT_EQ(s.raw_gyro[0], 131);
  EXPECT_EQ(s.raw_gyro[1], INT16_MIN);
  EXPECT_EQ(s.raw_gyro[2], INT16_MAX);
  EXPECT_EQ(s.rate_dps[0], 1.0);
  EXPECT_EQ(s.rate_dps[1], -32768.0 / 131.0);
  EXPECT_EQ(s.rate_dps[2], 32767.0 / 131.0);
  // RM Registers 65–66: °C = TEMP_OUT / 340 + 36.53.
  EXPECT_DOUBLE_EQ(s.temp_c, 26.53);
  f.temp = 0;
  convertFifoFrame(f, 16.4, s);
  EXPECT_DOUBLE_EQ(s.temp_c, 36.53);
  EXPECT_EQ(s.rate_dps[0], 131.0 / 16.4);
  f.temp = 340;
  convertFifoFrame(f, 16.4, s);
  EXPECT_DOUBLE_EQ(s.temp_c, 37.53);
}

TEST(FifoFrame, WithAccelTheFrameIsAccelTemperatureGyroFourteenBytes) {
  EXPECT_EQ(kAccelFrameBytes, 14u);
  EXPECT_EQ(kFifoEnableWithAccel, 0xF8);
  EXPECT_EQ(fifoEnableFor(false), kFifoEnable);
  EXPECT_EQ(frameBytesFor(true), kAccelFrameBytes);
  // Registers 0x3B..0x48 in order: ACCEL_X, ACCEL_Y, ACCEL_Z, TEMP, GYRO_X, GYRO_Y, GYRO_Z.
  const std::array<std::uint8_t, kAccelFrameBytes> bytes = {0x40, 0x00, 0xFF, 0xFE, 0xC0, 0x00, 0xF2,
                                                            0xB8, 0x00, 0x83, 0xFF, 0x7D, 0x80, 0x00};
  const FifoFrame f = decodeFifoFrame(std::span<const std::uint8_t, kAccelFrameBytes>(bytes));
  EXPECT_TRUE(f.has_accel);
  EXPECT_EQ(f.accel[0], 16384);
  EXPECT_EQ(f.accel[1], -2);
  EXPECT_EQ(f.accel[2], -16384);
  EXPECT_EQ(f.temp, -3400);
  EXPECT_EQ(f.gyro[0], 131);
  EXPECT_EQ(f.gyro[1], -131);
  EXPECT_EQ(f.gyro[2], INT16_MIN);
  EXPECT_FALSE(decode({0, 0, 0, 0, 0, 0, 0, 0}).has_accel);
}

TEST(FifoFrame, ConversionOfAccelIsExactAtTheGivenScaleAndNaNWithout) {
  FifoFrame f;
  f.has_accel = true;
  f.accel = {16384, -8192, INT16_MIN};
  GyroSample s;
  convertFifoFrame(f, 131.0, s, 16384.0);
  EXPECT_EQ(s.accel_g[0], 1.0);
  EXPECT_EQ(s.accel_g[1], -0.5);
  EXPECT_EQ(s.accel_g[2], -2.0);
  EXPECT_EQ(s.raw_accel[2], INT16_MIN);
  convertFifoFrame(f, 131.0, s, 2048.0);
  EXPECT_EQ(s.accel_g[0], 8.0);
  EXPECT_EQ(s.accel_g[2], -16.0);
  f.has_accel = false;
  convertFifoFrame(f, 131.0, s);
  EXPECT_TRUE(std::isnan(s.accel_g[0]) && std::isnan(s.accel_g[1]) && std::isnan(s.accel_g[2]));
  EXPECT_EQ(s.raw_accel, (std::array<std::int16_t, 3>{}));
}

TEST(FifoFrame, AlignmentCheckOnLongFramesFindsAShiftedBoundary) {
  // Two 14-byte frames of a level board at 26.53 °C (TEMP_OUT −3400): accel (0, 0, 1 g).
  std::vector<std::uint8_t> bytes;
  for (int k = 0; k < 3; ++k) {
    const std::vector<std::uint8_t> frame = {0x00, 0x00, 0x00, 0x01, 0x40, 0x00, 0xF2,
                                             0xB8, 0x00, 0x02, 0xFF, 0xFE, 0x00, 0x05};
    bytes.insert(bytes.end(), frame.begin(), frame.end());
  }
  const FifoFrames aligned{std::span<const std::uint8_t>(bytes), kAccelFrameBytes};
  ASSERT_EQ(aligned.size(), 3u);
  EXPECT_EQ(aligned[1].accel[2], 16384);
  EXPECT_EQ(firstMisalignedFrame(aligned, -3400, 340), std::nullopt);
  // One word lost at the start: ACCEL_Z's word lands where TEMP belongs, and TEMP where GYRO_X was.
  for (std::size_t shift : {1u, 2u, 4u, 6u, 8u}) {
    const FifoFrames shifted{std::span<const std::uint8_t>(bytes).subspan(shift), kAccelFrameBytes};
    EXPECT_EQ(firstMisalignedFrame(shifted, -3400, 340), std::optional<std::size_t>(0)) << "shift " << shift;
  }
}

}  // namespace
}  // namespace gyrod::driver::test
