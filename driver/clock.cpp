#include "driver/clock.hpp"

#include <time.h>

#include <stdexcept>
#include <string>

namespace gyrod::driver {

void VirtualClock::advanceNs(std::int64_t delta_ns) {
  if (delta_ns < 0) {
    throw std::invalid_argument("VirtualClock::advanceNs: delta_ns must be >= 0, got " + std::to_string(delta_ns));
  }
  now_ns_ += delta_ns;
}

void VirtualClock::setNs(std::int64_t t_ns) {
  if (t_ns < now_ns_) {
    throw std::invalid_argument("VirtualClock::setNs: time may not go backwards (now " + std::to_string(now_ns_) +
                                " ns, asked " + std::to_string(t_ns) + " ns)");
  }
  now_ns_ = t_ns;
}

std::int64_t MonotonicClock::nowNs() const {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

}  // namespace gyrod::driver
