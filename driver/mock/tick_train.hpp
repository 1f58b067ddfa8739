#pragma once
// The mock MPU-6050's sample clock: internal tick k (k ≥ 1) happens at
// anchor + round(k · period), so rounding never accumulates; every (1 + SMPLRT_DIV)-th
// tick is a sample.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include "driver/mock/mock_time.hpp"

namespace gyrod::driver::mock {

class TickTrain {
 public:
  bool running() const { return running_; }
  // Clock time of the next internal tick, kNever when stopped.
  std::int64_t nextTickNs() const { return next_tick_ns_; }

  // Starts ticking one period after t_ns, with the sample count from zero.
  void start(std::int64_t t_ns, double period_ns) {
    running_ = true;
    restart(t_ns, period_ns);
    ticks_since_sample_ = 0;
  }
  // A new period from t_ns on (a new internal rate); the sample count carries on.
  void restart(std::int64_t t_ns, double period_ns) {
    anchor_ns_ = t_ns;
    period_ns_ = period_ns;
    tick_index_ = 1;
    next_tick_ns_ = tickTimeNs(1);
  }
  void stop() {
    running_ = false;
    next_tick_ns_ = kNever;
  }
  void restartSampleCount() { ticks_since_sample_ = 0; }

  // Takes the next tick: returns its time and schedules the one after.
  std::int64_t takeTick() {
    const std::int64_t t = next_tick_ns_;
    ++tick_index_;
    next_tick_ns_ = tickTimeNs(tick_index_);
    return t;
  }
  // Counts a tick towards the next sample; true when this tick is a sample.
  bool countTowardsSample(int sample_rate_divider) {
    if (++ticks_since_sample_ > sample_rate_divider) {
      ticks_since_sample_ = 0;
      return true;
    }
    return false;
  }
  // Clock time of the next sample tick, if running.
  std::optional<std::int64_t> nextSampleNs(int sample_rate_divider) const {
    if (!running_) return std::nullopt;
    const int ticks_per_sample = sample_rate_divider + 1;
    const std::int64_t remaining = std::max(1, ticks_per_sample - ticks_since_sample_);
    return tickTimeNs(tick_index_ + remaining - 1);
  }

 private:
  std::int64_t tickTimeNs(std::int64_t k) const {
    return anchor_ns_ + std::llround(static_cast<double>(k) * period_ns_);
  }

  bool running_ = false;
  std::int64_t anchor_ns_ = 0;
  double period_ns_ = 0.0;
  std::int64_t tick_index_ = 1;
  std::int64_t next_tick_ns_ = kNever;
  int ticks_since_sample_ = 0;
};

}  // namespace gyrod::driver::mock
