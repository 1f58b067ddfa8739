#pragma once
// Shared helpers for the mock-device tests: a virtual clock, a source and a mock, and
// bus calls that fail the test on an error.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "driver/clock.hpp"
#include "driver/mock/mock_mpu6050.hpp"
#include "driver/mpu6050_registers.hpp"

namespace gyrod::driver::test {

using mpu6050::Register;

inline std::uint8_t A(Register r) { return mpu6050::address(r); }

inline void write(I2cBus& bus, Register r, std::uint8_t v) {
  ASSERT_EQ(bus.writeByte(A(r), v), 0) << "write to register 0x" << std::hex << int(A(r));
}

inline std::uint8_t read(I2cBus& bus, Register r) {
  std::uint8_t v = 0xEE;
  EXPECT_EQ(bus.readByte(A(r), v), 0) << "read of register 0x" << std::hex << int(A(r));
  return v;
}

inline std::uint16_t fifoCount(I2cBus& bus) {
  std::uint16_t v = 0;
  EXPECT_EQ(bus.readWordBigEndian(A(Register::FIFO_COUNTH), v), 0);
  return v;
}

// Pops n FIFO bytes in bursts no longer than the adapter allows.
inline std::vector<std::uint8_t> readFifo(I2cBus& bus, std::size_t n) {
  std::vector<std::uint8_t> out(n);
  std::size_t done = 0;
  while (done < n) {
    const std::size_t chunk = std::min(n - done, bus.maxBurstLength());
    EXPECT_EQ(bus.readBlock(A(Register::FIFO_R_W), std::span(out.data() + done, chunk)), 0);
    done += chunk;
  }
  return out;
}

inline std::int16_t be16(std::uint8_t h, std::uint8_t l) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>((h << 8) | l));
}

struct Rig {
  explicit Rig(SignalSource& source, MockMpu6050Config config = quietConfig()) : mock(clock, source, config) {}
  static MockMpu6050Config quietConfig() {
    MockMpu6050Config c;
    c.accel_noise_g = 0.0;  // exact accel values unless a test wants noise
    return c;
  }
  void advance(std::int64_t ns) {
    clock.advanceNs(ns);
    mock.sync();
  }
  // Wake the chip with the given DLPF_CFG and divider, FIFO off.
  void wake(int dlpf_cfg, std::uint8_t smplrt_div) {
    write(mock, Register::CONFIG, static_cast<std::uint8_t>(dlpf_cfg));
    write(mock, Register::SMPLRT_DIV, smplrt_div);
    write(mock, Register::PWR_MGMT_1, mpu6050::CLKSEL_PLL_XGYRO);
  }
  VirtualClock clock{0};
  MockMpu6050 mock;
};

}  // namespace gyrod::driver::test
