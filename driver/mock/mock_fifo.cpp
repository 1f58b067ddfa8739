// The FIFO: the byte ring (Fifo) and how the chip fills it (frames, overflow interrupt,
// the forced-overflow fault).
#include <array>

#include "driver/mock/fifo.hpp"
#include "driver/mock/mock_mpu6050.hpp"

namespace gyrod::driver {
namespace mock {

std::size_t Fifo::push(const std::uint8_t* bytes, std::size_t n) {
  std::size_t dropped = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (count_ == bytes_.size()) {
      head_ = (head_ + 1) % bytes_.size();
      --count_;
      ++dropped;
    }
    bytes_[(head_ + count_) % bytes_.size()] = bytes[i];
    ++count_;
  }
  return dropped;
}

std::uint8_t Fifo::pop() {
  if (count_ == 0) return last_read_;
  last_read_ = bytes_[head_];
  head_ = (head_ + 1) % bytes_.size();
  --count_;
  return last_read_;
}

void Fifo::clear() {
  head_ = 0;
  count_ = 0;
}

void Fifo::powerOnReset() {
  clear();
  last_read_ = 0;
  latched_count_ = 0;
}

std::uint8_t Fifo::latchCountHigh() {
  latched_count_ = static_cast<std::uint16_t>(count_);
  return static_cast<std::uint8_t>(latched_count_ >> 8);
}

}  // namespace mock

namespace reg = mpu6050;
using mpu6050::Register;

std::size_t MockMpu6050::buildFrame(std::uint8_t* out) const {
  // "Data is written to the FIFO in order of register number" (RM §4.31 p.44).
  const std::uint8_t en = regs_[Register::FIFO_EN];
  std::size_t n = 0;
  const auto copy = [&](Register from, std::size_t bytes) {
    for (std::size_t i = 0; i < bytes; ++i) out[n++] = regs_.at(static_cast<std::uint8_t>(mpu6050::address(from) + i));
  };
  if (en & reg::ACCEL_FIFO_EN) copy(Register::ACCEL_XOUT_H, 6);
  if (en & reg::TEMP_FIFO_EN) copy(Register::TEMP_OUT_H, 2);
  if (en & reg::XG_FIFO_EN) copy(Register::GYRO_XOUT_H, 2);
  if (en & reg::YG_FIFO_EN) copy(Register::GYRO_YOUT_H, 2);
  if (en & reg::ZG_FIFO_EN) copy(Register::GYRO_ZOUT_H, 2);
  return n;
}

void MockMpu6050::pushFifo(const std::uint8_t* bytes, std::size_t n, std::int64_t t_ns) {
  const std::size_t overwritten = fifo_.push(bytes, n);
  counters_.fifo_bytes_written += n;
  if (overwritten > 0) {
    counters_.fifo_bytes_overwritten += overwritten;
    ++counters_.fifo_overflow_events;
    raiseInterrupt(reg::FIFO_OFLOW_INT, reg::FIFO_OFLOW_EN, t_ns);
  }
}

std::uint8_t MockMpu6050::popFifo() {
  if (fifo_.empty()) {
    ++counters_.fifo_empty_reads;
  } else {
    ++counters_.fifo_bytes_read;
  }
  return fifo_.pop();
}

void MockMpu6050::forceFifoOverflow(std::int64_t t_ns) {
  ++counters_.forced_fifo_overflows;
  std::array<std::uint8_t, 14> frame{};
  std::size_t n = buildFrame(frame.data());
  if (n == 0) n = 1;  // nothing enabled: fill with zero bytes
  const std::uint64_t overflows_before = counters_.fifo_overflow_events;
  while (counters_.fifo_overflow_events == overflows_before) pushFifo(frame.data(), n, t_ns);
}

}  // namespace gyrod::driver
