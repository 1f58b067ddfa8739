#include "driver/mpu6050_config.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "driver/fifo_frame.hpp"
#include "driver/i2c_messages.hpp"

namespace gyrod::driver {
namespace {

using mpu6050::Register;
namespace reg = mpu6050;

}  // namespace

// ---------------------------------------------------------------------------------------
// Names

// The one table of gap-cause names: the tokens the daemon publishes on its socket and in
// recordings ([a-z0-9_], docs/protocol.md), and the driver's log lines use the same words.
const char* gapCauseName(GapCause cause) {
  switch (cause) {
    case GapCause::FifoOverflow: return "fifo_overflow";
    case GapCause::MisalignedFrames: return "misaligned_frames";
    case GapCause::TransferError: return "transfer_error";
    case GapCause::DeviceUnreachable: return "device_unreachable";
    case GapCause::SilentReset: return "silent_reset";
    case GapCause::Reinitialised: return "reinitialised";
  }
  return "unknown";
}

const char* deviceStateName(DeviceState state) {
  switch (state) {
    case DeviceState::Probing: return "probing";
    case DeviceState::Configuring: return "configuring";
    case DeviceState::Streaming: return "streaming";
    case DeviceState::Recovering: return "recovering";
    case DeviceState::Failed: return "failed";
  }
  return "unknown";
}

const char* logLevelName(LogLevel level) {
  switch (level) {
    case LogLevel::Debug: return "debug";
    case LogLevel::Info: return "info";
    case LogLevel::Warning: return "warning";
    case LogLevel::Error: return "error";
  }
  return "unknown";
}

// ---------------------------------------------------------------------------------------
// WHO_AM_I

bool isGenuineWhoAmI(std::uint8_t value) { return value == mpu6050::kWhoAmI; }
bool isKnownCloneWhoAmI(std::uint8_t value) { return value == 0x70 || value == 0x72 || value == 0x98; }

// ---------------------------------------------------------------------------------------
// Configuration

std::uint8_t sampleRateDivider(const Mpu6050Config& c) {
  if (!(c.dlpf_cfg >= 0 && c.dlpf_cfg <= 6)) {
    throw std::invalid_argument("Mpu6050Config.dlpf_cfg must be 0..6 (7 is reserved), got " +
                                std::to_string(c.dlpf_cfg));
  }
  if (!std::isfinite(c.sample_rate_hz) || c.sample_rate_hz <= 0.0) {
    throw std::invalid_argument("Mpu6050Config.sample_rate_hz must be finite and > 0, got " +
                                std::to_string(c.sample_rate_hz));
  }
  const std::optional<std::uint8_t> div = smplrtDivFor(c.dlpf_cfg, c.sample_rate_hz);
  if (!div) {
    const double internal = mpu6050::gyroOutputRateHz(c.dlpf_cfg);
    throw std::invalid_argument("Mpu6050Config.sample_rate_hz " + std::to_string(c.sample_rate_hz) + " is not " +
                                std::to_string(static_cast<int>(internal)) + " Hz / n for n = 1..256 (with dlpf_cfg " +
                                std::to_string(c.dlpf_cfg) + "); e.g. 1000, 500, 200, 100, 50, 20, 10 Hz");
  }
  return *div;
}

double nominalSamplePeriodNs(const Mpu6050Config& c) {
  return 1e9 * (1.0 + sampleRateDivider(c)) / mpu6050::gyroOutputRateHz(c.dlpf_cfg);
}

std::int64_t pollingPeriodNs(const Mpu6050Config& c) {
  const double fastest_period = nominalSamplePeriodNs(c) / (1.0 + c.max_clock_error);
  // Whole frames only: a partial frame at the FIFO's end is no sample.
  const double frames =
      static_cast<double>(kCloneFifoSize / frameBytesFor(c.accel));  // NOLINT(bugprone-integer-division)
  double period = std::min(
      {frames * fastest_period / 4.0, 100e6, static_cast<double>(c.max_frames_per_wakeup) * fastest_period / 2.0});
  period = std::max(period, 1e6);
  return static_cast<std::int64_t>(period);
}

void validateConfig(const Mpu6050Config& c) {
  const auto bad = [](const std::string& field, const std::string& why) {
    throw std::invalid_argument("Mpu6050Config." + field + " " + why);
  };
  if (c.address != mpu6050::kI2cAddressAd0Low && c.address != mpu6050::kI2cAddressAd0High) {
    bad("address", "must be 0x68 (AD0 low) or 0x69 (AD0 high), got " + hexByte(c.address));
  }
  (void)sampleRateDivider(c);  // checks dlpf_cfg and sample_rate_hz
  if (c.fs_sel < 0 || c.fs_sel > 3) bad("fs_sel", "must be 0..3, got " + std::to_string(c.fs_sel));
  if (c.afs_sel < 0 || c.afs_sel > 3) bad("afs_sel", "must be 0..3, got " + std::to_string(c.afs_sel));
  if (c.transfer_attempts < 1 || c.transfer_attempts > 10) {
    bad("transfer_attempts", "must be 1..10, got " + std::to_string(c.transfer_attempts));
  }
  const int max_frames = static_cast<int>(mpu6050::fifo::kSize / frameBytesFor(c.accel));
  if (c.max_frames_per_wakeup < 1 || c.max_frames_per_wakeup > max_frames) {
    bad("max_frames_per_wakeup",
        "must be 1.." + std::to_string(max_frames) + ", got " + std::to_string(c.max_frames_per_wakeup));
  }
  if (c.register_check_interval_ns <= 0) bad("register_check_interval_ns", "must be > 0");
  if (!(c.alignment_bound_c > 0.0 && c.alignment_bound_c < 50.0)) {
    bad("alignment_bound_c", "must be within (0, 50) °C, got " + std::to_string(c.alignment_bound_c));
  }
  if (!(c.max_clock_error > 0.0 && c.max_clock_error < 0.5)) {
    bad("max_clock_error", "must be within (0, 0.5), got " + std::to_string(c.max_clock_error));
  }
  if (c.failures_before_recovery < 1) bad("failures_before_recovery", "must be >= 1");
  if (c.backoff_initial_ns <= 0 || c.backoff_max_ns < c.backoff_initial_ns) {
    bad("backoff_initial_ns/backoff_max_ns", "must satisfy 0 < initial <= max");
  }
  if (c.recovery_attempts_before_failed < 1) bad("recovery_attempts_before_failed", "must be >= 1");
  if (c.reset_wait_ns <= 0) bad("reset_wait_ns", "must be > 0");
  if (c.settle_ns < 0) bad("settle_ns", "must be >= 0");
  if (c.data_ready_mode == DataReadyMode::Polling) {
    if (c.polling_period_ns <= 0) {
      bad("polling_period_ns", "must be > 0 in polling mode (use pollingPeriodNs(config))");
    }
    if (c.polling_period_ns > pollingPeriodNs(c)) {
      bad("polling_period_ns", std::to_string(c.polling_period_ns) +
                                   " ns is too long: the FIFO could overflow; at most " +
                                   std::to_string(pollingPeriodNs(c)) + " ns");
    }
  }
}

// ---------------------------------------------------------------------------------------
// The register table

std::vector<RegisterSetting> registerTableFor(const Mpu6050Config& c) {
  validateConfig(c);
  const std::uint8_t div = sampleRateDivider(c);
  const auto dlpf = static_cast<std::uint8_t>(c.dlpf_cfg);
  const auto fs = static_cast<std::uint8_t>(c.fs_sel << reg::kFsSelShift);
  std::uint8_t pin = 0;
  if (c.int_active_low) pin |= reg::INT_LEVEL;
  if (c.int_open_drain) pin |= reg::INT_OPEN;
  const std::uint8_t pin_clear = static_cast<std::uint8_t>(((reg::INT_LEVEL | reg::INT_OPEN) & ~pin) |
                                                           reg::LATCH_INT_EN | reg::INT_RD_CLEAR | reg::FSYNC_INT_EN);
  const auto accel_standby = static_cast<std::uint8_t>(reg::STBY_XA | reg::STBY_YA | reg::STBY_ZA);
  const auto afs = static_cast<std::uint8_t>(c.afs_sel << reg::kAfsSelShift);
  const std::uint8_t fifo_en = fifoEnableFor(c.accel);
  std::vector<RegisterSetting> table = {{
      // Written in this order. Wake with the PLL on the X gyro as clock source (RM Register
      // 107 recommends a gyro reference over the internal oscillator).
      {Register::PWR_MGMT_1, reg::CLKSEL_PLL_XGYRO,
       static_cast<std::uint8_t>(reg::DEVICE_RESET | reg::SLEEP | reg::CYCLE | reg::TEMP_DIS | reg::Bit2 | reg::Bit1)},
      {Register::PWR_MGMT_2, 0,
       static_cast<std::uint8_t>(reg::STBY_XG | reg::STBY_YG | reg::STBY_ZG | (c.accel ? accel_standby : 0))},
      {Register::SMPLRT_DIV, div, static_cast<std::uint8_t>(~div)},
      {Register::CONFIG, dlpf, static_cast<std::uint8_t>(reg::EXT_SYNC_SET_MASK | (reg::DLPF_CFG_MASK & ~dlpf))},
      {Register::GYRO_CONFIG, fs,
       static_cast<std::uint8_t>(reg::XG_ST | reg::YG_ST | reg::ZG_ST | (reg::FS_SEL_MASK & ~fs))},
      // Pulse mode (LATCH_INT_EN = 0): a 50 µs pulse per sample, so every sample is a rising
      // edge without any INT_STATUS read.
      {Register::INT_PIN_CFG, pin, pin_clear},
      {Register::INT_ENABLE, reg::DATA_RDY_EN | reg::FIFO_OFLOW_EN, reg::I2C_MST_INT_EN},
      {Register::FIFO_EN, fifo_en,
       static_cast<std::uint8_t>((reg::ACCEL_FIFO_EN & ~fifo_en) | reg::SLV2_FIFO_EN | reg::SLV1_FIFO_EN |
                                 reg::SLV0_FIFO_EN)},
      {Register::USER_CTRL, reg::USER_CTRL_BIT::FIFO_EN,
       static_cast<std::uint8_t>(reg::USER_CTRL_BIT::I2C_MST_EN | reg::USER_CTRL_BIT::I2C_IF_DIS)},
  }};
  if (c.accel) {
    // After GYRO_CONFIG: the accel's full scale, self-test off. Without accel the register
    // keeps whatever it holds (the 8-byte frame and the write sequence stay as they were).
    const auto after_gyro = std::find_if(table.begin(), table.end(),
                                         [](const RegisterSetting& s) { return s.reg == Register::GYRO_CONFIG; });
    table.insert(after_gyro + 1,
                 {Register::ACCEL_CONFIG, afs,
                  static_cast<std::uint8_t>(reg::XA_ST | reg::YA_ST | reg::ZA_ST | (reg::AFS_SEL_MASK & ~afs))});
  }
  return table;
}

}  // namespace gyrod::driver
