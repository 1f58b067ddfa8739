#include "driver/mpu6050_driver.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <stdexcept>
#include <string>

#include "driver/i2c_messages.hpp"

namespace gyrod::driver {
namespace {

using mpu6050::Register;
namespace reg = mpu6050;

constexpr std::size_t kFrameBytes = sizeof(mpu6050::fifo::TempGyroFrame);
constexpr std::uint8_t kFifoEnable = reg::TEMP_FIFO_EN | reg::XG_FIFO_EN | reg::YG_FIFO_EN | reg::ZG_FIFO_EN;
static_assert(mpu6050::fifo::frameSize(kFifoEnable) == kFrameBytes);

// Clones answering 0x70 are MPU-6500 cores, whose FIFO is 512 bytes (MPU-6500 product
// specification); for any clone the smaller size is assumed, so overflow is never missed.
constexpr std::size_t kCloneFifoSize = 512;
constexpr std::int64_t kWaitResetPollNs = 10'000'000;
constexpr int kMaxWaitResetPolls = 10;
constexpr int kMaxConfigureAttempts = 3;
// Wake-ups a new FIFO segment may wait for a usable data-ready edge before its first
// frames are placed on the sample clock from the read time instead.
constexpr int kMaxSyncWaits = 3;

std::string ms(std::int64_t ns) { return std::to_string(ns / 1'000'000) + " ms"; }

}  // namespace

// ---------------------------------------------------------------------------------------
// Names and configuration

const char* gapCauseName(GapCause cause) {
  switch (cause) {
    case GapCause::FifoOverflow: return "fifo-overflow";
    case GapCause::MisalignedFrames: return "misaligned-frames";
    case GapCause::TransferError: return "transfer-error";
    case GapCause::DeviceUnreachable: return "device-unreachable";
    case GapCause::SilentReset: return "silent-reset";
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

bool isGenuineWhoAmI(std::uint8_t value) { return value == mpu6050::kWhoAmI; }
bool isKnownCloneWhoAmI(std::uint8_t value) { return value == 0x70 || value == 0x72 || value == 0x98; }

std::uint8_t sampleRateDivider(const Mpu6050Config& c) {
  if (!(c.dlpf_cfg >= 0 && c.dlpf_cfg <= 6)) {
    throw std::invalid_argument("Mpu6050Config.dlpf_cfg must be 0..6 (7 is reserved), got " +
                                std::to_string(c.dlpf_cfg));
  }
  const double internal = mpu6050::gyroOutputRateHz(c.dlpf_cfg);
  if (!std::isfinite(c.sample_rate_hz) || c.sample_rate_hz <= 0.0) {
    throw std::invalid_argument("Mpu6050Config.sample_rate_hz must be finite and > 0, got " +
                                std::to_string(c.sample_rate_hz));
  }
  // Sample rate = gyro output rate / (1 + SMPLRT_DIV) (RM §4.2 p.11).
  const double n = internal / c.sample_rate_hz;
  const double rounded = std::round(n);
  if (rounded < 1.0 || rounded > 256.0 || std::fabs(n - rounded) > 1e-9 * n) {
    throw std::invalid_argument("Mpu6050Config.sample_rate_hz " + std::to_string(c.sample_rate_hz) +
                                " is not " + std::to_string(static_cast<int>(internal)) +
                                " Hz / n for n = 1..256 (with dlpf_cfg " + std::to_string(c.dlpf_cfg) +
                                "); e.g. 1000, 500, 200, 100, 50, 20, 10 Hz");
  }
  return static_cast<std::uint8_t>(rounded - 1.0);
}

double nominalSamplePeriodNs(const Mpu6050Config& c) {
  return 1e9 * (1.0 + sampleRateDivider(c)) / mpu6050::gyroOutputRateHz(c.dlpf_cfg);
}

std::int64_t pollingPeriodNs(const Mpu6050Config& c) {
  const double fastest_period = nominalSamplePeriodNs(c) / (1.0 + c.max_clock_error);
  const double frames = static_cast<double>(kCloneFifoSize / kFrameBytes);
  double period = std::min({frames * fastest_period / 4.0, 100e6,
                            static_cast<double>(c.max_frames_per_wakeup) * fastest_period / 2.0});
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
  if (c.transfer_attempts < 1 || c.transfer_attempts > 10) {
    bad("transfer_attempts", "must be 1..10, got " + std::to_string(c.transfer_attempts));
  }
  const int max_frames = static_cast<int>(mpu6050::fifo::kSize / kFrameBytes);
  if (c.max_frames_per_wakeup < 1 || c.max_frames_per_wakeup > max_frames) {
    bad("max_frames_per_wakeup", "must be 1.." + std::to_string(max_frames) + ", got " +
                                     std::to_string(c.max_frames_per_wakeup));
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
      bad("polling_period_ns", std::to_string(c.polling_period_ns) + " ns is too long: the FIFO could overflow; at most " +
                                   std::to_string(pollingPeriodNs(c)) + " ns");
    }
  }
}

std::array<RegisterSetting, kRegisterTableSize> registerTableFor(const Mpu6050Config& c) {
  validateConfig(c);
  const std::uint8_t div = sampleRateDivider(c);
  const auto dlpf = static_cast<std::uint8_t>(c.dlpf_cfg);
  const auto fs = static_cast<std::uint8_t>(c.fs_sel << reg::kFsSelShift);
  std::uint8_t pin = 0;
  if (c.int_active_low) pin |= reg::INT_LEVEL;
  if (c.int_open_drain) pin |= reg::INT_OPEN;
  const std::uint8_t pin_clear = static_cast<std::uint8_t>(
      ((reg::INT_LEVEL | reg::INT_OPEN) & ~pin) | reg::LATCH_INT_EN | reg::INT_RD_CLEAR | reg::FSYNC_INT_EN);
  return {{
      // Written in this order. Wake with the PLL on the X gyro as clock source (RM Register
      // 107 recommends a gyro reference over the internal oscillator).
      {Register::PWR_MGMT_1, reg::CLKSEL_PLL_XGYRO,
       static_cast<std::uint8_t>(reg::DEVICE_RESET | reg::SLEEP | reg::CYCLE | reg::TEMP_DIS | reg::Bit2 | reg::Bit1)},
      {Register::PWR_MGMT_2, 0, reg::STBY_XG | reg::STBY_YG | reg::STBY_ZG},
      {Register::SMPLRT_DIV, div, static_cast<std::uint8_t>(~div)},
      {Register::CONFIG, dlpf, static_cast<std::uint8_t>(reg::EXT_SYNC_SET_MASK | (reg::DLPF_CFG_MASK & ~dlpf))},
      {Register::GYRO_CONFIG, fs,
       static_cast<std::uint8_t>(reg::XG_ST | reg::YG_ST | reg::ZG_ST | (reg::FS_SEL_MASK & ~fs))},
      // Pulse mode (LATCH_INT_EN = 0): a 50 µs pulse per sample, so every sample is a rising
      // edge without any INT_STATUS read.
      {Register::INT_PIN_CFG, pin, pin_clear},
      {Register::INT_ENABLE, reg::DATA_RDY_EN | reg::FIFO_OFLOW_EN, reg::I2C_MST_INT_EN},
      {Register::FIFO_EN, kFifoEnable,
       static_cast<std::uint8_t>(reg::ACCEL_FIFO_EN | reg::SLV2_FIFO_EN | reg::SLV1_FIFO_EN | reg::SLV0_FIFO_EN)},
      {Register::USER_CTRL, reg::USER_CTRL_BIT::FIFO_EN,
       static_cast<std::uint8_t>(reg::USER_CTRL_BIT::I2C_MST_EN | reg::USER_CTRL_BIT::I2C_IF_DIS)},
  }};
}

namespace {

SampleClockConfig sampleClockConfigFor(const Mpu6050Config& c) {
  SampleClockConfig s;
  s.nominal_period_ns = nominalSamplePeriodNs(c);
  s.max_clock_error = c.max_clock_error;
  if (c.data_ready_mode == DataReadyMode::InterruptEdges) {
    // Edge times come from the GPIO interrupt (kernel timestamp): a quarter period leaves
    // room for interrupt latency and still tells neighbouring samples apart.
    s.observation_tolerance_ns = s.nominal_period_ns / 4.0;
    s.observation_bias_ns = 0.0;
  } else {
    // At a poll the newest sample is 0..P old (uniform): centre it, allow half a period
    // plus margin.
    s.observation_tolerance_ns = 0.75 * s.nominal_period_ns;
    s.observation_bias_ns = 0.5 * s.nominal_period_ns;
    s.easing = 0.05;
  }
  return s;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Construction and the loop interface

Mpu6050Driver::Mpu6050Driver(I2cBus& bus, DataReadySource& data_ready, const Clock& clock, SampleSink& sink,
                             Mpu6050Config config, LogFunction log)
    : bus_(bus),
      data_ready_(data_ready),
      clock_(clock),
      sink_(sink),
      config_(std::move(config)),
      log_(std::move(log)),
      table_(registerTableFor(config_)),
      sample_clock_(sampleClockConfigFor(config_)),
      nominal_period_ns_(nominalSamplePeriodNs(config_)) {
  const double slowest_period = nominal_period_ns_ * (1.0 + config_.max_clock_error);
  if (config_.data_ready_mode == DataReadyMode::InterruptEdges) {
    // No edge for four periods: look at the FIFO anyway (a stuck or unwired INT line).
    watchdog_ns_ = std::max<std::int64_t>(static_cast<std::int64_t>(4.0 * slowest_period), 20'000'000);
  } else {
    watchdog_ns_ = 3 * config_.polling_period_ns + static_cast<std::int64_t>(4.0 * slowest_period);
  }
  alignment_bound_lsb_ =
      static_cast<std::int16_t>(std::lround(config_.alignment_bound_c * mpu6050::kTemperatureLsbPerDegC));
  gyro_lsb_per_dps_ = mpu6050::kGyroLsbPerDps[static_cast<std::size_t>(config_.fs_sel)];
}

void Mpu6050Driver::start() {
  if (step_ != Step::Idle) return;
  setState(DeviceState::Probing);
  log(LogLevel::Info, "looking for the " + where());
  goTo(Step::Probe, clock_.nowNs());
}

std::optional<std::int64_t> Mpu6050Driver::nextDeadlineNs() const {
  if (step_ != Step::Streaming) return step_deadline_;
  std::int64_t next = std::min(watchdog_due_, check_due_);
  if (continue_pending_) next = std::min(next, continue_due_);
  return next;
}

void Mpu6050Driver::onTimer(std::int64_t now_ns) {
  if (step_ == Step::Streaming) {
    streamingTimers(now_ns);
    return;
  }
  if (step_deadline_ && now_ns >= *step_deadline_) {
    step_deadline_.reset();
    runStep(now_ns);
  }
}

void Mpu6050Driver::onDataReady() {
  if (step_ != Step::Streaming) {
    // Drain, so a level-triggered loop does not spin; these edges belong to no segment.
    std::int64_t t = 0;
    for (int i = 0; i < 4096 && data_ready_.consumeEdge(t) == 0; ++i) {
    }
    stashed_edge_.reset();
    return;
  }
  std::int64_t t = 0;
  const int r = data_ready_.consumeEdge(t);
  if (r == -EAGAIN) return;  // woke with nothing pending (a polling source may do this)
  if (r < 0) {
    log(LogLevel::Warning, std::string("reading the data-ready source failed: ") + busErrorName(r));
    return;
  }
  if (config_.data_ready_mode == DataReadyMode::Polling) {
    for (int i = 0; i < 4096 && data_ready_.consumeEdge(t) == 0; ++i) {
    }
    readFifo(Trigger::Poll);
    return;
  }
  // Every queued edge is older than the FIFO_COUNT read that follows; keep the newest.
  stashed_edge_ = stashed_edge_ ? std::max(*stashed_edge_, t) : t;
  readFifo(Trigger::Edge);
}

// ---------------------------------------------------------------------------------------
// The configuration steps

void Mpu6050Driver::goTo(Step step, std::int64_t at_ns) {
  step_ = step;
  step_deadline_ = at_ns;
}

void Mpu6050Driver::runStep(std::int64_t now) {
  switch (step_) {
    case Step::Probe: doProbe(); break;
    case Step::Reset: doReset(); break;
    case Step::WaitReset: doWaitReset(); break;
    case Step::Configure: doConfigure(); break;
    case Step::StartFifo: doStartFifo(); break;
    case Step::Backoff:
      step_ = Step::Probe;
      doProbe();
      break;
    case Step::Streaming: streamingTimers(now); break;
    case Step::Idle:
    case Step::Failed: break;
  }
}

void Mpu6050Driver::doProbe() {
  if (!ever_streamed_ && status_.state != DeviceState::Failed) setState(DeviceState::Probing, status_.reason);
  const int sel = bus_.selectDevice(config_.address);
  if (sel != 0) {
    enterRecovery(GapCause::DeviceUnreachable, 0, "cannot address the " + where() + ": " +
                                                      describeSelectError(sel, config_.address));
    return;
  }
  std::uint8_t who = 0;
  const int r = readRegister(Register::WHO_AM_I, who);
  if (r != 0) {
    enterRecovery(GapCause::DeviceUnreachable, r, "no answer from the " + where() + " (WHO_AM_I read failed)");
    return;
  }
  status_.who_am_i = who;
  if (isGenuineWhoAmI(who)) {
    fifo_capacity_ = mpu6050::fifo::kSize;
  } else if (isKnownCloneWhoAmI(who)) {
    fifo_capacity_ = kCloneFifoSize;
    if (!clone_warned_) {
      clone_warned_ = true;
      log(LogLevel::Warning,
          "WHO_AM_I of the " + where() + " reads " + hexByte(who) +
              ", not 0x68: this is a part sold as an MPU6050 (0x70 is the MPU-6500's ID; 0x72 and 0x98 are "
              "seen on clone boards). Using it as an MPU6050 with a 512-byte FIFO assumed; its temperature "
              "scale may differ, so °C may be off by a few degrees.");
    }
  } else {
    const std::string reason = "WHO_AM_I of the device at " + hexByte(config_.address) + " on " +
                               config_.bus_name + " reads " + hexByte(who) +
                               ": not an MPU6050 (0x68) nor a known clone (0x70, 0x72, 0x98). Another chip "
                               "answers at this address (an RTC also uses 0x68); check the wiring and address.";
    if (!ever_streamed_) {
      fail(reason, false);
    } else {
      enterRecovery(GapCause::DeviceUnreachable, 0, reason);
    }
    return;
  }

  if (configured_before_ && !phase_broken_) {
    // Back after an outage. If the chip kept its configuration (a loose wire, not a power
    // loss), it kept sampling on the same clock: restarting the FIFO is enough, and the
    // gap stays exact.
    bool intact = true;
    for (std::size_t i = 0; i < table_.size(); ++i) {
      std::uint8_t v = 0;
      const int rr = readRegister(table_[i].reg, v);
      if (rr != 0) {
        enterRecovery(GapCause::DeviceUnreachable, rr, "reading back the " + where() + "'s registers failed");
        return;
      }
      if (!registerMatches(i, v)) {
        intact = false;
        break;
      }
    }
    if (intact) {
      log(LogLevel::Info, "the " + where() + " answers again with its configuration intact; restarting the FIFO");
      restartFifo();
      return;
    }
    log(LogLevel::Warning, "the " + where() + " answers again but lost its configuration (power loss?); resetting it");
  }
  doReset();
}

void Mpu6050Driver::doReset() {
  step_ = Step::Reset;
  if (ever_streamed_) {
    setState(status_.state == DeviceState::Failed ? DeviceState::Failed : DeviceState::Recovering, status_.reason,
             status_.retrying);
  } else {
    setState(DeviceState::Configuring);
  }
  phase_broken_ = true;  // from here on the chip's sample clock restarts
  const int r = writeRegister(Register::PWR_MGMT_1, reg::DEVICE_RESET);
  if (r != 0) {
    enterRecovery(GapCause::Reinitialised, r, "writing DEVICE_RESET to the " + where() + " failed");
    return;
  }
  ++counters_.device_resets;
  wait_reset_polls_ = 0;
  goTo(Step::WaitReset, clock_.nowNs() + config_.reset_wait_ns);
}

void Mpu6050Driver::doWaitReset() {
  std::uint8_t v = 0;
  const int r = readRegister(Register::PWR_MGMT_1, v);
  if (r != 0) {
    enterRecovery(GapCause::Reinitialised, r, "reading PWR_MGMT_1 after reset failed on the " + where());
    return;
  }
  if (v & reg::DEVICE_RESET) {
    if (++wait_reset_polls_ < kMaxWaitResetPolls) {
      goTo(Step::WaitReset, clock_.nowNs() + kWaitResetPollNs);
      return;
    }
    enterRecovery(GapCause::Reinitialised, 0,
                  "the " + where() + " did not finish its reset (PWR_MGMT_1 still " + hexByte(v) + ")");
    return;
  }
  if (isGenuineWhoAmI(status_.who_am_i) && v != mpu6050::kPwrMgmt1ResetValue) {
    log(LogLevel::Warning, "after reset PWR_MGMT_1 reads " + hexByte(v) + ", expected 0x40 (asleep)");
  }
  configure_attempts_ = 0;
  doConfigure();
}

void Mpu6050Driver::doConfigure() {
  step_ = Step::Configure;
  for (const RegisterSetting& s : table_) {
    const int r = writeRegister(s.reg, s.set);
    if (r != 0) {
      enterRecovery(GapCause::Reinitialised, r,
                    "configuring register " + hexByte(mpu6050::address(s.reg)) + " of the " + where() + " failed");
      return;
    }
  }
  ++counters_.configures;
  configured_before_ = true;
  goTo(Step::StartFifo, clock_.nowNs() + config_.settle_ns);
}

void Mpu6050Driver::doStartFifo() {
  for (std::size_t i = 0; i < table_.size(); ++i) {
    std::uint8_t v = 0;
    const int r = readRegister(table_[i].reg, v);
    if (r != 0) {
      enterRecovery(GapCause::Reinitialised, r, "reading back the configuration of the " + where() + " failed");
      return;
    }
    if (!registerMatches(i, v)) {
      const std::string what = "register " + hexByte(mpu6050::address(table_[i].reg)) + " of the " + where() +
                               " reads " + hexByte(v) + " after configuration (wanted bits " +
                               hexByte(table_[i].set) + " set, " + hexByte(table_[i].clear) + " clear)";
      if (++configure_attempts_ < kMaxConfigureAttempts) {
        log(LogLevel::Warning, what + "; configuring again");
        doConfigure();
      } else {
        enterRecovery(GapCause::Reinitialised, 0, what + "; the chip does not keep its configuration");
      }
      return;
    }
  }
  restartFifo();
}

// ---------------------------------------------------------------------------------------
// Streaming

bool Mpu6050Driver::restartFifo() {
  // RM Register 106: FIFO_RESET resets the FIFO "while FIFO_EN equals 0"; so disable,
  // reset, enable. Samples taken in between are not written; the gap accounting counts them.
  std::uint8_t user_ctrl = 0;
  for (const RegisterSetting& s : table_) {
    if (s.reg == Register::USER_CTRL) user_ctrl = s.set;
  }
  const auto off = static_cast<std::uint8_t>(user_ctrl & ~reg::USER_CTRL_BIT::FIFO_EN);
  int r = writeRegister(Register::USER_CTRL, off);
  if (r == 0) r = writeRegister(Register::USER_CTRL, static_cast<std::uint8_t>(off | reg::USER_CTRL_BIT::FIFO_RESET));
  if (r == 0) r = writeRegister(Register::USER_CTRL, user_ctrl);
  if (r != 0) {
    enterRecovery(GapCause::TransferError, r, "resetting the FIFO of the " + where() + " failed");
    return false;
  }
  ++counters_.fifo_resets;
  const std::int64_t now = clock_.nowNs();
  segment_start_ns_ = now;
  segment_base_known_ = false;
  segment_frames_ = 0;
  sync_waits_ = 0;
  stashed_edge_.reset();
  step_ = Step::Streaming;
  step_deadline_.reset();
  watchdog_due_ = now + watchdog_ns_;
  if (check_due_ < now) check_due_ = now + config_.register_check_interval_ns;
  continue_pending_ = false;
  return true;
}

void Mpu6050Driver::endSegment(GapCause cause) {
  if (!pending_cause_) pending_cause_ = cause;
  segment_base_known_ = false;
}

void Mpu6050Driver::streamingTimers(std::int64_t now) {
  if (continue_pending_ && now >= continue_due_) {
    continue_pending_ = false;
    readFifo(Trigger::Continue);
    if (step_ != Step::Streaming) return;
  }
  if (now >= watchdog_due_) {
    // No data-ready for several periods. Look at the FIFO, and at PWR_MGMT_1: a chip that
    // browned out sleeps and stops producing edges, so this is the fast silent-reset check.
    watchdog_due_ = now + watchdog_ns_;
    readFifo(Trigger::Watchdog);
    if (step_ != Step::Streaming) return;
    if (!checkOneRegister(0)) return;
  }
  if (now >= check_due_) {
    check_due_ = now + config_.register_check_interval_ns;
    const std::size_t i = next_check_;
    next_check_ = (next_check_ + 1) % table_.size();
    checkOneRegister(i);
  }
}

bool Mpu6050Driver::checkOneRegister(std::size_t index) {
  ++counters_.register_checks;
  std::uint8_t v = 0;
  const int r = readRegister(table_[index].reg, v);
  if (r != 0) {
    operationFailed(r, "the periodic register check");
    return step_ == Step::Streaming;
  }
  if (registerMatches(index, v)) return true;
  ++counters_.silent_resets;
  const std::string what = "register " + hexByte(mpu6050::address(table_[index].reg)) + " of the " + where() +
                           " reads " + hexByte(v) +
                           ": the chip lost its configuration without a bus error (a silent reset, "
                           "e.g. a brown-out on a weak 3.3 V supply); re-initialising";
  log(LogLevel::Error, what);
  endSegment(GapCause::SilentReset);
  phase_broken_ = true;
  setState(DeviceState::Recovering, what);
  goTo(Step::Reset, clock_.nowNs());
  return false;
}

void Mpu6050Driver::collectEdges(std::int64_t before_ns, std::int64_t after_ns, std::optional<std::int64_t>& newest,
                                 bool& ambiguous) {
  std::optional<std::int64_t> later;
  const auto classify = [&](std::int64_t e) {
    if (e <= segment_start_ns_) return;  // belongs to frames the FIFO reset discarded
    if (e <= before_ns) {
      newest = newest ? std::max(*newest, e) : e;
    } else if (e <= after_ns) {
      ambiguous = true;  // during the FIFO_COUNT read: counted or not, we cannot tell
    } else {
      later = later ? std::max(*later, e) : e;
    }
  };
  if (stashed_edge_) classify(*stashed_edge_);
  stashed_edge_.reset();
  std::int64_t e = 0;
  for (int i = 0; i < 4096; ++i) {
    const int r = data_ready_.consumeEdge(e);
    if (r != 0) break;
    classify(e);
  }
  stashed_edge_ = later;
  // A full edge queue drops the newest edges (as the kernel's line-event FIFO does): the
  // newest edge left is then older than the newest frame and must not be paired with it.
  const std::uint64_t dropped = data_ready_.edgesDropped();
  if (dropped != edges_dropped_seen_) {
    edges_dropped_seen_ = dropped;
    ambiguous = true;
  }
}

void Mpu6050Driver::readFifo(Trigger trigger) {
  const std::int64_t t0 = clock_.nowNs();
  std::uint16_t count = 0;
  const int r = readWord(Register::FIFO_COUNTH, count);
  if (r != 0) {
    operationFailed(r, "reading FIFO_COUNT");
    return;
  }
  const std::int64_t t1 = clock_.nowNs();
  std::optional<std::int64_t> newest_edge;
  bool ambiguous = false;
  if (config_.data_ready_mode == DataReadyMode::InterruptEdges) {
    collectEdges(t0, t1, newest_edge, ambiguous);
  }

  if (count > mpu6050::fifo::kSize) {
    ++counters_.fifo_transfer_errors;
    log(LogLevel::Warning, "FIFO_COUNT of the " + where() + " reads " + std::to_string(count) +
                               ", more than the FIFO holds: the read was corrupted; resetting the FIFO");
    endSegment(GapCause::TransferError);
    restartFifo();
    return;
  }
  if (count >= fifo_capacity_) {
    // Full: the chip has overwritten (or is about to overwrite) the oldest bytes. Where
    // frames start is then unknown in general (1024 is not a multiple of most frame sizes,
    // and the map does not promise whole-frame overwrites), so reset rather than guess.
    ++counters_.fifo_overflows;
    log(LogLevel::Warning, "FIFO overflow on the " + where() +
                               ": the reader fell behind by a full FIFO; resetting the FIFO (the lost "
                               "samples are reported as a gap)");
    endSegment(GapCause::FifoOverflow);
    restartFifo();
    return;
  }
  const std::size_t available = count / kFrameBytes;
  if (available == 0) {
    if (trigger == Trigger::Edge || trigger == Trigger::Poll) ++counters_.empty_wakeups;
    return;
  }
  if (trigger == Trigger::Watchdog && config_.data_ready_mode == DataReadyMode::InterruptEdges) {
    ++counters_.data_ready_missed;
    // Once a minute at most: data arrive but no edge announced them.
    if (last_missed_log_ns_ == INT64_MIN || t0 - last_missed_log_ns_ >= 60 * kNsPerSecond) {
      last_missed_log_ns_ = t0;
      log(LogLevel::Warning, "the FIFO of the " + where() +
                                 " has data but no data-ready edge came for " + ms(watchdog_ns_) +
                                 ": check the INT wire and the GPIO chip, line and edge settings (reading on a "
                                 "timer meanwhile)");
    }
  }

  std::optional<std::int64_t> observation;
  if (config_.data_ready_mode == DataReadyMode::Polling) {
    observation = t0;
  } else if (newest_edge && !ambiguous) {
    observation = newest_edge;
  }
  if (!segment_base_known_) {
    if (!determineSegmentBase(observation, available, t0)) return;  // frames wait in the FIFO
  } else if (observation) {
    // The newest edge announced the newest frame counted.
    const auto verdict = sample_clock_.observe(*observation, segment_base_ + segment_frames_ + available - 1);
    if (verdict == SampleClock::Verdict::Rejected) ++counters_.timestamp_rejections;
    if (verdict == SampleClock::Verdict::Relocked) {
      ++counters_.timestamp_rejections;
      ++counters_.timestamp_relocks;
      log(LogLevel::Warning, "data-ready edges of the " + where() +
                                 " disagree with its sample clock repeatedly; re-anchoring the timestamps");
    }
  }

  const std::size_t frames = std::min<std::size_t>(available, static_cast<std::size_t>(config_.max_frames_per_wakeup));
  const std::size_t bytes = frames * kFrameBytes;
  const std::size_t burst = bus_.maxBurstLength();
  const std::size_t chunk = burst >= kFrameBytes ? burst / kFrameBytes * kFrameBytes : std::max<std::size_t>(burst, 1);
  for (std::size_t off = 0; off < bytes;) {
    const std::size_t len = std::min(chunk, bytes - off);
    const int br = bus_.readBlock(mpu6050::address(Register::FIFO_R_W), std::span(fifo_bytes_.data() + off, len));
    if (br != 0) {
      // Never retried: the failed burst may have popped some or all of its bytes, so the
      // FIFO's position is unknown. Reset it; the sample clock counts what was lost.
      ++counters_.transfers_failed;
      ++counters_.fifo_transfer_errors;
      log(LogLevel::Warning, "FIFO read from the " + where() + " failed: " + describeTransferError(br) +
                                 "; resetting the FIFO");
      endSegment(GapCause::TransferError);
      operationFailed(br, nullptr);
      if (step_ == Step::Streaming) restartFifo();
      return;
    }
    off += len;
  }

  // Alignment: every frame starts with the temperature word, which must agree with
  // TEMP_OUT (the newest sample's temperature; the die warms by far less than the bound
  // within one FIFO's worth of samples). A gyro word in that place almost never does —
  // except near 36.53 °C, where TEMP_OUT ≈ 0 and a still gyro also reads ≈ 0.
  std::uint16_t temp_word = 0;
  const int tr = readWord(Register::TEMP_OUT_H, temp_word);
  if (tr != 0) {
    ++counters_.fifo_transfer_errors;
    log(LogLevel::Warning, "reading TEMP_OUT from the " + where() + " failed: " + describeTransferError(tr) +
                               "; the frames just read cannot be checked and are dropped");
    endSegment(GapCause::TransferError);
    operationFailed(tr, nullptr);
    if (step_ == Step::Streaming) restartFifo();
    return;
  }
  const auto temp_out = static_cast<std::int16_t>(temp_word);
  for (std::size_t i = 0; i < frames; ++i) {
    const std::uint8_t* f = fifo_bytes_.data() + i * kFrameBytes;
    const std::int16_t t = mpu6050::combineBigEndian(f[0], f[1]);
    if (std::abs(static_cast<int>(t) - static_cast<int>(temp_out)) > alignment_bound_lsb_) {
      ++counters_.misaligned_bursts;
      log(LogLevel::Warning, "FIFO frames from the " + where() + " are misaligned (frame " + std::to_string(i) +
                                 " has temperature word " + std::to_string(t) + ", TEMP_OUT is " +
                                 std::to_string(temp_out) + "); resetting the FIFO");
      endSegment(GapCause::MisalignedFrames);
      restartFifo();
      return;
    }
  }

  deliverFrames(frames);
  failure_score_ = std::max(0, failure_score_ - 1);
  const std::int64_t now = clock_.nowNs();
  watchdog_due_ = now + watchdog_ns_;
  if (frames < available) {
    ++counters_.backlog_capped;
    continue_pending_ = true;
    continue_due_ = now;  // at once, but through the loop, so other sources get their turn
  }
}

bool Mpu6050Driver::determineSegmentBase(std::optional<std::int64_t> observation, std::size_t available,
                                         std::int64_t read_time_ns) {
  const double period = sample_clock_.periodNs();
  const bool edges = config_.data_ready_mode == DataReadyMode::InterruptEdges;
  bool approximate = false;
  if (edges && observation) {
    // The FIFO was reset at segment_start_ns_ while the chip was sampling, so its first
    // frame came within one period after that. An edge that puts it elsewhere is not the
    // newest frame's (an edge was lost): do not use it.
    const double first = static_cast<double>(*observation) - static_cast<double>(available - 1) * period;
    const double tol = period / 4.0;
    const double start = static_cast<double>(segment_start_ns_);
    if (first <= start - tol || first > start + period * (1.0 + config_.max_clock_error) + tol) {
      observation.reset();
    }
  }
  if (edges && !observation) {
    if (++sync_waits_ <= kMaxSyncWaits) return false;
    // No usable edge (a stuck INT line?): place the newest frame half a period before the
    // read, as polling does. Its sequence number may be off by one.
    observation = read_time_ns - static_cast<std::int64_t>(period / 2.0);
    approximate = true;
  }

  const std::uint64_t newest_local = available - 1;
  std::uint64_t base = next_seq_;
  if (sample_clock_.locked()) {
    // Sequence numbers are sample-clock slots: the newest frame's slot is where its time
    // falls on the (old) clock. With the chip's clock running on, this is the exact count of
    // samples in between; after a restart of the chip's clock, the number of whole periods.
    const std::int64_t newest = sample_clock_.nearestIndexOfObservation(*observation);
    const std::int64_t signed_base = newest - static_cast<std::int64_t>(newest_local);
    if (signed_base > static_cast<std::int64_t>(next_seq_)) base = static_cast<std::uint64_t>(signed_base);
  }
  if (phase_broken_ || !sample_clock_.locked()) {
    sample_clock_.breakPhase();
    if (approximate) {
      sample_clock_.lockApproximately(*observation, base + newest_local);
    } else {
      (void)sample_clock_.observe(*observation, base + newest_local);
    }
  } else if (!approximate) {
    const auto verdict = sample_clock_.observe(*observation, base + newest_local);
    if (verdict == SampleClock::Verdict::Rejected || verdict == SampleClock::Verdict::Relocked) {
      ++counters_.timestamp_rejections;
    }
  }

  if (base > next_seq_) {
    const SampleGap gap{next_seq_, base - next_seq_, pending_cause_.value_or(GapCause::Reinitialised)};
    ++counters_.gaps;
    counters_.samples_lost += gap.count;
    log(LogLevel::Warning, "lost " + std::to_string(gap.count) + " samples (seq " + std::to_string(gap.first_seq) +
                               ".." + std::to_string(gap.first_seq + gap.count - 1) + ", " +
                               gapCauseName(gap.cause) + ")");
    sink_.onGap(gap);
  }
  pending_cause_.reset();
  phase_broken_ = false;
  segment_base_ = base;
  segment_base_known_ = true;
  next_seq_ = base;
  sync_waits_ = 0;
  return true;
}

void Mpu6050Driver::deliverFrames(std::size_t frames) {
  GyroSample s;
  for (std::size_t i = 0; i < frames; ++i) {
    const std::uint8_t* f = fifo_bytes_.data() + i * kFrameBytes;
    s.seq = segment_base_ + segment_frames_ + i;
    std::int64_t t = sample_clock_.timeOf(s.seq);
    if (t <= last_t_ns_) t = last_t_ns_ + 1;  // strictly increasing, even across a re-anchor
    s.t_ns = t;
    last_t_ns_ = t;
    // Frame layout (FIFO_EN = 0xF0): TEMP, GYRO_X, GYRO_Y, GYRO_Z, each big-endian.
    s.raw_temp = mpu6050::combineBigEndian(f[0], f[1]);
    for (std::size_t a = 0; a < 3; ++a) {
      s.raw_gyro[a] = mpu6050::combineBigEndian(f[2 + 2 * a], f[3 + 2 * a]);
      s.rate_dps[a] = static_cast<double>(s.raw_gyro[a]) / gyro_lsb_per_dps_;
    }
    s.temp_c = mpu6050::temperatureDegCFromRaw(s.raw_temp);
    sink_.onSample(s);
  }
  segment_frames_ += frames;
  next_seq_ = segment_base_ + segment_frames_;
  counters_.samples_delivered += frames;
  ever_streamed_ = true;
  if (status_.state != DeviceState::Streaming) {
    recovery_attempts_ = 0;
    setState(DeviceState::Streaming);
    log(LogLevel::Info, "streaming from the " + where() + " at " + std::to_string(config_.sample_rate_hz) +
                            " Hz (FS_SEL " + std::to_string(config_.fs_sel) + ", DLPF_CFG " +
                            std::to_string(config_.dlpf_cfg) + ")");
  }
}

// ---------------------------------------------------------------------------------------
// Errors and recovery

void Mpu6050Driver::operationFailed(int error, const char* what) {
  failure_score_ += 1;
  if (what != nullptr) {
    log(LogLevel::Warning, std::string(what) + " on the " + where() + " failed: " + describeTransferError(error));
  }
  if (-error == ENODEV || failure_score_ >= config_.failures_before_recovery) {
    enterRecovery(GapCause::DeviceUnreachable, error, "repeated transfer errors on the " + where());
  }
}

void Mpu6050Driver::enterRecovery(GapCause cause, int error, const std::string& what) {
  ++counters_.recoveries;
  if (step_ == Step::Streaming || ever_streamed_) endSegment(cause);
  stashed_edge_.reset();
  continue_pending_ = false;
  failure_score_ = 0;
  ++recovery_attempts_;
  const int shift = std::min(recovery_attempts_ - 1, 30);
  const std::int64_t backoff = std::min(config_.backoff_max_ns, config_.backoff_initial_ns << shift);
  std::string message = what;
  if (error != 0) message += ": " + describeTransferError(error);
  message += ". Retrying in " + ms(backoff) + ".";
  if (recovery_attempts_ > config_.recovery_attempts_before_failed) {
    if (status_.state != DeviceState::Failed) log(LogLevel::Error, message + " The sensor is marked not functional.");
    setState(DeviceState::Failed, message, true);
  } else {
    log(LogLevel::Warning, message);
    setState(DeviceState::Recovering, message, true);
  }
  goTo(Step::Backoff, clock_.nowNs() + backoff);
}

void Mpu6050Driver::fail(const std::string& reason, bool retrying) {
  step_ = Step::Failed;
  step_deadline_.reset();
  log(LogLevel::Error, reason);
  setState(DeviceState::Failed, reason, retrying);
}

// ---------------------------------------------------------------------------------------
// Transfers

template <typename Op>
int Mpu6050Driver::withRetries(Op&& op) {
  int r = 0;
  for (int attempt = 1;; ++attempt) {
    r = op();
    if (r == 0) return 0;
    ++counters_.transfers_failed;
    if (attempt >= config_.transfer_attempts || !isTransientTransferError(r)) break;
    ++counters_.retries;
  }
  ++counters_.operations_failed;
  return r;
}

int Mpu6050Driver::readRegister(Register r, std::uint8_t& value) {
  return withRetries([&] { return bus_.readByte(mpu6050::address(r), value); });
}

int Mpu6050Driver::writeRegister(Register r, std::uint8_t value) {
  return withRetries([&] { return bus_.writeByte(mpu6050::address(r), value); });
}

int Mpu6050Driver::readWord(Register r, std::uint16_t& value) {
  return withRetries([&] { return bus_.readWordBigEndian(mpu6050::address(r), value); });
}

bool Mpu6050Driver::registerMatches(std::size_t index, std::uint8_t value) const {
  const RegisterSetting& s = table_[index];
  return (value & s.set) == s.set && (value & s.clear) == 0;
}

// ---------------------------------------------------------------------------------------
// State and messages

void Mpu6050Driver::setState(DeviceState state, std::string reason, bool retrying) {
  if (status_.state == state && status_.reason == reason && status_.retrying == retrying) return;
  status_.state = state;
  status_.reason = std::move(reason);
  status_.retrying = retrying;
  sink_.onStatus(status_);
}

void Mpu6050Driver::log(LogLevel level, const std::string& message) const {
  if (log_) log_(level, message);
}

std::string Mpu6050Driver::where() const {
  return "MPU6050 at " + hexByte(config_.address) + " on " + config_.bus_name;
}

}  // namespace gyrod::driver
