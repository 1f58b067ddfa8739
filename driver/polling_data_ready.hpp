#pragma once
// Data-ready without a wired INT pin: a periodic timer. Each expiry is reported as one
// "edge" whose time is when it was consumed; the driver then reads FIFO_COUNT (the sample
// clock is anchored from those reads, see DataReadyMode::Polling). The period must be short
// enough that the FIFO cannot overflow between polls: use pollingPeriodNs(config).
//
// On a real-time clock (MonotonicClock) the fd is a periodic CLOCK_MONOTONIC timerfd. On a
// virtual clock (tests) the same fd exists but is never armed; the caller asks
// nextPollNs() when to call the driver, and consumeEdge() compares with the virtual time.
#include <cstdint>

#include "driver/clock.hpp"
#include "driver/data_ready.hpp"
#include "protocol/fd.hpp"

namespace gyrod::driver {

class PollingDataReady final : public DataReadySource {
 public:
  // Throws std::invalid_argument for period_ns <= 0 and std::system_error when the timerfd
  // cannot be created or armed.
  PollingDataReady(const Clock& clock, std::int64_t period_ns);
  ~PollingDataReady() override;
  PollingDataReady(const PollingDataReady&) = delete;
  PollingDataReady& operator=(const PollingDataReady&) = delete;

  int fd() const override { return fd_.get(); }
  // 0 with the current time when at least one period has elapsed since the last poll
  // (several elapsed periods are one poll: the FIFO holds the data), else -EAGAIN.
  [[nodiscard]] int consumeEdge(std::int64_t& timestamp_ns) override;
  // Polls are never queued, so none can be dropped.
  std::uint64_t edgesDropped() const override { return 0; }

  std::int64_t periodNs() const { return period_ns_; }
  // Clock time of the next poll (virtual-time tests step to it).
  std::int64_t nextPollNs() const { return next_poll_ns_; }

 private:
  const Clock& clock_;
  std::int64_t period_ns_;
  std::int64_t next_poll_ns_;
  protocol::Fd fd_;
};

}  // namespace gyrod::driver
