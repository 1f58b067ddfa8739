#pragma once
// An I2C bus with one selected device address, as the chip layer sees it. Implemented by
// the mock device (driver/mock/mock_mpu6050.hpp) and by the Linux backend on /dev/i2c-N.
//
// Errors are errno-style, like libi2c's i2c_smbus_* calls: every transfer returns 0 on
// success or a negative errno. The values a caller should expect:
//   -EREMOTEIO  the device did not acknowledge (wrong address, no power, a glitch)
//   -EIO        the transfer failed on the wire (arbitration lost, bus error)
//   -ETIMEDOUT  the adapter gave up (SCL held low, clock stretching too long)
//   -ENXIO / -ENODEV  the device or the adapter itself is gone
//   -EINVAL     the request cannot be made on this adapter (e.g. too long a burst)
// Nothing here allocates; outputs are written only on success.
#include <cstddef>
#include <cstdint>
#include <span>

namespace gyrod::driver {

class I2cBus {
 public:
  virtual ~I2cBus() = default;

  // Selects the 7-bit address the transfers below go to. Returns 0 or −errno
  // (-EINVAL for an address above 0x7F).
  [[nodiscard]] virtual int selectDevice(std::uint8_t address) = 0;
  virtual std::uint8_t selectedDevice() const = 0;

  // One register: write [reg, value] / write [reg], repeated start, read one byte.
  [[nodiscard]] virtual int readByte(std::uint8_t reg, std::uint8_t& value) = 0;
  [[nodiscard]] virtual int writeByte(std::uint8_t reg, std::uint8_t value) = 0;

  // A 16-bit register pair read in one transfer: `reg` holds bits 15:8 and reg+1 bits 7:0
  // (the MPU-6050's big-endian layout). One transfer, so the two bytes cannot tear.
  [[nodiscard]] virtual int readWordBigEndian(std::uint8_t reg, std::uint16_t& value) = 0;

  // A burst read of out.size() bytes starting at `reg` in one transfer. The device decides
  // how the register pointer advances (the MPU-6050 does not advance past FIFO_R_W, so a
  // burst there drains the FIFO). -EINVAL if out is empty or longer than maxBurstLength().
  [[nodiscard]] virtual int readBlock(std::uint8_t reg, std::span<std::uint8_t> out) = 0;

  // Longest burst this adapter can do in one transfer: 32 for SMBus block reads
  // (I2C_SMBUS_BLOCK_MAX), more with plain I2C_RDWR messages.
  virtual std::size_t maxBurstLength() const = 0;
};

// "EREMOTEIO" etc. for logs and test messages; "errno N" for anything else.
const char* busErrorName(int negative_errno);

}  // namespace gyrod::driver
