#pragma once
// Recordings of the ImuCalibration logger (github.com/tomisuarez2/ImuCalibration, an MPU6050
// on an Arduino), which `gyroctl import` converts into gyrod's CSV. Header lines "Fs,<Hz>",
// "Logging Type,<n>", "Initialization time,<s>", "Waiting time,<s>", then the column names
// (ax,ay,az,gx,gy,gz), then one line per sample of raw signed 16-bit counts. No timestamps:
// t = i / Fs (the chip's sample clock). The logger's firmware keeps the MPU6050 library's
// defaults, ±250 °/s and ±2 g (FS_SEL = AFS_SEL = 0); its static files agree: |a| ≈ 14,900
// counts, 0.91 g at 16,384 LSB per g (an uncalibrated chip), where ±4 g would give 1.8 g.
#include <cstddef>
#include <iosfwd>
#include <string>

namespace gyrod::recording {

// Gyro sensitivity per FS_SEL (MPU-6050 product specification §6.1): LSB per °/s.
inline constexpr double kGyroLsbPerDps[4] = {131.0, 65.5, 32.8, 16.4};

// Accelerometer sensitivity per AFS_SEL (MPU-6050 product specification §6.2): LSB per g.
inline constexpr double kAccelLsbPerG[4] = {16384.0, 8192.0, 4096.0, 2048.0};

struct ImucalConversion {
  // Header t, the gyro columns present (°/s), then the accelerometer columns present (g),
  // then one line per sample.
  std::string csv;
  std::size_t samples = 0;
  double rate_hz = 0.0;      // the file's Fs
  double lsb_per_dps = 0.0;  // kGyroLsbPerDps[fs_sel]
  double lsb_per_g = 0.0;    // kAccelLsbPerG[afs_sel]
  std::size_t accel_columns = 0;
};

// Reads the whole logger file from `in` (`path` names it in messages) at gyro full scale
// `fs_sel` and accelerometer full scale `afs_sel` (each 0..3; std::invalid_argument
// otherwise). Throws RecordingError "FILE:LINE: cause" (or "FILE: empty file").
ImucalConversion convertImucal(std::istream& in, const std::string& path, int fs_sel, int afs_sel = 0);

}  // namespace gyrod::recording
