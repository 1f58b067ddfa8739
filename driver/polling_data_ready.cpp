#include "driver/polling_data_ready.hpp"

#include <sys/timerfd.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>
#include <string>
#include <system_error>

namespace gyrod::driver {

PollingDataReady::PollingDataReady(const Clock& clock, std::int64_t period_ns)
    : clock_(clock), period_ns_(period_ns), next_poll_ns_(clock.nowNs() + period_ns) {
  if (period_ns <= 0) {
    throw std::invalid_argument("the data-ready poll needs a period > 0 ns, got " + std::to_string(period_ns));
  }
  fd_.reset(timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC));
  if (!fd_) throw std::system_error(errno, std::generic_category(), "timerfd_create for FIFO polling");
  if (clock_.isRealTime()) {
    itimerspec spec{};
    spec.it_interval.tv_sec = static_cast<time_t>(period_ns / kNsPerSecond);
    spec.it_interval.tv_nsec = static_cast<long>(period_ns % kNsPerSecond);
    spec.it_value = spec.it_interval;
    if (timerfd_settime(fd_.get(), 0, &spec, nullptr) != 0)
      throw std::system_error(errno, std::generic_category(), "timerfd_settime for FIFO polling");
  }
}

PollingDataReady::~PollingDataReady() = default;

int PollingDataReady::consumeEdge(std::int64_t& timestamp_ns) {
  const std::int64_t now = clock_.nowNs();
  if (clock_.isRealTime()) {
    std::uint64_t expirations = 0;
    const ssize_t n = ::read(fd_.get(), &expirations, sizeof expirations);
    if (n != static_cast<ssize_t>(sizeof expirations)) return n < 0 && errno != EAGAIN ? -errno : -EAGAIN;
  } else if (now < next_poll_ns_) {
    return -EAGAIN;
  }
  // Next poll one period after the last due one, skipping any that were missed.
  if (next_poll_ns_ <= now) next_poll_ns_ += ((now - next_poll_ns_) / period_ns_ + 1) * period_ns_;
  timestamp_ns = now;
  return 0;
}

}  // namespace gyrod::driver
