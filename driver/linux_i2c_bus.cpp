#include "driver/linux_i2c_bus.hpp"

extern "C" {
#include <i2c/smbus.h>
}
#include <fcntl.h>
#include <linux/i2c-dev.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "driver/i2c_messages.hpp"

namespace gyrod::driver {

std::string describeOpenError(int error, const std::string& path) {
  const std::string sys = std::string(" (") + std::strerror(error) + ")";
  switch (error) {
    case ENOENT:
      return path + " does not exist" + sys +
             ": I2C is not enabled, or this is the wrong bus number. On a Raspberry Pi enable it with "
             "`sudo raspi-config nonint do_i2c 0` (or raspi-config > Interface Options > I2C), or add "
             "`dtparam=i2c_arm=on` to /boot/firmware/config.txt (/boot/config.txt before bookworm), make sure "
             "the i2c-dev module loads, and reboot; `ls /dev/i2c-*` then lists the buses. The header's SDA/SCL "
             "(pins 3 and 5) are bus 1.";
    case EACCES:
    case EPERM:
      return "permission denied opening " + path + sys +
             ": add the user running gyrod to the 'i2c' group (`sudo usermod -aG i2c $USER`, then log out and "
             "in). On systems without that group, install the udev rule from docs/hardware.md.";
    case ENXIO:
    case ENODEV:
      return path + " exists but no adapter is behind it" + sys + " (the controller was removed or failed to probe)";
    case EBUSY: return path + " is busy" + sys;
    default: return "cannot open " + path + sys;
  }
}

std::string describeFunctionalityError(int error, const std::string& path) {
  if (error == ENOTTY || error == EINVAL) {
    return path + " is not an I2C adapter: the I2C_FUNCS ioctl failed" + std::string(" (") + std::strerror(error) +
           "). Give an i2c-dev node such as /dev/i2c-1.";
  }
  return "cannot query the functions of " + path + " (" + std::strerror(error) + ")";
}

std::array<i2c_msg, 2> registerReadMessages(std::uint8_t address, std::uint8_t* reg_byte, std::span<std::uint8_t> out) {
  if (address > 0x7F)
    throw std::invalid_argument("an I2C register read needs a 7-bit device address, got " + hexByte(address));
  if (out.empty() || out.size() > 0xFFFF) {
    throw std::invalid_argument("an I2C register read needs a length of 1..65535 bytes, got " +
                                std::to_string(out.size()));
  }
  std::array<i2c_msg, 2> m{};
  m[0].addr = address;
  m[0].flags = 0;  // write
  m[0].len = 1;
  m[0].buf = reg_byte;
  m[1].addr = address;
  m[1].flags = I2C_M_RD;  // read, after a repeated start (messages of one I2C_RDWR)
  m[1].len = static_cast<__u16>(out.size());
  m[1].buf = out.data();
  return m;
}

LinuxI2cBus::LinuxI2cBus(int bus_number) : LinuxI2cBus("/dev/i2c-" + std::to_string(bus_number)) {
  if (bus_number < 0) throw I2cBusError("I2C bus number must be >= 0, got " + std::to_string(bus_number), EINVAL);
}

LinuxI2cBus::LinuxI2cBus(const std::string& device_path) : path_(device_path) {
  fd_.reset(::open(path_.c_str(), O_RDWR | O_CLOEXEC));
  if (!fd_) {
    const int e = errno;
    throw I2cBusError(describeOpenError(e, path_), e);
  }
  if (::ioctl(fd_.get(), I2C_FUNCS, &funcs_) < 0) {
    const int e = errno;
    throw I2cBusError(describeFunctionalityError(e, path_), e);
  }
  rdwr_ = (funcs_ & I2C_FUNC_I2C) != 0;
  std::string missing;
  if (!(funcs_ & I2C_FUNC_SMBUS_READ_BYTE_DATA)) missing += " SMBus read byte data;";
  if (!(funcs_ & I2C_FUNC_SMBUS_WRITE_BYTE_DATA)) missing += " SMBus write byte data;";
  if (!rdwr_ && !(funcs_ & I2C_FUNC_SMBUS_READ_WORD_DATA)) missing += " SMBus read word data (or plain I2C);";
  if (!rdwr_ && !(funcs_ & I2C_FUNC_SMBUS_READ_I2C_BLOCK)) missing += " SMBus I2C block read (or plain I2C);";
  if (!missing.empty()) {
    throw I2cBusError("the adapter " + path_ + " lacks transfers the MPU6050 needs:" + missing +
                          " use another I2C bus (on a Pi, bus 1 on header pins 3 and 5).",
                      EOPNOTSUPP);
  }
}

LinuxI2cBus::~LinuxI2cBus() = default;

int LinuxI2cBus::selectDevice(std::uint8_t address) {
  if (address > 0x7F) return -EINVAL;
  // I2C_SLAVE fails with EBUSY when a kernel driver is bound to the address. Deliberately
  // not I2C_SLAVE_FORCE: two drivers on one chip corrupt each other's configuration.
  if (::ioctl(fd_.get(), I2C_SLAVE, static_cast<unsigned long>(address)) < 0) return -errno;
  selected_ = address;
  return 0;
}

int LinuxI2cBus::readByte(std::uint8_t reg, std::uint8_t& value) {
  // libi2c (i2c-tools ≥ 4.0) returns the byte or −errno.
  const __s32 r = i2c_smbus_read_byte_data(fd_.get(), reg);
  if (r < 0) return r;
  value = static_cast<std::uint8_t>(r & 0xFF);
  return 0;
}

int LinuxI2cBus::writeByte(std::uint8_t reg, std::uint8_t value) {
  const __s32 r = i2c_smbus_write_byte_data(fd_.get(), reg, value);
  return r < 0 ? r : 0;
}

int LinuxI2cBus::rdwrRead(std::uint8_t reg, std::span<std::uint8_t> out) {
  std::uint8_t reg_byte = reg;
  std::array<i2c_msg, 2> msgs = registerReadMessages(selected_, &reg_byte, out);
  i2c_rdwr_ioctl_data data{};
  data.msgs = msgs.data();
  data.nmsgs = static_cast<__u32>(msgs.size());
  const int r = ::ioctl(fd_.get(), I2C_RDWR, &data);
  if (r < 0) return -errno;
  if (r != static_cast<int>(msgs.size())) {
    ++short_reads_;  // the adapter stopped after the first message
    return -ENODATA;
  }
  return 0;
}

int LinuxI2cBus::readWordBigEndian(std::uint8_t reg, std::uint16_t& value) {
  if (rdwr_) {
    std::array<std::uint8_t, 2> b{};
    const int r = rdwrRead(reg, b);
    if (r != 0) return r;
    value = static_cast<std::uint16_t>((b[0] << 8) | b[1]);
    return 0;
  }
  // SMBus words are little-endian on the wire (first byte = low byte); the MPU6050 sends
  // the high byte first, so swap.
  const __s32 r = i2c_smbus_read_word_data(fd_.get(), reg);
  if (r < 0) return r;
  const auto w = static_cast<std::uint16_t>(r & 0xFFFF);
  value = static_cast<std::uint16_t>((w << 8) | (w >> 8));
  return 0;
}

int LinuxI2cBus::readBlock(std::uint8_t reg, std::span<std::uint8_t> out) {
  if (out.empty() || out.size() > maxBurstLength()) return -EINVAL;
  if (rdwr_) return rdwrRead(reg, out);
  const __s32 r = i2c_smbus_read_i2c_block_data(fd_.get(), reg, static_cast<__u8>(out.size()), out.data());
  if (r < 0) return r;
  if (static_cast<std::size_t>(r) != out.size()) {
    ++short_reads_;
    return -ENODATA;
  }
  return 0;
}

}  // namespace gyrod::driver
