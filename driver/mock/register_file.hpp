#pragma once
// The mock MPU-6050's register storage: 128 bytes at their reset values, which of them the
// host may write, and the configuration fields the rest of the chip reads. What a read or
// a write does besides storing (clear-on-read, FIFO, resets) is the chip's business
// (mock_registers.cpp).
#include <algorithm>
#include <array>
#include <cstdint>

#include "driver/mpu6050_registers.hpp"

namespace gyrod::driver::mock {

class RegisterFile {
 public:
  using Register = mpu6050::Register;

  // Highest register address that exists; reads above it return 0.
  static constexpr std::uint8_t kLastRegister = 0x75;

  // Registers the host may write on an MPU-6050 (RM §3 p.6–8, R/W entries). Writes
  // elsewhere (outputs, INT_STATUS, FIFO_COUNT, WHO_AM_I, unknown addresses) are ignored
  // by the chip.
  static constexpr bool isWritable(std::uint8_t r) {
    return (r >= 0x0D && r <= 0x10) ||  // self-test
           (r >= 0x19 && r <= 0x1C) ||  // SMPLRT_DIV, CONFIG, GYRO_CONFIG, ACCEL_CONFIG
           (r >= 0x23 && r <= 0x35) ||  // FIFO_EN, I2C master and slaves
           r == 0x37 || r == 0x38 ||    // INT_PIN_CFG, INT_ENABLE
           (r >= 0x63 && r <= 0x68) ||  // I2C slave data out, master delay, SIGNAL_PATH_RESET
           r == 0x6A || r == 0x6B || r == 0x6C || r == 0x74;
  }

  // Power-on values: every register 0 except PWR_MGMT_1 = 0x40 (asleep).
  void powerOnReset() {
    bytes_.fill(0);
    (*this)[Register::PWR_MGMT_1] = mpu6050::kPwrMgmt1ResetValue;
  }

  std::uint8_t& operator[](Register r) { return bytes_[mpu6050::address(r)]; }
  std::uint8_t operator[](Register r) const { return bytes_[mpu6050::address(r)]; }
  std::uint8_t& at(std::uint8_t address) { return bytes_[address]; }
  std::uint8_t at(std::uint8_t address) const { return bytes_[address]; }
  // What a plain read of `address` returns (0 beyond the last register).
  std::uint8_t stored(std::uint8_t address) const { return address <= kLastRegister ? bytes_[address] : 0; }

  // Output registers hold big-endian 16-bit words (high byte at the lower address).
  void putBigEndian(std::uint8_t high_address, std::int16_t v) {
    const auto u = static_cast<std::uint16_t>(v);
    bytes_[high_address] = static_cast<std::uint8_t>(u >> 8);
    bytes_[high_address + 1] = static_cast<std::uint8_t>(u & 0xFF);
  }
  // ACCEL_XOUT_H .. GYRO_ZOUT_L to 0 (USER_CTRL.SIG_COND_RESET).
  void clearSensorOutputs() {
    std::fill(bytes_.begin() + mpu6050::address(Register::ACCEL_XOUT_H),
              bytes_.begin() + mpu6050::address(Register::GYRO_ZOUT_L) + 1, 0);
  }

  bool has(Register r, std::uint8_t bits) const { return ((*this)[r] & bits) != 0; }
  int dlpfCfg() const { return (*this)[Register::CONFIG] & mpu6050::DLPF_CFG_MASK; }
  int fsSel() const { return ((*this)[Register::GYRO_CONFIG] & mpu6050::FS_SEL_MASK) >> mpu6050::kFsSelShift; }
  int afsSel() const { return ((*this)[Register::ACCEL_CONFIG] & mpu6050::AFS_SEL_MASK) >> mpu6050::kAfsSelShift; }
  // Internal ticks per sample: 1 + SMPLRT_DIV (RM §4.2 p.11).
  int sampleRateDivider() const { return (*this)[Register::SMPLRT_DIV]; }

 private:
  std::array<std::uint8_t, 128> bytes_{};
};

}  // namespace gyrod::driver::mock
