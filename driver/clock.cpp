#include "driver/clock.hpp"

#include <time.h>

#include <stdexcept>
#include <string>

namespace gyrod::driver {
namespace {

std::int64_t readNs(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

}  // namespace

std::int64_t measureRealtimeOffsetNs(std::int64_t* uncertainty_ns) {
  // Through the vDSO a pair spans < 100 ns; one preempted between its reads (on a busy host,
  // 1 in 10^4: up to a scheduler slice) is not believed: the narrowest of up to 3 pairs is kept.
  constexpr std::int64_t kGoodSpanNs = 2'000;
  std::int64_t best_offset = 0, best_span = INT64_MAX;
  for (int attempt = 0; attempt < 3 && best_span > kGoodSpanNs; ++attempt) {
    const std::int64_t before = readNs(CLOCK_MONOTONIC);
    const std::int64_t real = readNs(CLOCK_REALTIME);
    const std::int64_t after = readNs(CLOCK_MONOTONIC);
    if (after - before < best_span) {
      best_span = after - before;
      best_offset = real - (before + best_span / 2);
    }
  }
  if (uncertainty_ns) *uncertainty_ns = (best_span + 1) / 2;
  return best_offset;
}

std::int64_t Clock::realtimeOffsetNs() const { return measureRealtimeOffsetNs(); }

VirtualClock::VirtualClock(std::int64_t start_ns)
    : now_ns_(start_ns), realtime_offset_ns_(readNs(CLOCK_REALTIME) - start_ns) {}

void VirtualClock::advanceNs(std::int64_t delta_ns) {
  if (delta_ns < 0) {
    throw std::invalid_argument("the simulated clock cannot go back: a step of " + std::to_string(delta_ns) + " ns");
  }
  now_ns_ += delta_ns;
}

void VirtualClock::setNs(std::int64_t t_ns) {
  if (t_ns < now_ns_) {
    throw std::invalid_argument("the simulated clock cannot go back (now " + std::to_string(now_ns_) + " ns, asked " +
                                std::to_string(t_ns) + " ns)");
  }
  now_ns_ = t_ns;
}

std::int64_t MonotonicClock::nowNs() const { return readNs(CLOCK_MONOTONIC); }

}  // namespace gyrod::driver
