#pragma once
// Decoding the MPU6050's FIFO as gyrod's driver fills it: pure functions over bytes, no bus,
// no state. Two layouts: mpu6050::fifo::TempGyroFrame (FIFO_EN = TEMP | XG | YG | ZG, 8 bytes,
// accel off) and mpu6050::fifo::FullFrame (FIFO_EN adds ACCEL, 14 bytes: accel X, Y, Z, TEMP,
// gyro X, Y, Z in register order, RM §4.31). The byte positions live in those structs only.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "driver/mpu6050_registers.hpp"
#include "driver/mpu6050_types.hpp"

namespace gyrod::driver {

// FIFO_EN for the driver's frames without accel: temperature first (the sync marker), then
// gyro X, Y, Z.
inline constexpr std::uint8_t kFifoEnable =
    mpu6050::TEMP_FIFO_EN | mpu6050::XG_FIFO_EN | mpu6050::YG_FIFO_EN | mpu6050::ZG_FIFO_EN;
inline constexpr std::size_t kFrameBytes = sizeof(mpu6050::fifo::TempGyroFrame);
static_assert(mpu6050::fifo::frameSize(kFifoEnable) == kFrameBytes);
// With accel: accel X, Y, Z, then the same temperature and gyro words.
inline constexpr std::uint8_t kFifoEnableWithAccel = kFifoEnable | mpu6050::ACCEL_FIFO_EN;
inline constexpr std::size_t kAccelFrameBytes = sizeof(mpu6050::fifo::FullFrame);
static_assert(mpu6050::fifo::frameSize(kFifoEnableWithAccel) == kAccelFrameBytes);

constexpr std::uint8_t fifoEnableFor(bool accel) { return accel ? kFifoEnableWithAccel : kFifoEnable; }
constexpr std::size_t frameBytesFor(bool accel) { return accel ? kAccelFrameBytes : kFrameBytes; }

// One frame's words, sign-extended from the chip's big-endian two's complement.
struct FifoFrame {
  std::int16_t temp = 0;
  std::array<std::int16_t, 3> gyro{};   // x, y, z
  bool has_accel = false;               // the frame carried accel words
  std::array<std::int16_t, 3> accel{};  // x, y, z (zero when !has_accel)
};

// The frame in `bytes` (exactly one frame, as read from FIFO_R_W).
FifoFrame decodeFifoFrame(std::span<const std::uint8_t, kFrameBytes> bytes);
FifoFrame decodeFifoFrame(std::span<const std::uint8_t, kAccelFrameBytes> bytes);

// A burst of whole frames, read-only. The bytes must outlive the view.
class FifoFrames {
 public:
  // `frame_bytes` is kFrameBytes or kAccelFrameBytes; `bytes.size()` should be a multiple of
  // it (a trailing partial frame is ignored).
  explicit FifoFrames(std::span<const std::uint8_t> bytes, std::size_t frame_bytes = kFrameBytes)
      : bytes_(bytes), frame_bytes_(frame_bytes == kAccelFrameBytes ? kAccelFrameBytes : kFrameBytes) {}
  std::size_t size() const { return bytes_.size() / frame_bytes_; }
  std::size_t frameBytes() const { return frame_bytes_; }
  FifoFrame operator[](std::size_t index) const {
    const std::span<const std::uint8_t> at = bytes_.subspan(index * frame_bytes_);
    if (frame_bytes_ == kAccelFrameBytes) return decodeFifoFrame(at.first<kAccelFrameBytes>());
    return decodeFifoFrame(at.first<kFrameBytes>());
  }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t frame_bytes_;
};

// The first frame whose temperature word is more than `bound_lsb` away from TEMP_OUT (the
// newest sample's temperature), or nullopt when every frame passes. A frame boundary in
// the wrong place puts a gyro (or accel) word where the temperature belongs, which almost
// never agrees. With accel the temperature word sits at byte 6 of the 14, between the accel
// and the gyro words; the check is the same.
std::optional<std::size_t> firstMisalignedFrame(const FifoFrames& frames, std::int16_t temp_out,
                                                std::int16_t bound_lsb);

// Fills the measured fields of `sample` (raw words, °/s, °C, g) from a frame; seq, t_ns and
// wall_ns are left as they are. `gyro_lsb_per_dps` is mpu6050::kGyroLsbPerDps[FS_SEL],
// `accel_lsb_per_g` mpu6050::kAccelLsbPerG[AFS_SEL]. A frame without accel sets accel_g to
// NaN and raw_accel to 0.
void convertFifoFrame(const FifoFrame& frame, double gyro_lsb_per_dps, GyroSample& sample,
                      double accel_lsb_per_g = mpu6050::kAccelLsbPerG[0]);

}  // namespace gyrod::driver
