#pragma once
// The mock MPU-6050's 1024-byte FIFO as a byte ring, with the two register-level quirks
// a driver can see: FIFO_COUNTH latches the count that FIFO_COUNTL then returns, and an
// empty FIFO_R_W read returns the last byte read. Counting, interrupts and what a frame
// holds are the chip's (mock_fifo.cpp).
#include <array>
#include <cstddef>
#include <cstdint>

#include "driver/mpu6050_registers.hpp"

namespace gyrod::driver::mock {

class Fifo {
 public:
  // Appends n bytes. When full, the oldest byte is dropped for each new one (RM §4.31
  // p.44: "the oldest data will be lost"), byte by byte, so with 1024 not a multiple of
  // the frame size the stream becomes misaligned. Returns how many bytes were dropped.
  std::size_t push(const std::uint8_t* bytes, std::size_t n);
  // Pops the oldest byte; when empty, returns the last byte popped (RM §4.31 p.44).
  std::uint8_t pop();
  // Empties the ring (USER_CTRL.FIFO_RESET); the latched count and last byte stay.
  void clear();
  // Power-on state: empty, latched count 0, last byte 0.
  void powerOnReset();

  std::size_t size() const { return count_; }
  bool empty() const { return count_ == 0; }
  // Reading FIFO_COUNTH loads both count registers; FIFO_COUNTL alone returns the value
  // loaded last time (RM §4.30 p.43).
  std::uint8_t latchCountHigh();
  std::uint8_t latchedCountLow() const { return static_cast<std::uint8_t>(latched_count_ & 0xFF); }

 private:
  std::array<std::uint8_t, mpu6050::fifo::kSize> bytes_{};
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::uint8_t last_read_ = 0;
  std::uint16_t latched_count_ = 0;
};

}  // namespace gyrod::driver::mock
