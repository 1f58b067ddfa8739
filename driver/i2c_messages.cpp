#include "driver/i2c_messages.hpp"

#include <cerrno>
#include <cstdio>

#include "driver/i2c_bus.hpp"

namespace gyrod::driver {

static_assert(kShortReadErrno == ENODATA, "kShortReadErrno must equal ENODATA");

std::string hexByte(std::uint8_t value) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", static_cast<unsigned>(value));
  return buf;
}

std::string describeTransferError(int negative_errno) {
  switch (-negative_errno) {
    case EREMOTEIO:
    case ENXIO:
      // Documentation/i2c/fault-codes: ENXIO is the address NACK; i2c-bcm2835 (the Pi's
      // adapter) reports a NACK as EREMOTEIO ("Remote I/O error").
      return std::string(-negative_errno == EREMOTEIO ? "EREMOTEIO" : "ENXIO") +
             " (no acknowledge: nothing answered at this address. Check power (3.3 V on VCC), "
             "SDA/SCL wiring, the AD0 pin (low = 0x68, high = 0x69) and run `i2cdetect -y 1`)";
    case EIO:
      return "EIO (the transfer failed on the wire: noise, long wires, missing or weak pull-ups, "
             "or a bus speed too high for the wiring)";
    case ETIMEDOUT:
      return "ETIMEDOUT (the adapter gave up: SCL held low or the device stretched the clock too long; "
             "if it persists, power-cycle the sensor)";
    case ENODEV:
      // i2c-dev passes on what the adapter driver returns: several report an address that
      // nobody acknowledges as ENODEV; a removed adapter gives it too.
      return "ENODEV (no device answered at this address, or the I2C adapter is gone. Check power "
             "(3.3 V on VCC), SDA/SCL wiring, the AD0 pin (low = 0x68, high = 0x69) and run `i2cdetect -y 1`)";
    case EBUSY: return "EBUSY (the bus stayed busy too long: another master, or SDA/SCL held low)";
    case EINVAL: return "EINVAL (the adapter refused the request: too long a burst or an unsupported transfer)";
    case EOPNOTSUPP: return "EOPNOTSUPP (the adapter does not support this kind of transfer)";
    case ENODATA: return "short read (the adapter returned fewer bytes than asked; the transfer was cut off)";
    case EAGAIN: return "EAGAIN (the adapter was busy; try again)";
    default: return std::string(busErrorName(negative_errno)) + " (errno " + std::to_string(-negative_errno) + ")";
  }
}

std::string describeSelectError(int negative_errno, std::uint8_t address) {
  if (-negative_errno == EBUSY) {
    return "EBUSY: address " + hexByte(address) +
           " is claimed by a kernel driver (inv-mpu6050 from a `dtoverlay=mpu6050` line, or an RTC "
           "overlay such as `dtoverlay=i2c-rtc` at 0x68). gyrod will not take the address from it: "
           "remove the overlay from config.txt and reboot (`i2cdetect -y 1` shows UU for a claimed "
           "address)";
  }
  if (-negative_errno == EINVAL) {
    return "EINVAL: " + hexByte(address) + " is not a valid 7-bit address";
  }
  return describeTransferError(negative_errno);
}

bool isTransientTransferError(int negative_errno) {
  switch (-negative_errno) {
    case EREMOTEIO:
    case ENXIO:
    case EIO:
    case ETIMEDOUT:
    case EAGAIN:
    case EBUSY:
    case ENODATA: return true;
    default: return false;
  }
}

}  // namespace gyrod::driver
