// What a 32-bit target (armhf: 32-bit size_t and long) or an ARM one (unsigned char,
// strict-alignment history) would break first, checked on every target: register words keep
// their sign, frames are packed bytes decoded at any offset, and sequence numbers and
// timestamps stay 64-bit past 2^32 samples and 2^32 ns. scripts/cross-test.sh runs these
// under qemu-user for arm64 and armhf; they run natively too.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "driver/counter_names.hpp"
#include "driver/fifo_frame.hpp"
#include "driver/mpu6050_registers.hpp"
#include "driver/mpu6050_types.hpp"
#include "driver/sample_clock.hpp"

namespace gyrod::driver {
namespace {

// The frame is 8 packed bytes in register order, whatever the target's alignment rules.
static_assert(sizeof(mpu6050::fifo::TempGyroFrame) == 8);
static_assert(alignof(mpu6050::fifo::TempGyroFrame) == 1);
static_assert(offsetof(mpu6050::fifo::TempGyroFrame, GYRO_XOUT_H) == 2);
static_assert(offsetof(mpu6050::fifo::TempGyroFrame, GYRO_ZOUT_L) == 7);
static_assert(sizeof(mpu6050::fifo::FullFrame) == 14 && alignof(mpu6050::fifo::FullFrame) == 1);

// Counts and times are 64 bits on every target, never size_t or long.
static_assert(sizeof(GyroSample::seq) == 8 && sizeof(GyroSample::t_ns) == 8);
static_assert(sizeof(SampleGap::first_seq) == 8 && sizeof(SampleGap::count) == 8);
static_assert(sizeof(DriverCounters) == kDriverCounterNames.size() * 8);

// The two's-complement value of a big-endian word, computed without casts to int16_t.
int expectedWord(int high, int low) { return high * 256 + low - (high >= 0x80 ? 65536 : 0); }

TEST(WordSizes, EveryRegisterWordKeepsItsSign) {
  int mismatches = 0;
  for (int high = 0; high < 256; ++high) {
    for (int low = 0; low < 256; ++low) {
      const auto h = static_cast<std::uint8_t>(high), l = static_cast<std::uint8_t>(low);
      const int expected = expectedWord(high, low);
      const std::array<std::uint8_t, kFrameBytes> bytes = {h, l, l, h, h, l, 0x00, 0x00};
      const FifoFrame frame = decodeFifoFrame(std::span<const std::uint8_t, kFrameBytes>(bytes));
      GyroSample sample;
      convertFifoFrame(frame, 131.0, sample);
      const bool ok = mpu6050::combineBigEndian(h, l) == expected && frame.temp == expected &&
                      frame.gyro[0] == expectedWord(low, high) && frame.gyro[1] == expected &&
                      sample.raw_gyro[1] == expected && sample.rate_dps[1] == expected / 131.0 &&
                      sample.raw_temp == expected;
      if (!ok && ++mismatches <= 5) ADD_FAILURE() << "bytes " << high << ", " << low << " -> " << frame.temp;
    }
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(WordSizes, FramesDecodeTheSameFromAnyByteOffset) {
  // Three frames with every byte distinct, copied to each offset 0..7 of a larger buffer: a
  // decoder that cast the bytes to a wider type would fault or differ at odd offsets on ARM.
  const std::vector<std::uint8_t> frames = {0x12, 0x34, 0x80, 0x01, 0xFF, 0xFE, 0x7F, 0xFF,  //
                                            0xF0, 0x0D, 0x00, 0x80, 0x81, 0x00, 0x01, 0x02,  //
                                            0xAB, 0xCD, 0xEF, 0x01, 0x23, 0x45, 0x67, 0x89};
  const FifoFrames aligned{std::span<const std::uint8_t>(frames)};
  ASSERT_EQ(aligned.size(), 3u);
  EXPECT_EQ(aligned[0].temp, 0x1234);
  EXPECT_EQ(aligned[0].gyro[0], -32767);
  EXPECT_EQ(aligned[1].gyro[1], -32512);  // 0x8100
  EXPECT_EQ(aligned[2].gyro[2], 0x6789);
  for (std::size_t offset = 0; offset < 8; ++offset) {
    std::vector<std::uint8_t> buffer(offset, 0xEE);
    buffer.insert(buffer.end(), frames.begin(), frames.end());
    const FifoFrames shifted{std::span<const std::uint8_t>(buffer).subspan(offset)};
    ASSERT_EQ(shifted.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(shifted[i].temp, aligned[i].temp) << offset;
      EXPECT_EQ(shifted[i].gyro, aligned[i].gyro) << offset;
    }
  }
}

TEST(WordSizes, SampleClockStaysExactPast2To32SamplesAndLongUptimes) {
  // Fifty days of uptime (4.3e15 ns) and sequence numbers around 2^32: past what a 32-bit
  // size_t or long holds, within what an int64 ns and a uint64 sequence number hold exactly.
  const std::uint64_t n0 = (std::uint64_t{1} << 32) - 100;
  const std::int64_t t0 = std::int64_t{50} * 86400 * 1'000'000'000;
  const double p_true = 1e6 * 1.02;  // a 1 kHz chip 2 % slow
  SampleClockConfig config;
  config.nominal_period_ns = 1e6;
  config.observation_tolerance_ns = 2e5;
  SampleClock clock(config);
  for (std::uint64_t k = 0; k <= 300; ++k) {
    clock.observe(t0 + static_cast<std::int64_t>(std::llround(static_cast<double>(k) * p_true)), n0 + k);
  }
  EXPECT_NEAR(clock.periodNs(), p_true, 1e-3);
  for (std::uint64_t k : {100u, 300u, 1000u}) {
    const double expected = static_cast<double>(t0) + static_cast<double>(k) * p_true;
    EXPECT_NEAR(static_cast<double>(clock.timeOf(n0 + k)), expected, 2.0) << k;
  }
  const auto past = t0 + static_cast<std::int64_t>(std::llround(205.0 * p_true));
  EXPECT_EQ(clock.nearestIndexOfObservation(past), static_cast<std::int64_t>(n0 + 205));
  EXPECT_EQ(clock.rejections(), 0u);
}

TEST(WordSizes, EveryCounterHoldsValuesPast2To32) {
  DriverCounters counters;
  std::uint64_t value = std::uint64_t{1} << 32;
  for (const auto& c : kDriverCounterNames) counters.*c.member = value++;
  value = std::uint64_t{1} << 32;
  for (const auto& c : kDriverCounterNames) EXPECT_EQ(counters.*c.member, value++) << c.name;
}

}  // namespace
}  // namespace gyrod::driver
