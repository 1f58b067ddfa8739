#pragma once
// Time for the mock device: a virtual clock that tests advance by hand (an hour of sensor
// time in about a second), or CLOCK_MONOTONIC for the demo. Both count nanoseconds on the
// CLOCK_MONOTONIC time line, so data-ready timestamps look the same to a driver.
#include <cstdint>

namespace gyrod::driver {

class Clock {
 public:
  virtual ~Clock() = default;
  virtual std::int64_t nowNs() const = 0;
  // True when nowNs() is the real CLOCK_MONOTONIC, so a timerfd can wait for a time on it.
  virtual bool isRealTime() const = 0;
};

// Starts at `start_ns` and moves only when told to; never backwards.
class VirtualClock final : public Clock {
 public:
  explicit VirtualClock(std::int64_t start_ns = 0) : now_ns_(start_ns) {}
  std::int64_t nowNs() const override { return now_ns_; }
  bool isRealTime() const override { return false; }
  // Throws std::invalid_argument for a negative step or a time before now.
  void advanceNs(std::int64_t delta_ns);
  void setNs(std::int64_t t_ns);

 private:
  std::int64_t now_ns_;
};

class MonotonicClock final : public Clock {
 public:
  std::int64_t nowNs() const override;
  bool isRealTime() const override { return true; }
};

inline constexpr std::int64_t kNsPerSecond = 1'000'000'000;
inline constexpr std::int64_t kNsPerMillisecond = 1'000'000;

}  // namespace gyrod::driver
