#include "driver/fifo_frame.hpp"

#include <cstdlib>
#include <cstring>
#include <limits>

namespace gyrod::driver {

namespace {
// The temperature and gyro words, which both frame layouts carry under the same names.
template <typename RawFrame>
FifoFrame decodeTempGyro(const RawFrame& raw) {
  FifoFrame frame;
  frame.temp = mpu6050::combineBigEndian(raw.TEMP_OUT_H, raw.TEMP_OUT_L);
  frame.gyro = {mpu6050::combineBigEndian(raw.GYRO_XOUT_H, raw.GYRO_XOUT_L),
                mpu6050::combineBigEndian(raw.GYRO_YOUT_H, raw.GYRO_YOUT_L),
                mpu6050::combineBigEndian(raw.GYRO_ZOUT_H, raw.GYRO_ZOUT_L)};
  return frame;
}
}  // namespace

FifoFrame decodeFifoFrame(std::span<const std::uint8_t, kFrameBytes> bytes) {
  mpu6050::fifo::TempGyroFrame raw;
  std::memcpy(&raw, bytes.data(), sizeof raw);
  return decodeTempGyro(raw);
}

FifoFrame decodeFifoFrame(std::span<const std::uint8_t, kAccelFrameBytes> bytes) {
  mpu6050::fifo::FullFrame raw;
  std::memcpy(&raw, bytes.data(), sizeof raw);
  FifoFrame frame = decodeTempGyro(raw);
  frame.has_accel = true;
  frame.accel = {mpu6050::combineBigEndian(raw.ACCEL_XOUT_H, raw.ACCEL_XOUT_L),
                 mpu6050::combineBigEndian(raw.ACCEL_YOUT_H, raw.ACCEL_YOUT_L),
                 mpu6050::combineBigEndian(raw.ACCEL_ZOUT_H, raw.ACCEL_ZOUT_L)};
  return frame;
}

std::optional<std::size_t> firstMisalignedFrame(const FifoFrames& frames, std::int16_t temp_out,
                                                std::int16_t bound_lsb) {
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (std::abs(static_cast<int>(frames[i].temp) - static_cast<int>(temp_out)) > bound_lsb) return i;
  }
  return std::nullopt;
}

void convertFifoFrame(const FifoFrame& frame, double gyro_lsb_per_dps, GyroSample& sample, double accel_lsb_per_g) {
  sample.raw_temp = frame.temp;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    sample.raw_gyro[axis] = frame.gyro[axis];
    sample.rate_dps[axis] = static_cast<double>(frame.gyro[axis]) / gyro_lsb_per_dps;
  }
  sample.temp_c = mpu6050::temperatureDegCFromRaw(frame.temp);
  for (std::size_t axis = 0; axis < 3; ++axis) {
    sample.raw_accel[axis] = frame.has_accel ? frame.accel[axis] : std::int16_t{0};
    sample.accel_g[axis] = frame.has_accel ? static_cast<double>(frame.accel[axis]) / accel_lsb_per_g
                                           : std::numeric_limits<double>::quiet_NaN();
  }
}

}  // namespace gyrod::driver
