#include "driver/mpu6050_driver.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <string>

#include "driver/fifo_frame.hpp"
#include "driver/i2c_messages.hpp"

namespace gyrod::driver {
namespace {

using mpu6050::Register;
namespace reg = mpu6050;

constexpr std::int64_t kWaitResetPollNs = 10'000'000;
constexpr int kMaxWaitResetPolls = 10;
constexpr int kMaxConfigureAttempts = 3;

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
  accel_lsb_per_g_ = mpu6050::kAccelLsbPerG[static_cast<std::size_t>(config_.afs_sel)];
  frame_bytes_ = frameBytesFor(config_.accel);
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
    for (int i = 0; i < 4096 && data_ready_.consumeEdge(t) == 0; ++i) {}
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
    for (int i = 0; i < 4096 && data_ready_.consumeEdge(t) == 0; ++i) {}
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
    enterRecovery(GapCause::DeviceUnreachable, 0,
                  "cannot address the " + where() + ": " + describeSelectError(sel, config_.address));
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
    const std::string reason = "WHO_AM_I of the device at " + hexByte(config_.address) + " on " + config_.bus_name +
                               " reads " + hexByte(who) +
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
      if (!table_[i].matches(v)) {
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
    const bool failed = status_.state == DeviceState::Failed;
    setState(failed ? DeviceState::Failed : DeviceState::Recovering, status_.reason, !failed || status_.retrying);
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
    if (!table_[i].matches(v)) {
      const std::string what = "register " + hexByte(mpu6050::address(table_[i].reg)) + " of the " + where() +
                               " reads " + hexByte(v) + " after configuration (wanted bits " + hexByte(table_[i].set) +
                               " set, " + hexByte(table_[i].clear) + " clear)";
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

// ---------------------------------------------------------------------------------------
// State and messages

void Mpu6050Driver::setState(DeviceState state, std::string reason, bool retrying) {
  // STATUS shows the flag as is: a device that streams, configures or is probed for the first
  // time is not being retried, whatever the caller's default says.
  retrying = retrying && (state == DeviceState::Recovering || state == DeviceState::Failed ||
                          (state == DeviceState::Probing && !reason.empty()));
  if (status_.state == state && status_.reason == reason && status_.retrying == retrying) return;
  status_.state = state;
  status_.reason = std::move(reason);
  status_.retrying = retrying;
  sink_.onStatus(status_);
}

void Mpu6050Driver::log(LogLevel level, const std::string& message) const {
  if (log_) log_(level, message);
}

std::string Mpu6050Driver::ms(std::int64_t ns) { return std::to_string(ns / 1'000'000) + " ms"; }

std::string Mpu6050Driver::where() const {
  return "MPU6050 at " + hexByte(config_.address) + " on " + config_.bus_name;
}

}  // namespace gyrod::driver
