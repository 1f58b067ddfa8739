#pragma once
// Sentences a user can act on, for the errno values an I2C transfer returns. Shared by the
// Linux backend and the MPU6050 driver, so the same fault reads the same way everywhere.
#include <cstdint>
#include <string>

namespace gyrod::driver {

// Short read: the adapter returned fewer bytes than asked (LinuxI2cBus reports it as this
// errno, since the bus interface has no byte count).
inline constexpr int kShortReadErrno = 61;  // ENODATA on Linux; checked in i2c_messages.cpp

// "EREMOTEIO (no acknowledge: ...)" — the errno name and what it usually means on a
// Raspberry Pi with an MPU6050, with what to check. `negative_errno` as the bus returns it.
std::string describeTransferError(int negative_errno);

// For a failure of selectDevice() (the I2C_SLAVE ioctl): EBUSY there means a kernel driver
// owns the address.
std::string describeSelectError(int negative_errno, std::uint8_t address);

// Whether a failed transfer is worth repeating at once (a NACK, a bus glitch, a timeout),
// as opposed to errors that repeating cannot fix (adapter gone, request invalid).
bool isTransientTransferError(int negative_errno);

// "0x68"
std::string hexByte(std::uint8_t value);

}  // namespace gyrod::driver
