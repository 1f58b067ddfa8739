// The chip as a whole: construction, time (ticks and scheduled events in order) and the
// I2C transfers. The parts are in mock_registers.cpp, mock_fifo.cpp, mock_int_line.cpp,
// mock_faults.cpp and mock_sampling.cpp.
#include "driver/mock/mock_mpu6050.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gyrod::driver {
namespace {

using mpu6050::Register;
namespace reg = mpu6050;

// The register map's temperature constants and processing's sensor model must agree.
static_assert(mpu6050::kTemperatureLsbPerDegC == processing::kTemperatureLsbPerDegC);
static_assert(mpu6050::kTemperatureOffsetDegC == processing::kTemperatureOffsetDegC);

void validate(const MockMpu6050Config& config) {
  if (config.address > 0x7F) {
    throw std::invalid_argument("MockMpu6050Config.address must be a 7-bit address, got " +
                                std::to_string(config.address));
  }
  if (!std::isfinite(config.clock_error_ppm) || std::fabs(config.clock_error_ppm) > 100'000.0) {
    throw std::invalid_argument("MockMpu6050Config.clock_error_ppm must be within ±100000 (10 %), got " +
                                std::to_string(config.clock_error_ppm));
  }
  if (config.reset_duration_ns < 0) {
    throw std::invalid_argument("MockMpu6050Config.reset_duration_ns must be >= 0, got " +
                                std::to_string(config.reset_duration_ns));
  }
  if (config.max_burst_length == 0) {
    throw std::invalid_argument("MockMpu6050Config.max_burst_length must be > 0");
  }
  for (double g : config.accel_bias_g) {
    if (!std::isfinite(g)) throw std::invalid_argument("MockMpu6050Config.accel_bias_g must be finite");
  }
  for (double g : config.accel_g) {
    if (!std::isfinite(g)) throw std::invalid_argument("MockMpu6050Config.accel_g must be finite");
  }
  if (!std::isfinite(config.accel_noise_g) || config.accel_noise_g < 0.0) {
    throw std::invalid_argument("MockMpu6050Config.accel_noise_g must be finite and >= 0, got " +
                                std::to_string(config.accel_noise_g));
  }
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
      accel_noise_(config.accel_noise_seed),
      int_line_(clock, *this, config.data_ready_edge, config.data_ready_queue_depth,
                counters_.data_ready_edges_hidden) {
  validate(config_);
  selected_ = config_.address;
  resetChip();
}

MockMpu6050::~MockMpu6050() = default;

// ---------------------------------------------------------------------------------------
// Time

void MockMpu6050::sync() {
  advanceTo(clock_.nowNs());
  int_line_.host().updateReadiness();
}

void MockMpu6050::advanceTo(std::int64_t t_ns) {
  if (t_ns < now_ns_) return;
  for (;;) {
    // An event at the same instant as a tick happens first (e.g. a brown-out swallows
    // the tick).
    while (ticks_.running() && ticks_.nextTickNs() <= t_ns && ticks_.nextTickNs() < next_event_ns_) {
      now_ns_ = ticks_.nextTickNs();
      internalTick(ticks_.takeTick());
    }
    if (next_event_ns_ > t_ns) break;
    now_ns_ = next_event_ns_;
    processNextEvent();
  }
  now_ns_ = t_ns;
}

std::optional<std::int64_t> MockMpu6050::nextSampleTimeNs() const {
  return ticks_.nextSampleNs(regs_.sampleRateDivider());
}

std::int64_t MockMpu6050::nextPossibleEdgeNs() const {
  // Only a sample tick with an interrupt enabled, or a scheduled event (pulse end, reset
  // done, a fault), can move the INT line.
  std::int64_t next = next_event_ns_;
  if (ticks_.running() && regs_.has(Register::INT_ENABLE, reg::DATA_RDY_EN | reg::FIFO_OFLOW_EN)) {
    next = std::min(next, *nextSampleTimeNs());
  }
  return next;
}

void MockMpu6050::recomputeNextEvent() {
  next_event_ns_ = std::min({reset_done_ns_, int_line_.pulseEndNs(), faults_.nextEventNs()});
}

void MockMpu6050::processNextEvent() {
  const std::int64_t t = next_event_ns_;
  if (reset_done_ns_ == t) {
    // DEVICE_RESET self-clears; the chip comes out of reset asleep (PWR_MGMT_1 = 0x40).
    reset_done_ns_ = mock::kNever;
    reset_busy_ = false;
    regs_[Register::PWR_MGMT_1] = mpu6050::kPwrMgmt1ResetValue;
  } else if (int_line_.pulseEndNs() == t) {
    int_line_.endPulse(t);
  } else {
    applyFaultEvent(faults_.takeNextEvent(), t);
  }
  recomputeNextEvent();
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
  if (faults_.inOutage()) {
    ++counters_.nacks_during_outage;
    return -faults_.outageError();
  }
  const int error = faults_.drawTransferError(counters_);
  // Injected after the transfer: the chip does it; the caller reports -error after.
  if (error != 0) deferred_error = faults_.errorsAfterTransfer();
  return -error;
}

int MockMpu6050::finishTransfer(int result) {
  if (result == 0) ++counters_.transfers_ok;
  int_line_.host().updateReadiness();
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
    if (r != mpu6050::address(Register::FIFO_R_W)) r = static_cast<std::uint8_t>((r + 1) & 0x7F);
  }
  afterRead();
  return finishTransfer(status);
}

}  // namespace gyrod::driver
