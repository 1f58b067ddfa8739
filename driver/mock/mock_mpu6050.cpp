#include "driver/mock/mock_mpu6050.hpp"

#include <sys/timerfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <system_error>

namespace gyrod::driver {
namespace {

using mpu6050::Register;
namespace reg = mpu6050;

constexpr std::uint8_t R(Register r) { return mpu6050::address(r); }

// The register map's temperature constants and processing's sensor model must agree.
static_assert(mpu6050::kTemperatureLsbPerDegC == processing::kTemperatureLsbPerDegC);
static_assert(mpu6050::kTemperatureOffsetDegC == processing::kTemperatureOffsetDegC);

// Registers the host may write on an MPU-6050 (RM §3 p.6–8, R/W entries). Writes elsewhere
// (outputs, INT_STATUS, FIFO_COUNT, WHO_AM_I, unknown addresses) are ignored by the chip.
constexpr bool isWritable(std::uint8_t r) {
  return (r >= 0x0D && r <= 0x10) ||  // self-test
         (r >= 0x19 && r <= 0x1C) ||  // SMPLRT_DIV, CONFIG, GYRO_CONFIG, ACCEL_CONFIG
         (r >= 0x23 && r <= 0x35) ||  // FIFO_EN, I2C master and slaves
         r == 0x37 || r == 0x38 ||    // INT_PIN_CFG, INT_ENABLE
         (r >= 0x63 && r <= 0x68) ||  // I2C slave data out, master delay, SIGNAL_PATH_RESET
         r == 0x6A || r == 0x6B || r == 0x6C || r == 0x74;
}

// Highest register address that exists; reads above it return 0.
constexpr std::uint8_t kLastRegister = 0x75;

void putBigEndian(std::array<std::uint8_t, 128>& regs, std::uint8_t at, std::int16_t v) {
  const auto u = static_cast<std::uint16_t>(v);
  regs[at] = static_cast<std::uint8_t>(u >> 8);
  regs[at + 1] = static_cast<std::uint8_t>(u & 0xFF);
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Construction

MockMpu6050::MockMpu6050(Clock& clock, SignalSource& source, MockMpu6050Config config)
    : clock_(clock),
      source_(source),
      config_(config),
      epoch_ns_(clock.nowNs()),
      now_ns_(epoch_ns_),
      filters_{processing::DigitalLowPassFilter(0), processing::DigitalLowPassFilter(0),
               processing::DigitalLowPassFilter(0)},
      accel_rng_(config.accel_noise_seed),
      data_ready_(*this, config.data_ready_edge, config.data_ready_queue_depth) {
  if (config_.address > 0x7F) {
    throw std::invalid_argument("MockMpu6050Config.address must be a 7-bit address, got " +
                                std::to_string(config_.address));
  }
  if (!std::isfinite(config_.clock_error_ppm) || std::fabs(config_.clock_error_ppm) > 100'000.0) {
    throw std::invalid_argument("MockMpu6050Config.clock_error_ppm must be within ±100000 (10 %), got " +
                                std::to_string(config_.clock_error_ppm));
  }
  if (config_.reset_duration_ns < 0) {
    throw std::invalid_argument("MockMpu6050Config.reset_duration_ns must be >= 0, got " +
                                std::to_string(config_.reset_duration_ns));
  }
  if (config_.max_burst_length == 0) {
    throw std::invalid_argument("MockMpu6050Config.max_burst_length must be > 0");
  }
  for (double g : config_.accel_g) {
    if (!std::isfinite(g)) throw std::invalid_argument("MockMpu6050Config.accel_g must be finite");
  }
  if (!std::isfinite(config_.accel_noise_g) || config_.accel_noise_g < 0.0) {
    throw std::invalid_argument("MockMpu6050Config.accel_noise_g must be finite and >= 0, got " +
                                std::to_string(config_.accel_noise_g));
  }
  selected_ = config_.address;
  resetChip();
}

MockMpu6050::~MockMpu6050() = default;

// ---------------------------------------------------------------------------------------
// Time

void MockMpu6050::sync() {
  advanceTo(clock_.nowNs());
  data_ready_.updateReadiness();
}

std::int64_t MockMpu6050::tickTimeNs(std::int64_t k) const {
  return anchor_ns_ + std::llround(static_cast<double>(k) * period_ns_);
}

double MockMpu6050::internalTickRateHz() const {
  return mpu6050::gyroOutputRateHz(dlpfCfg()) * (1.0 + config_.clock_error_ppm * 1e-6);
}

void MockMpu6050::advanceTo(std::int64_t t_ns) {
  if (t_ns < now_ns_) return;
  for (;;) {
    // An event at the same instant as a tick happens first (e.g. a brown-out swallows
    // the tick).
    while (sampling_ && next_tick_ns_ <= t_ns && next_tick_ns_ < next_event_ns_) {
      const std::int64_t t = next_tick_ns_;
      now_ns_ = t;
      ++tick_index_;
      next_tick_ns_ = tickTimeNs(tick_index_);
      internalTick(t);
    }
    if (next_event_ns_ > t_ns) break;
    now_ns_ = next_event_ns_;
    processNextEvent();
  }
  now_ns_ = t_ns;
}

void MockMpu6050::internalTick(std::int64_t t_ns) {
  ++counters_.internal_ticks;
  if (rate_mismatch_) ++counters_.source_rate_mismatch_ticks;
  const AnalogSample in = source_.nextTick(static_cast<double>(t_ns - epoch_ns_) * 1e-9);
  if (dlpf_bypass_) {
    filtered_dps_ = in.rate_dps;
  } else {
    if (prime_filters_) {
      // Start each filter in steady state at the first input after waking, instead of
      // from zero (the real start-up transient is not modelled).
      for (int i = 0; i < 3; ++i) filters_[i].reset(in.rate_dps[i]);
    }
    for (int i = 0; i < 3; ++i) filtered_dps_[i] = filters_[i].update(in.rate_dps[i]);
  }
  prime_filters_ = false;
  temperature_c_ = in.temperature_c;
  // Sample rate = gyro output rate / (1 + SMPLRT_DIV) (RM §4.2 p.11).
  if (++ticks_since_sample_ > regs_[R(Register::SMPLRT_DIV)]) {
    ticks_since_sample_ = 0;
    sampleTick(t_ns);
  }
}

void MockMpu6050::sampleTick(std::int64_t t_ns) {
  SampleRecord s;
  s.sequence = counters_.samples_produced++;
  s.time_ns = t_ns;
  const int fs_sel = (regs_[R(Register::GYRO_CONFIG)] & reg::FS_SEL_MASK) >> reg::kFsSelShift;
  const int afs_sel = (regs_[R(Register::ACCEL_CONFIG)] & reg::AFS_SEL_MASK) >> reg::kAfsSelShift;
  for (int i = 0; i < 3; ++i) {
    s.gyro[i] = processing::quantizeToInt16(filtered_dps_[i], mpu6050::kGyroLsbPerDps[fs_sel]);
    s.accel[i] = processing::quantizeToInt16(config_.accel_g[i] + accelNoise(), mpu6050::kAccelLsbPerG[afs_sel]);
  }
  // TEMP_OUT = (T − 36.53) · 340, the inverse of RM Registers 65–66.
  s.temperature = processing::quantizeToInt16(temperature_c_ - mpu6050::kTemperatureOffsetDegC,
                                              mpu6050::kTemperatureLsbPerDegC);
  for (int i = 0; i < 3; ++i) {
    putBigEndian(regs_, static_cast<std::uint8_t>(R(Register::ACCEL_XOUT_H) + 2 * i), s.accel[i]);
    putBigEndian(regs_, static_cast<std::uint8_t>(R(Register::GYRO_XOUT_H) + 2 * i), s.gyro[i]);
  }
  putBigEndian(regs_, R(Register::TEMP_OUT_H), s.temperature);

  if (regs_[R(Register::USER_CTRL)] & reg::USER_CTRL_BIT::FIFO_EN) {
    std::array<std::uint8_t, 14> frame{};
    const std::size_t n = buildFrame(frame.data());
    if (n > 0) {
      pushFifo(frame.data(), n, t_ns);
      ++counters_.fifo_frames_written;
      s.written_to_fifo = true;
    }
  }
  raiseInterrupt(reg::DATA_RDY_INT, reg::DATA_RDY_EN, t_ns);
  last_sample_ = s;
  if (observer_) observer_(s);
}

std::optional<std::int64_t> MockMpu6050::nextSampleTimeNs() const {
  if (!sampling_) return std::nullopt;
  const int ticks_per_sample = regs_[R(Register::SMPLRT_DIV)] + 1;
  const std::int64_t remaining = std::max(1, ticks_per_sample - ticks_since_sample_);
  return tickTimeNs(tick_index_ + remaining - 1);
}

std::int64_t MockMpu6050::nextPossibleEdgeNs() const {
  // Only a sample tick with an interrupt enabled, or a scheduled event (pulse end, reset
  // done, a fault), can move the INT line.
  std::int64_t next = next_event_ns_;
  if (sampling_ && (regs_[R(Register::INT_ENABLE)] & (reg::DATA_RDY_EN | reg::FIFO_OFLOW_EN))) {
    next = std::min(next, *nextSampleTimeNs());
  }
  return next;
}

void MockMpu6050::recomputeNextEvent() {
  std::int64_t next = std::min(reset_done_ns_, pulse_end_ns_);
  if (next_plan_event_ < events_.size()) next = std::min(next, events_[next_plan_event_].time_ns);
  next_event_ns_ = next;
}

void MockMpu6050::processNextEvent() {
  const std::int64_t t = next_event_ns_;
  if (reset_done_ns_ == t) {
    // DEVICE_RESET self-clears; the chip comes out of reset asleep (PWR_MGMT_1 = 0x40).
    reset_done_ns_ = kNever;
    reset_busy_ = false;
    regs_[R(Register::PWR_MGMT_1)] = mpu6050::kPwrMgmt1ResetValue;
  } else if (pulse_end_ns_ == t) {
    pulse_end_ns_ = kNever;
    setChipPinActive(false, t);
  } else {
    const ScheduledEvent e = events_[next_plan_event_++];
    const bool was_high = intLineHigh();
    switch (e.kind) {
      case EventKind::BurstStart:
        burst_remaining_ += plan_.error_bursts[e.index].transfers;
        burst_error_ = plan_.error_bursts[e.index].error;
        break;
      case EventKind::OutageStart: {
        const DeviceOutage& o = plan_.outages[e.index];
        outage_ = true;
        outage_error_ = o.error;
        ++counters_.outages_started;
        if (o.power_lost) {
          resetChip();
          powered_ = false;
          updateSampling();
        }
        break;
      }
      case EventKind::OutageEnd:
        outage_ = false;
        if (plan_.outages[e.index].power_lost) {
          powered_ = true;
          resetChip();  // power-on state: reset values, asleep
        }
        break;
      case EventKind::Brownout:
        ++counters_.brownouts;
        resetChip();
        break;
      case EventKind::ForcedOverflow:
        forceFifoOverflow(t);
        break;
      case EventKind::StuckStart:
        stuck_ = true;
        stuck_high_ = plan_.stuck_data_ready[e.index].level_high;
        lineMaybeMoved(was_high, t);
        break;
      case EventKind::StuckEnd:
        stuck_ = false;
        lineMaybeMoved(was_high, t);
        break;
    }
  }
  recomputeNextEvent();
}

// ---------------------------------------------------------------------------------------
// Power and configuration

void MockMpu6050::resetChip() {
  const bool was_high = intLineHigh();
  regs_.fill(0);
  regs_[R(Register::PWR_MGMT_1)] = mpu6050::kPwrMgmt1ResetValue;
  clearFifo();
  fifo_last_read_ = 0;
  fifo_count_shadow_ = 0;
  reset_busy_ = false;
  reset_done_ns_ = kNever;
  pin_active_ = false;
  pulse_end_ns_ = kNever;
  ticks_since_sample_ = 0;
  filtered_dps_ = {};
  applyDlpfConfig(0);
  updateSampling();
  lineMaybeMoved(was_high, now_ns_);
  recomputeNextEvent();
}

int MockMpu6050::dlpfCfg() const { return regs_[R(Register::CONFIG)] & reg::DLPF_CFG_MASK; }

void MockMpu6050::applyDlpfConfig(int cfg) {
  // DLPF_CFG 7 is "reserved" in the register map; PX4 uses it as "bypass DLPF" and the gyro
  // then runs at 8 kHz, so the mock passes the rate through unfiltered.
  dlpf_bypass_ = cfg == mpu6050::kDlpfCfgReserved;
  if (!dlpf_bypass_) {
    for (int i = 0; i < 3; ++i) {
      filters_[i] = processing::DigitalLowPassFilter(cfg);
      filters_[i].reset(filtered_dps_[i]);
    }
  }
  const double expected = source_.expectedTickRateHz();
  rate_mismatch_ = expected > 0.0 && expected != mpu6050::gyroOutputRateHz(cfg);
}

void MockMpu6050::updateSampling() {
  const bool should = powered_ && !reset_busy_ && !(regs_[R(Register::PWR_MGMT_1)] & reg::SLEEP);
  if (should && !sampling_) {
    startSampling(now_ns_);
  } else if (!should && sampling_) {
    sampling_ = false;
    next_tick_ns_ = kNever;
  }
}

void MockMpu6050::startSampling(std::int64_t t_ns) {
  sampling_ = true;
  anchor_ns_ = t_ns;
  period_ns_ = 1e9 / internalTickRateHz();
  tick_index_ = 1;
  next_tick_ns_ = tickTimeNs(1);
  ticks_since_sample_ = 0;
  prime_filters_ = true;
}

// ---------------------------------------------------------------------------------------
// Registers

std::uint8_t MockMpu6050::readRegister(std::uint8_t r) {
  switch (r) {
    case R(Register::INT_STATUS): {
      // Each bit clears when the register is read (RM Register 58).
      const std::uint8_t v = regs_[r];
      clearInterruptStatus(0xFF, now_ns_);
      return v;
    }
    case R(Register::FIFO_COUNTH):
      // Reading FIFO_COUNTH loads both count registers; FIFO_COUNTL alone returns the
      // value loaded last time (RM §4.30 p.43).
      fifo_count_shadow_ = static_cast<std::uint16_t>(fifo_count_);
      return static_cast<std::uint8_t>(fifo_count_shadow_ >> 8);
    case R(Register::FIFO_COUNTL):
      return static_cast<std::uint8_t>(fifo_count_shadow_ & 0xFF);
    case R(Register::FIFO_R_W):
      // An empty FIFO returns the last byte read until new data arrive (RM §4.31 p.44).
      if (fifo_count_ == 0) {
        ++counters_.fifo_empty_reads;
        return fifo_last_read_;
      }
      fifo_last_read_ = fifo_[fifo_head_];
      fifo_head_ = (fifo_head_ + 1) % fifo_.size();
      --fifo_count_;
      ++counters_.fifo_bytes_read;
      return fifo_last_read_;
    case R(Register::WHO_AM_I):
      if (plan_.who_am_i) {
        ++counters_.who_am_i_faked_reads;
        return *plan_.who_am_i;
      }
      return mpu6050::kWhoAmI;
    default:
      return r <= kLastRegister ? regs_[r] : 0;
  }
}

void MockMpu6050::afterRead() {
  // INT_RD_CLEAR = 1: status bits are cleared by any read operation (RM Register 55).
  if (regs_[R(Register::INT_PIN_CFG)] & reg::INT_RD_CLEAR) clearInterruptStatus(0xFF, now_ns_);
}

void MockMpu6050::writeRegister(std::uint8_t r, std::uint8_t v) {
  if (reset_busy_ || !isWritable(r)) {
    ++counters_.writes_ignored;
    return;
  }
  switch (r) {
    case R(Register::PWR_MGMT_1):
      if (v & reg::DEVICE_RESET) {
        ++counters_.device_resets;
        resetChip();
        if (config_.reset_duration_ns > 0) {
          // DEVICE_RESET reads back as 1 until the reset is done; writes meanwhile are lost.
          regs_[r] = reg::DEVICE_RESET | mpu6050::kPwrMgmt1ResetValue;
          reset_busy_ = true;
          reset_done_ns_ = now_ns_ + config_.reset_duration_ns;
          recomputeNextEvent();
        }
        return;
      }
      regs_[r] = v;
      updateSampling();
      return;
    case R(Register::CONFIG): {
      const int old_cfg = dlpfCfg();
      regs_[r] = v;
      const int cfg = dlpfCfg();
      if (cfg != old_cfg) {
        applyDlpfConfig(cfg);
        // A new internal rate: restart the tick train at the time of the write.
        if (sampling_) {
          anchor_ns_ = now_ns_;
          period_ns_ = 1e9 / internalTickRateHz();
          tick_index_ = 1;
          next_tick_ns_ = tickTimeNs(1);
        }
      }
      return;
    }
    case R(Register::USER_CTRL):
      if (v & reg::USER_CTRL_BIT::FIFO_RESET) {
        clearFifo();
        ++counters_.fifo_resets;
        // The register map does not say whether FIFO_RESET clears FIFO_OFLOW_INT; the mock
        // clears it, so a driver that resets after an overflow does not see it twice.
        clearInterruptStatus(reg::FIFO_OFLOW_INT, now_ns_);
      }
      if (v & reg::USER_CTRL_BIT::SIG_COND_RESET) {
        // "resets the signal paths ... and clears the sensor registers" (RM Register 106).
        std::fill(regs_.begin() + R(Register::ACCEL_XOUT_H), regs_.begin() + R(Register::GYRO_ZOUT_L) + 1, 0);
      }
      // FIFO_RESET, I2C_MST_RESET and SIG_COND_RESET clear themselves.
      regs_[r] = v & static_cast<std::uint8_t>(~(reg::USER_CTRL_BIT::FIFO_RESET | reg::USER_CTRL_BIT::I2C_MST_RESET |
                                                 reg::USER_CTRL_BIT::SIG_COND_RESET));
      return;
    case R(Register::SIGNAL_PATH_RESET):
      regs_[r] = 0;  // self-clearing; analog/digital path resets have no effect on the model
      return;
    case R(Register::INT_PIN_CFG): {
      const bool was_high = intLineHigh();
      regs_[r] = v;
      if (!(v & reg::LATCH_INT_EN) && pin_active_ && pulse_end_ns_ == kNever) {
        pin_active_ = false;  // leaving latch mode releases a held line
      } else if ((v & reg::LATCH_INT_EN) && !pin_active_ && regs_[R(Register::INT_STATUS)] != 0) {
        pin_active_ = true;
      }
      lineMaybeMoved(was_high, now_ns_);
      return;
    }
    case R(Register::FIFO_R_W):
      pushFifo(&v, 1, now_ns_);  // the host may write into the FIFO too
      return;
    default:
      regs_[r] = v;
      return;
  }
}

// ---------------------------------------------------------------------------------------
// FIFO

std::size_t MockMpu6050::buildFrame(std::uint8_t* out) const {
  // "Data is written to the FIFO in order of register number" (RM §4.31 p.44).
  const std::uint8_t en = regs_[R(Register::FIFO_EN)];
  std::size_t n = 0;
  const auto copy = [&](Register from, std::size_t bytes) {
    for (std::size_t i = 0; i < bytes; ++i) out[n++] = regs_[R(from) + i];
  };
  if (en & reg::ACCEL_FIFO_EN) copy(Register::ACCEL_XOUT_H, 6);
  if (en & reg::TEMP_FIFO_EN) copy(Register::TEMP_OUT_H, 2);
  if (en & reg::XG_FIFO_EN) copy(Register::GYRO_XOUT_H, 2);
  if (en & reg::YG_FIFO_EN) copy(Register::GYRO_YOUT_H, 2);
  if (en & reg::ZG_FIFO_EN) copy(Register::GYRO_ZOUT_H, 2);
  return n;
}

void MockMpu6050::pushFifo(const std::uint8_t* bytes, std::size_t n, std::int64_t t_ns) {
  // On overflow "the oldest data will be lost and new data will be written" (RM §4.31
  // p.44): byte by byte, so with 1024 not a multiple of the frame size the stream becomes
  // misaligned.
  std::size_t overwritten = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (fifo_count_ == fifo_.size()) {
      fifo_head_ = (fifo_head_ + 1) % fifo_.size();
      --fifo_count_;
      ++overwritten;
    }
    fifo_[(fifo_head_ + fifo_count_) % fifo_.size()] = bytes[i];
    ++fifo_count_;
  }
  counters_.fifo_bytes_written += n;
  if (overwritten > 0) {
    counters_.fifo_bytes_overwritten += overwritten;
    ++counters_.fifo_overflow_events;
    raiseInterrupt(reg::FIFO_OFLOW_INT, reg::FIFO_OFLOW_EN, t_ns);
  }
}

void MockMpu6050::clearFifo() {
  fifo_head_ = 0;
  fifo_count_ = 0;
}

void MockMpu6050::forceFifoOverflow(std::int64_t t_ns) {
  ++counters_.forced_fifo_overflows;
  std::array<std::uint8_t, 14> frame{};
  std::size_t n = buildFrame(frame.data());
  if (n == 0) n = 1;  // nothing enabled: fill with zero bytes
  const std::uint64_t overflows_before = counters_.fifo_overflow_events;
  while (counters_.fifo_overflow_events == overflows_before) pushFifo(frame.data(), n, t_ns);
}

// ---------------------------------------------------------------------------------------
// Interrupts and the INT line

void MockMpu6050::raiseInterrupt(std::uint8_t status_bit, std::uint8_t enable_bit, std::int64_t t_ns) {
  // A status bit is set only for an enabled interrupt ("sets to 1 when a ... interrupt is
  // generated", RM Register 58); a driver must enable what it wants to see.
  if (!(regs_[R(Register::INT_ENABLE)] & enable_bit)) return;
  if (status_bit == reg::DATA_RDY_INT) ++counters_.data_ready_interrupts;
  regs_[R(Register::INT_STATUS)] |= status_bit;
  if (regs_[R(Register::INT_PIN_CFG)] & reg::LATCH_INT_EN) {
    setChipPinActive(true, t_ns);  // held until the status is cleared
  } else if (!pin_active_) {
    setChipPinActive(true, t_ns);  // a 50 µs pulse
    pulse_end_ns_ = t_ns + mpu6050::kIntPulseWidthNs;
    recomputeNextEvent();
  }
}

void MockMpu6050::clearInterruptStatus(std::uint8_t bits, std::int64_t t_ns) {
  std::uint8_t& status = regs_[R(Register::INT_STATUS)];
  status = static_cast<std::uint8_t>(status & ~bits);
  if ((regs_[R(Register::INT_PIN_CFG)] & reg::LATCH_INT_EN) && status == 0) setChipPinActive(false, t_ns);
}

bool MockMpu6050::chipLineHigh() const {
  const bool active_low = regs_[R(Register::INT_PIN_CFG)] & reg::INT_LEVEL;
  return pin_active_ != active_low;
}

bool MockMpu6050::intLineHigh() const { return stuck_ ? stuck_high_ : chipLineHigh(); }

void MockMpu6050::setChipPinActive(bool active, std::int64_t t_ns) {
  if (pin_active_ == active) return;
  const bool was_chip_high = chipLineHigh();
  const bool was_high = intLineHigh();
  pin_active_ = active;
  if (stuck_ && chipLineHigh() != was_chip_high) ++counters_.data_ready_edges_hidden;
  lineMaybeMoved(was_high, t_ns);
}

void MockMpu6050::lineMaybeMoved(bool was_high, std::int64_t t_ns) {
  const bool high = intLineHigh();
  if (high != was_high) data_ready_.lineMoved(t_ns, high);
}

// ---------------------------------------------------------------------------------------
// Transfers

int MockMpu6050::selectDevice(std::uint8_t address) {
  // Like the I2C_SLAVE ioctl: nothing goes on the wire, so nothing can fail but the value.
  if (address > 0x7F) return -EINVAL;
  selected_ = address;
  return 0;
}

int MockMpu6050::beginTransfer(bool& deferred_error) {
  sync();
  ++counters_.transfers;
  deferred_error = false;
  if (selected_ != config_.address) {
    ++counters_.nacks_absent_address;
    return -EREMOTEIO;
  }
  if (outage_) {
    ++counters_.nacks_during_outage;
    return -outage_error_;
  }
  int error = 0;
  if (burst_remaining_ > 0) {
    --burst_remaining_;
    ++counters_.injected_burst_errors;
    error = burst_error_;
  } else if (plan_.random_errors.probability > 0.0 && uniform01(transfer_rng_) < plan_.random_errors.probability) {
    ++counters_.injected_random_errors;
    error = plan_.random_errors.error;
  }
  if (error != 0) {
    if (!plan_.injected_errors_after_transfer) return -error;
    deferred_error = true;  // the chip does the transfer; the caller reports -error after
    return -error;
  }
  return 0;
}

int MockMpu6050::finishTransfer(int result) {
  if (result == 0) ++counters_.transfers_ok;
  data_ready_.updateReadiness();
  return result;
}

int MockMpu6050::readByte(std::uint8_t reg, std::uint8_t& value) {
  bool deferred = false;
  const int status = beginTransfer(deferred);
  if (status != 0 && !deferred) return finishTransfer(status);
  const std::uint8_t v = readRegister(reg);
  afterRead();
  if (status == 0) value = v;
  return finishTransfer(status);
}

int MockMpu6050::writeByte(std::uint8_t reg, std::uint8_t value) {
  bool deferred = false;
  const int status = beginTransfer(deferred);
  if (status != 0 && !deferred) return finishTransfer(status);
  writeRegister(reg, value);
  return finishTransfer(status);
}

int MockMpu6050::readWordBigEndian(std::uint8_t reg, std::uint16_t& value) {
  // A word read is its own transfer type (SMBus read word), not limited by the burst length.
  std::array<std::uint8_t, 2> b{};
  const int status = readBurst(reg, b);
  if (status == 0) value = static_cast<std::uint16_t>((b[0] << 8) | b[1]);
  return status;
}

int MockMpu6050::readBlock(std::uint8_t reg, std::span<std::uint8_t> out) {
  if (out.empty() || out.size() > config_.max_burst_length) {
    ++counters_.transfers;
    return -EINVAL;  // the adapter refuses before anything reaches the wire
  }
  return readBurst(reg, out);
}

int MockMpu6050::readBurst(std::uint8_t reg, std::span<std::uint8_t> out) {
  bool deferred = false;
  const int status = beginTransfer(deferred);
  if (status != 0 && !deferred) return finishTransfer(status);
  // The register pointer advances after each byte, except at FIFO_R_W, where a burst
  // keeps reading the FIFO (RM §4.31: "The FIFO register supports burst reads").
  // With a deferred error the bytes are clocked out (and lost) but not reported.
  std::uint8_t r = reg;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::uint8_t v = readRegister(r);
    if (status == 0) out[i] = v;
    if (r != R(Register::FIFO_R_W)) r = static_cast<std::uint8_t>((r + 1) & 0x7F);
  }
  afterRead();
  return finishTransfer(status);
}

// ---------------------------------------------------------------------------------------
// Faults

void MockMpu6050::setFaultPlan(const FaultPlan& plan) {
  sync();
  const std::int64_t now_sensor = now_ns_ - epoch_ns_;
  const auto check_errno = [](int e, const std::string& what) {
    if (e <= 0) throw std::invalid_argument(what + ": error must be a positive errno value, got " + std::to_string(e));
  };
  const auto check_time = [&](std::int64_t t, const std::string& what) {
    if (t < now_sensor) {
      throw std::invalid_argument(what + " at " + std::to_string(t) + " ns is before the current sensor time " +
                                  std::to_string(now_sensor) + " ns");
    }
  };
  const auto check_duration = [](std::int64_t d, const std::string& what) {
    if (d <= 0) throw std::invalid_argument(what + ": duration_ns must be > 0, got " + std::to_string(d));
  };
  const double p = plan.random_errors.probability;
  if (!(p >= 0.0 && p <= 1.0)) {
    throw std::invalid_argument("FaultPlan.random_errors.probability must be within 0..1, got " + std::to_string(p));
  }
  check_errno(plan.random_errors.error, "FaultPlan.random_errors");

  std::vector<ScheduledEvent> events;
  for (std::size_t i = 0; i < plan.error_bursts.size(); ++i) {
    const auto& b = plan.error_bursts[i];
    const std::string what = "FaultPlan.error_bursts[" + std::to_string(i) + "]";
    check_errno(b.error, what);
    check_time(b.start_ns, what);
    events.push_back({epoch_ns_ + b.start_ns, EventKind::BurstStart, i});
  }
  const auto add_windows = [&](const auto& windows, const char* name, EventKind start, EventKind end) {
    std::vector<std::pair<std::int64_t, std::int64_t>> spans;
    for (std::size_t i = 0; i < windows.size(); ++i) {
      const std::string what = std::string("FaultPlan.") + name + "[" + std::to_string(i) + "]";
      check_time(windows[i].start_ns, what);
      check_duration(windows[i].duration_ns, what);
      spans.emplace_back(windows[i].start_ns, windows[i].start_ns + windows[i].duration_ns);
      events.push_back({epoch_ns_ + windows[i].start_ns, start, i});
      events.push_back({epoch_ns_ + windows[i].start_ns + windows[i].duration_ns, end, i});
    }
    std::sort(spans.begin(), spans.end());
    for (std::size_t i = 1; i < spans.size(); ++i) {
      if (spans[i].first < spans[i - 1].second) {
        throw std::invalid_argument(std::string("FaultPlan.") + name + ": windows overlap (one starts at " +
                                    std::to_string(spans[i].first) + " ns, before the previous ends at " +
                                    std::to_string(spans[i - 1].second) + " ns)");
      }
    }
  };
  for (std::size_t i = 0; i < plan.outages.size(); ++i) {
    check_errno(plan.outages[i].error, "FaultPlan.outages[" + std::to_string(i) + "]");
  }
  add_windows(plan.outages, "outages", EventKind::OutageStart, EventKind::OutageEnd);
  add_windows(plan.stuck_data_ready, "stuck_data_ready", EventKind::StuckStart, EventKind::StuckEnd);
  for (std::size_t i = 0; i < plan.brownouts_ns.size(); ++i) {
    check_time(plan.brownouts_ns[i], "FaultPlan.brownouts_ns[" + std::to_string(i) + "]");
    events.push_back({epoch_ns_ + plan.brownouts_ns[i], EventKind::Brownout, i});
  }
  for (std::size_t i = 0; i < plan.forced_fifo_overflows_ns.size(); ++i) {
    check_time(plan.forced_fifo_overflows_ns[i], "FaultPlan.forced_fifo_overflows_ns[" + std::to_string(i) + "]");
    events.push_back({epoch_ns_ + plan.forced_fifo_overflows_ns[i], EventKind::ForcedOverflow, i});
  }
  // Same instant: ends before starts (EventKind order), so back-to-back windows work.
  std::stable_sort(events.begin(), events.end(), [](const ScheduledEvent& a, const ScheduledEvent& b) {
    return a.time_ns != b.time_ns ? a.time_ns < b.time_ns : a.kind < b.kind;
  });

  // A new plan ends whatever the old one had started.
  const bool was_high = intLineHigh();
  plan_ = plan;
  events_ = std::move(events);
  next_plan_event_ = 0;
  transfer_rng_ = plan.random_errors.seed;
  burst_remaining_ = 0;
  outage_ = false;
  if (!powered_) {
    powered_ = true;
    resetChip();
  }
  stuck_ = false;
  lineMaybeMoved(was_high, now_ns_);
  recomputeNextEvent();
  data_ready_.updateReadiness(true);
}

// ---------------------------------------------------------------------------------------
// Random numbers

std::uint64_t MockMpu6050::splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

double MockMpu6050::uniform01(std::uint64_t& state) {
  return static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-53;  // [0, 1)
}

double MockMpu6050::accelNoise() {
  if (config_.accel_noise_g == 0.0) return 0.0;
  if (spare_normal_) {
    const double v = *spare_normal_;
    spare_normal_.reset();
    return v * config_.accel_noise_g;
  }
  // Box–Muller: two independent standard normals from two uniforms.
  const double u1 = 1.0 - uniform01(accel_rng_);  // (0, 1]
  const double u2 = uniform01(accel_rng_);
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_normal_ = r * std::sin(2.0 * std::numbers::pi * u2);
  return r * std::cos(2.0 * std::numbers::pi * u2) * config_.accel_noise_g;
}

// ---------------------------------------------------------------------------------------
// The host's view of INT

MockMpu6050::DataReadyLine::DataReadyLine(MockMpu6050& owner, EdgeDirection direction, std::size_t depth)
    : owner_(owner), direction_(direction) {
  if (depth == 0) throw std::invalid_argument("MockMpu6050Config.data_ready_queue_depth must be > 0");
  queue_.assign(depth, 0);
  fd_ = timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
  if (fd_ < 0) throw std::system_error(errno, std::generic_category(), "timerfd_create for the mock data-ready line");
}

MockMpu6050::DataReadyLine::~DataReadyLine() {
  if (fd_ >= 0) ::close(fd_);
}

void MockMpu6050::DataReadyLine::lineMoved(std::int64_t t_ns, bool rising) {
  const bool wanted = direction_ == EdgeDirection::Both || (direction_ == EdgeDirection::Rising) == rising;
  if (!wanted) return;
  if (count_ == queue_.size()) {
    ++dropped_;  // like the kernel's line-event FIFO: the new event is lost
    return;
  }
  queue_[(head_ + count_) % queue_.size()] = t_ns;
  ++count_;
}

void MockMpu6050::DataReadyLine::updateReadiness(bool force) {
  // A timerfd stands in for the GPIO event fd: no thread is needed, and in real-time mode
  // it wakes the loop when the chip can next move the INT line.
  std::int64_t at = 0;  // disarmed
  if (count_ > 0) {
    at = 1;  // an absolute time long past: expires at once
  } else if (owner_.clock_.isRealTime()) {
    const std::int64_t next = owner_.nextPossibleEdgeNs();
    if (next != kNever) at = std::max<std::int64_t>(next, 1);
  }
  if (at == armed_at_ns_ && !force) return;
  itimerspec spec{};
  spec.it_value.tv_sec = static_cast<time_t>(at / kNsPerSecond);
  spec.it_value.tv_nsec = static_cast<long>(at % kNsPerSecond);
  if (timerfd_settime(fd_, TFD_TIMER_ABSTIME, &spec, nullptr) == 0) armed_at_ns_ = at;
}

int MockMpu6050::DataReadyLine::consumeEdge(std::int64_t& timestamp_ns) {
  owner_.advanceTo(owner_.clock_.nowNs());
  if (count_ == 0) {
    // Re-arm and clear a stale expiry. Only real time can have one (a wake-up armed for a
    // possible edge that did not come); in virtual time the timer is disarmed whenever the
    // queue is empty, and the forced timerfd_settime would be a wasted system call.
    updateReadiness(owner_.clock_.isRealTime());
    return -EAGAIN;
  }
  timestamp_ns = queue_[head_];
  head_ = (head_ + 1) % queue_.size();
  --count_;
  updateReadiness();
  return 0;
}

}  // namespace gyrod::driver
