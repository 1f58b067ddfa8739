// Register reads and writes and what they do besides storing: clear-on-read INT_STATUS,
// the FIFO count latch and data port, WHO_AM_I (possibly faked), resets, power and DLPF
// changes, and the INT pin configuration. Storage and reset values: register_file.hpp.
#include "driver/mock/mock_mpu6050.hpp"

namespace gyrod::driver {
namespace {

using mpu6050::Register;
namespace reg = mpu6050;

constexpr std::uint8_t R(Register r) { return mpu6050::address(r); }

}  // namespace

std::uint8_t MockMpu6050::readRegister(std::uint8_t r) {
  switch (r) {
    case R(Register::INT_STATUS): {
      // Each bit clears when the register is read (RM Register 58).
      const std::uint8_t v = regs_.at(r);
      clearInterruptStatus(0xFF, now_ns_);
      return v;
    }
    case R(Register::FIFO_COUNTH): return fifo_.latchCountHigh();
    case R(Register::FIFO_COUNTL): return fifo_.latchedCountLow();
    case R(Register::FIFO_R_W): return popFifo();
    case R(Register::WHO_AM_I):
      if (const auto fake = faults_.fakeWhoAmI()) {
        ++counters_.who_am_i_faked_reads;
        return *fake;
      }
      return mpu6050::kWhoAmI;
    default: return regs_.stored(r);
  }
}

void MockMpu6050::afterRead() {
  // INT_RD_CLEAR = 1: status bits are cleared by any read operation (RM Register 55).
  if (regs_.has(Register::INT_PIN_CFG, reg::INT_RD_CLEAR)) clearInterruptStatus(0xFF, now_ns_);
}

void MockMpu6050::writeRegister(std::uint8_t r, std::uint8_t v) {
  if (reset_busy_ || !mock::RegisterFile::isWritable(r)) {
    ++counters_.writes_ignored;
    return;
  }
  switch (r) {
    case R(Register::PWR_MGMT_1): writePowerManagement(v); return;
    case R(Register::CONFIG): writeConfig(v); return;
    case R(Register::USER_CTRL): writeUserControl(v); return;
    case R(Register::SIGNAL_PATH_RESET):
      regs_.at(r) = 0;  // self-clearing; analog/digital path resets have no effect on the model
      return;
    case R(Register::INT_PIN_CFG): writeIntPinConfig(v); return;
    case R(Register::FIFO_R_W):
      pushFifo(&v, 1, now_ns_);  // the host may write into the FIFO too
      return;
    default: regs_.at(r) = v; return;
  }
}

void MockMpu6050::writePowerManagement(std::uint8_t v) {
  if (v & reg::DEVICE_RESET) {
    ++counters_.device_resets;
    resetChip();
    if (config_.reset_duration_ns > 0) {
      // DEVICE_RESET reads back as 1 until the reset is done; writes meanwhile are lost.
      regs_[Register::PWR_MGMT_1] = reg::DEVICE_RESET | mpu6050::kPwrMgmt1ResetValue;
      reset_busy_ = true;
      reset_done_ns_ = now_ns_ + config_.reset_duration_ns;
      recomputeNextEvent();
    }
    return;
  }
  regs_[Register::PWR_MGMT_1] = v;
  updateSampling();
}

void MockMpu6050::writeConfig(std::uint8_t v) {
  const int old_cfg = regs_.dlpfCfg();
  regs_[Register::CONFIG] = v;
  const int cfg = regs_.dlpfCfg();
  if (cfg == old_cfg) return;
  applyDlpfConfig(cfg);
  // A new internal rate: restart the tick train at the time of the write.
  if (ticks_.running()) ticks_.restart(now_ns_, 1e9 / internalTickRateHz());
}

void MockMpu6050::writeUserControl(std::uint8_t v) {
  if (v & reg::USER_CTRL_BIT::FIFO_RESET) {
    fifo_.clear();
    ++counters_.fifo_resets;
    // The register map does not say whether FIFO_RESET clears FIFO_OFLOW_INT; the mock
    // clears it, so a driver that resets after an overflow does not see it twice.
    clearInterruptStatus(reg::FIFO_OFLOW_INT, now_ns_);
  }
  if (v & reg::USER_CTRL_BIT::SIG_COND_RESET) {
    // "resets the signal paths ... and clears the sensor registers" (RM Register 106).
    regs_.clearSensorOutputs();
  }
  // FIFO_RESET, I2C_MST_RESET and SIG_COND_RESET clear themselves.
  regs_[Register::USER_CTRL] =
      v & static_cast<std::uint8_t>(~(reg::USER_CTRL_BIT::FIFO_RESET | reg::USER_CTRL_BIT::I2C_MST_RESET |
                                      reg::USER_CTRL_BIT::SIG_COND_RESET));
}

void MockMpu6050::writeIntPinConfig(std::uint8_t v) {
  regs_[Register::INT_PIN_CFG] = v;
  // The line keeps its own copy of the polarity (it is the pin driver's setting).
  int_line_.configure((v & reg::INT_LEVEL) != 0, (v & reg::LATCH_INT_EN) != 0, regs_[Register::INT_STATUS] != 0,
                      now_ns_);
}

}  // namespace gyrod::driver
