#pragma once
// Decoding the MPU6050's FIFO as gyrod's driver fills it: pure functions over bytes, no bus,
// no state. The frame layout is mpu6050::fifo::TempGyroFrame (FIFO_EN = TEMP | XG | YG | ZG);
// the byte positions of the words live in that struct and nowhere else.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "driver/mpu6050_registers.hpp"
#include "driver/mpu6050_types.hpp"

namespace gyrod::driver {

// FIFO_EN for the driver's frames: temperature first (the sync marker), then gyro X, Y, Z.
inline constexpr std::uint8_t kFifoEnable =
    mpu6050::TEMP_FIFO_EN | mpu6050::XG_FIFO_EN | mpu6050::YG_FIFO_EN | mpu6050::ZG_FIFO_EN;
inline constexpr std::size_t kFrameBytes = sizeof(mpu6050::fifo::TempGyroFrame);
static_assert(mpu6050::fifo::frameSize(kFifoEnable) == kFrameBytes);

// One frame's words, sign-extended from the chip's big-endian two's complement.
struct FifoFrame {
  std::int16_t temp = 0;
  std::array<std::int16_t, 3> gyro{};  // x, y, z
};

// The frame in `bytes` (exactly kFrameBytes, as read from FIFO_R_W).
FifoFrame decodeFifoFrame(std::span<const std::uint8_t, kFrameBytes> bytes);

// A burst of whole frames, read-only. The bytes must outlive the view.
class FifoFrames {
 public:
  // `bytes.size()` must be a multiple of kFrameBytes (a trailing partial frame is ignored).
  explicit FifoFrames(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  std::size_t size() const { return bytes_.size() / kFrameBytes; }
  FifoFrame operator[](std::size_t index) const {
    return decodeFifoFrame(bytes_.subspan(index * kFrameBytes).first<kFrameBytes>());
  }

 private:
  std::span<const std::uint8_t> bytes_;
};

// The first frame whose temperature word is more than `bound_lsb` away from TEMP_OUT (the
// newest sample's temperature), or nullopt when every frame passes. A frame boundary in
// the wrong place puts a gyro word where the temperature belongs, which almost never agrees.
std::optional<std::size_t> firstMisalignedFrame(const FifoFrames& frames, std::int16_t temp_out,
                                                std::int16_t bound_lsb);

// Fills the measured fields of `sample` (raw words, °/s, °C) from a frame; seq and t_ns
// are left as they are. `gyro_lsb_per_dps` is mpu6050::kGyroLsbPerDps[FS_SEL].
void convertFifoFrame(const FifoFrame& frame, double gyro_lsb_per_dps, GyroSample& sample);

}  // namespace gyrod::driver
