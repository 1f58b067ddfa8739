#pragma once
// What a Mpu6050Config means for the chip: whether it is usable, the sample-rate rule
// (SMPLRT_DIV), the register table the driver writes and checks, and the derived periods.
// Pure functions; the daemon's config loader uses the same sample-rate rule.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "driver/mpu6050_registers.hpp"
#include "driver/mpu6050_types.hpp"

namespace gyrod::driver {

// Clones answering 0x70 are MPU-6500 cores, whose FIFO is 512 bytes (MPU-6500 product
// specification); for any clone the smaller size is assumed, so overflow is never missed.
inline constexpr std::size_t kCloneFifoSize = 512;

// The sample-rate rule (RM §4.2 p.11): sample rate = gyro output rate / (1 + SMPLRT_DIV),
// SMPLRT_DIV 0..255, the output rate being 8 kHz with DLPF_CFG 0 (or 7), else 1 kHz.
// Returns the SMPLRT_DIV that gives `rate_hz` exactly, or nullopt when no value does.
// Inline so that the daemon's config loader can apply it without linking the driver.
inline std::optional<std::uint8_t> smplrtDivFor(int dlpf_cfg, double rate_hz) {
  if (!std::isfinite(rate_hz) || rate_hz <= 0.0) return std::nullopt;
  const double n = mpu6050::gyroOutputRateHz(dlpf_cfg) / rate_hz;
  const double rounded = std::round(n);
  if (rounded < 1.0 || rounded > 256.0 || std::fabs(n - rounded) > 1e-9 * n) return std::nullopt;
  return static_cast<std::uint8_t>(rounded - 1.0);
}

// AFS_SEL for an accel full-scale range of ±range_g (2, 4, 8, 16 → 0..3; product spec §6.2),
// or nullopt for any other range.
constexpr std::optional<int> afsSelForRangeG(int range_g) {
  for (int afs = 0; afs < 4; ++afs)
    if (range_g == (2 << afs)) return afs;
  return std::nullopt;
}

// Throws std::invalid_argument naming the field and value when a config is unusable.
void validateConfig(const Mpu6050Config& config);

// SMPLRT_DIV for the configured rate: internal rate / (1 + div) = rate exactly. Throws
// std::invalid_argument when dlpf_cfg or sample_rate_hz is unusable.
std::uint8_t sampleRateDivider(const Mpu6050Config& config);

// Nominal sample period in ns.
double nominalSamplePeriodNs(const Mpu6050Config& config);

// A poll period for DataReadyMode::Polling that cannot lose samples: a quarter of the time
// the FIFO (the smaller capacity of clones assumed) takes to fill at the fastest plausible
// chip clock, at most 100 ms and at least 1 ms; and short enough that one wake-up's
// backlog cap drains more than a poll period brings.
std::int64_t pollingPeriodNs(const Mpu6050Config& config);

// WHO_AM_I values the driver accepts: the genuine part, and those the clones sold as
// MPU6050 are known to answer (accepted with a warning).
bool isGenuineWhoAmI(std::uint8_t value);
bool isKnownCloneWhoAmI(std::uint8_t value);

// One line of the register table: after configuration, (value & set) == set and
// (value & clear) == 0. Configure writes `set`; the read-back checks both masks.
struct RegisterSetting {
  mpu6050::Register reg;
  std::uint8_t set;
  std::uint8_t clear;

  bool matches(std::uint8_t value) const { return (value & set) == set && (value & clear) == 0; }
};
// Entries without accel; with accel ACCEL_CONFIG is one more.
inline constexpr std::size_t kRegisterTableSize = 9;

// The table for a configuration, in the order it is written (exposed for tests and for
// `gyroctl` diagnostics). Throws std::invalid_argument for an invalid config.
std::vector<RegisterSetting> registerTableFor(const Mpu6050Config& config);

}  // namespace gyrod::driver
