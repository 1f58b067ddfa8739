#pragma once
// The I2cBus interface on a Linux I2C adapter, /dev/i2c-N, through libi2c (i2c-tools'
// i2c_smbus_* helpers) for register transfers and one I2C_RDWR transaction (write the
// register, repeated start, read N bytes) for FIFO bursts where the adapter can do plain
// I2C (I2C_FUNC_I2C). Adapters that only speak SMBus fall back to SMBus I2C-block reads,
// which stop at 32 bytes (I2C_SMBUS_BLOCK_MAX); maxBurstLength() says which.
//
// The address is selected with I2C_SLAVE, never I2C_SLAVE_FORCE: if a kernel driver owns
// the address (inv-mpu6050 from a dtoverlay, an RTC), gyrod reports that and leaves it.
#include <linux/i2c.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

#include "driver/i2c_bus.hpp"
#include "protocol/fd.hpp"

namespace gyrod::driver {

// Thrown when the adapter cannot be opened or is unusable; what() says what to do.
class I2cBusError : public std::runtime_error {
 public:
  I2cBusError(const std::string& message, int error) : std::runtime_error(message), error_(error) {}
  int error() const { return error_; }  // positive errno (0 when not from a system call)

 private:
  int error_;
};

// Messages for open() and the I2C_FUNCS ioctl failing with errno `error` on `path`. Pure.
std::string describeOpenError(int error, const std::string& path);
std::string describeFunctionalityError(int error, const std::string& path);

// The two I2C_RDWR messages of a register read with a repeated start:
//   [S addr+W reg] [Sr addr+R out.size() bytes P]
// Buffers are the caller's (`reg_byte` holds the register number; `out` receives the data).
// Pure: builds, sends nothing. Throws std::invalid_argument for an address above 0x7F or a
// length outside 1..65535 (i2c_msg.len is 16 bits).
std::array<i2c_msg, 2> registerReadMessages(std::uint8_t address, std::uint8_t* reg_byte, std::span<std::uint8_t> out);

class LinuxI2cBus final : public I2cBus {
 public:
  // The longest FIFO burst asked of an I2C_RDWR-capable adapter: the whole FIFO. (i2c-dev
  // accepts up to 8192 bytes per message.)
  static constexpr std::size_t kRdwrBurstLength = 1024;
  static constexpr std::size_t kSmbusBlockLength = 32;  // I2C_SMBUS_BLOCK_MAX

  // "/dev/i2c-<bus_number>". Throws I2cBusError.
  explicit LinuxI2cBus(int bus_number);
  // Any i2c-dev node. Throws I2cBusError.
  explicit LinuxI2cBus(const std::string& device_path);
  ~LinuxI2cBus() override;
  LinuxI2cBus(const LinuxI2cBus&) = delete;
  LinuxI2cBus& operator=(const LinuxI2cBus&) = delete;

  [[nodiscard]] int selectDevice(std::uint8_t address) override;
  std::uint8_t selectedDevice() const override { return selected_; }
  [[nodiscard]] int readByte(std::uint8_t reg, std::uint8_t& value) override;
  [[nodiscard]] int writeByte(std::uint8_t reg, std::uint8_t value) override;
  [[nodiscard]] int readWordBigEndian(std::uint8_t reg, std::uint16_t& value) override;
  // A short read (fewer bytes than asked) returns -ENODATA (kShortReadErrno).
  [[nodiscard]] int readBlock(std::uint8_t reg, std::span<std::uint8_t> out) override;
  std::size_t maxBurstLength() const override { return rdwr_ ? kRdwrBurstLength : kSmbusBlockLength; }

  const std::string& path() const { return path_; }
  unsigned long functionality() const { return funcs_; }
  bool usesRdwr() const { return rdwr_; }
  std::uint64_t shortReads() const { return short_reads_; }

 private:
  int rdwrRead(std::uint8_t reg, std::span<std::uint8_t> out);

  std::string path_;
  protocol::Fd fd_;
  unsigned long funcs_ = 0;
  bool rdwr_ = false;
  std::uint8_t selected_ = 0;
  std::uint64_t short_reads_ = 0;
};

}  // namespace gyrod::driver
