#pragma once
// Recordings of the ImuCalibration logger (github.com/tomisuarez2/ImuCalibration, an MPU6050
// on an Arduino), which `gyroctl import` converts into gyrod's CSV. Header lines "Fs,<Hz>",
// "Logging Type,<n>", "Initialization time,<s>", "Waiting time,<s>", then the column names
// (ax,ay,az,gx,gy,gz), then one line per sample of raw signed 16-bit counts. No timestamps:
// t = i / Fs (the chip's sample clock).
#include <cstddef>
#include <iosfwd>
#include <string>

namespace gyrod::recording {

// Gyro sensitivity per FS_SEL (MPU-6050 product specification §6.1): LSB per °/s.
inline constexpr double kGyroLsbPerDps[4] = {131.0, 65.5, 32.8, 16.4};

struct ImucalConversion {
  std::string csv;  // header t and the gyro columns present, then one line per sample in °/s
  std::size_t samples = 0;
  double rate_hz = 0.0;      // the file's Fs
  double lsb_per_dps = 0.0;  // kGyroLsbPerDps[fs_sel]
};

// Reads the whole logger file from `in` (`path` names it in messages) at full scale `fs_sel`
// (0..3; std::invalid_argument otherwise). Throws RecordingError "FILE:LINE: cause" (or "FILE: empty file").
ImucalConversion convertImucal(std::istream& in, const std::string& path, int fs_sel);

}  // namespace gyrod::recording
