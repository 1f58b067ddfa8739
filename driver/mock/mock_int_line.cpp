// The INT line: the pin and the stuck-line fault (IntLine), the host's edge queue and fd
// (HostDataReadyLine), and when the chip raises and clears interrupts.
#include <sys/timerfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <stdexcept>
#include <system_error>

#include "driver/mock/int_line.hpp"
#include "driver/mock/mock_mpu6050.hpp"

namespace gyrod::driver {
namespace mock {

HostDataReadyLine::HostDataReadyLine(Clock& clock, ChipTimeline& chip, EdgeDirection direction, std::size_t depth)
    : clock_(clock), chip_(chip), direction_(direction) {
  if (depth == 0) throw std::invalid_argument("MockMpu6050Config.data_ready_queue_depth must be > 0");
  queue_.assign(depth, 0);
  fd_ = timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
  if (fd_ < 0) throw std::system_error(errno, std::generic_category(), "timerfd_create for the mock data-ready line");
}

HostDataReadyLine::~HostDataReadyLine() {
  if (fd_ >= 0) ::close(fd_);
}

void HostDataReadyLine::lineMoved(std::int64_t t_ns, bool rising) {
  const bool wanted = direction_ == EdgeDirection::Both || (direction_ == EdgeDirection::Rising) == rising;
  if (!wanted) return;
  if (count_ == queue_.size()) {
    ++dropped_;  // like the kernel's line-event FIFO: the new event is lost
    return;
  }
  queue_[(head_ + count_) % queue_.size()] = t_ns;
  ++count_;
}

void HostDataReadyLine::updateReadiness(bool force) {
  // A timerfd stands in for the GPIO event fd: no thread is needed, and in real-time mode
  // it wakes the loop when the chip can next move the INT line.
  std::int64_t at = 0;  // disarmed
  if (count_ > 0) {
    at = 1;  // an absolute time long past: expires at once
  } else if (clock_.isRealTime()) {
    const std::int64_t next = chip_.nextPossibleEdgeNs();
    if (next != kNever) at = std::max<std::int64_t>(next, 1);
  }
  if (at == armed_at_ns_ && !force) return;
  itimerspec spec{};
  spec.it_value.tv_sec = static_cast<time_t>(at / kNsPerSecond);
  spec.it_value.tv_nsec = static_cast<long>(at % kNsPerSecond);
  if (timerfd_settime(fd_, TFD_TIMER_ABSTIME, &spec, nullptr) == 0) armed_at_ns_ = at;
}

int HostDataReadyLine::consumeEdge(std::int64_t& timestamp_ns) {
  chip_.advanceTo(clock_.nowNs());
  if (count_ == 0) {
    // Re-arm and clear a stale expiry. Only real time can have one (a wake-up armed for a
    // possible edge that did not come); in virtual time the timer is disarmed whenever the
    // queue is empty, and the forced timerfd_settime would be a wasted system call.
    updateReadiness(clock_.isRealTime());
    return -EAGAIN;
  }
  timestamp_ns = queue_[head_];
  head_ = (head_ + 1) % queue_.size();
  --count_;
  updateReadiness();
  return 0;
}

void IntLine::notifyIfMoved(bool was_high, std::int64_t t_ns) {
  const bool now_high = high();
  if (now_high != was_high) host_.lineMoved(t_ns, now_high);
}

void IntLine::setPinActive(bool active, std::int64_t t_ns) {
  if (pin_active_ == active) return;
  const bool was_chip_high = chipHigh();
  const bool was_high = high();
  pin_active_ = active;
  if (stuck_ && chipHigh() != was_chip_high) ++hidden_edges_;
  notifyIfMoved(was_high, t_ns);
}

void IntLine::startPulse(std::int64_t t_ns) {
  setPinActive(true, t_ns);
  pulse_end_ns_ = t_ns + mpu6050::kIntPulseWidthNs;
}

void IntLine::endPulse(std::int64_t t_ns) {
  pulse_end_ns_ = kNever;
  setPinActive(false, t_ns);
}

void IntLine::configure(bool active_low, bool latched, bool status_pending, std::int64_t t_ns) {
  const bool was_high = high();
  active_low_ = active_low;
  if (!latched && pin_active_ && pulse_end_ns_ == kNever) {
    pin_active_ = false;  // leaving latch mode releases a held line
  } else if (latched && !pin_active_ && status_pending) {
    pin_active_ = true;
  }
  notifyIfMoved(was_high, t_ns);
}

void IntLine::powerOnReset(std::int64_t t_ns) {
  const bool was_high = high();
  active_low_ = false;
  pin_active_ = false;
  pulse_end_ns_ = kNever;
  notifyIfMoved(was_high, t_ns);
}

void IntLine::stick(bool level_high, std::int64_t t_ns) {
  const bool was_high = high();
  stuck_ = true;
  stuck_high_ = level_high;
  notifyIfMoved(was_high, t_ns);
}

void IntLine::unstick(std::int64_t t_ns) {
  const bool was_high = high();
  stuck_ = false;
  notifyIfMoved(was_high, t_ns);
}

}  // namespace mock

namespace reg = mpu6050;
using mpu6050::Register;

void MockMpu6050::raiseInterrupt(std::uint8_t status_bit, std::uint8_t enable_bit, std::int64_t t_ns) {
  // A status bit is set only for an enabled interrupt ("sets to 1 when a ... interrupt is
  // generated", RM Register 58); a driver must enable what it wants to see.
  if (!regs_.has(Register::INT_ENABLE, enable_bit)) return;
  if (status_bit == reg::DATA_RDY_INT) ++counters_.data_ready_interrupts;
  regs_[Register::INT_STATUS] |= status_bit;
  if (regs_.has(Register::INT_PIN_CFG, reg::LATCH_INT_EN)) {
    int_line_.setPinActive(true, t_ns);  // held until the status is cleared
  } else if (!int_line_.pinActive()) {
    int_line_.startPulse(t_ns);  // a 50 µs pulse
    recomputeNextEvent();
  }
}

void MockMpu6050::clearInterruptStatus(std::uint8_t bits, std::int64_t t_ns) {
  std::uint8_t& status = regs_[Register::INT_STATUS];
  status = static_cast<std::uint8_t>(status & ~bits);
  if (regs_.has(Register::INT_PIN_CFG, reg::LATCH_INT_EN) && status == 0) int_line_.setPinActive(false, t_ns);
}

bool MockMpu6050::intLineHigh() const { return int_line_.high(); }

}  // namespace gyrod::driver
