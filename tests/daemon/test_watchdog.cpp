// The watchdog timing daemon/watchdog.hpp documents, simulated: gyrod's ping timer (every
// W/2 from start), samples every 20 ms that stop or pause, and systemd's rule (restart when no
// WATCHDOG=1 came for W).
#include "daemon/watchdog.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <optional>

using namespace gyrod::daemon;

namespace {

constexpr std::uint64_t kWatchdogUsec = 10'000'000;  // WatchdogSec=10s, as in gyrod.service
constexpr std::int64_t kW = static_cast<std::int64_t>(kWatchdogUsec) * 1000;
constexpr std::int64_t kSamplePeriod = 20'000'000;  // 50 Hz
constexpr std::int64_t kStart = 1'000'000'000;      // gyrod's start on the monotonic clock

// Samples from kStart + kSamplePeriod to `last`, none in (last, resume), again from `resume` on.
// Returns when systemd restarts gyrod (ns), or nothing within `until`.
std::optional<std::int64_t> simulatedRestart(std::int64_t last, std::int64_t resume, std::int64_t until) {
  const std::int64_t period = std::chrono::nanoseconds(watchdogPingPeriod(kWatchdogUsec)).count();
  std::int64_t last_ping = kStart;  // systemd counts from READY=1, sent at start
  for (std::int64_t tick = kStart + period; tick <= until; tick += period) {
    if (tick - last_ping >= kW) return last_ping + kW;
    std::int64_t newest = 0;  // the newest sample at `tick`
    const std::int64_t before = tick >= resume ? tick : std::min(tick, last);
    if (before > kStart) newest = kStart + (before - kStart) / kSamplePeriod * kSamplePeriod;
    if (watchdogPingDue(tick, newest, kWatchdogUsec)) last_ping = tick;
  }
  if (until - last_ping >= kW) return last_ping + kW;
  return std::nullopt;
}

}  // namespace

TEST(Watchdog, PingsEveryHalfWatchdogSecAndOnlyAfterASampleYoungerThanWatchdogSec) {
  EXPECT_EQ(watchdogPingPeriod(kWatchdogUsec), std::chrono::seconds(5));
  EXPECT_FALSE(watchdogPingDue(kStart, 0, kWatchdogUsec));  // no sample yet
  EXPECT_TRUE(watchdogPingDue(kStart + kW - 1, kStart, kWatchdogUsec));
  EXPECT_FALSE(watchdogPingDue(kStart + kW, kStart, kWatchdogUsec));
}

TEST(Watchdog, ASensorThatStopsIsRestartedBetweenOneAndAHalfAndTwoWatchdogSecAfterItsLastSample) {
  // Every phase of the last sample against the ping timer, in steps of one sample.
  const std::int64_t period = kW / 2;
  for (std::int64_t last = 60 * kW; last < 60 * kW + period; last += kSamplePeriod) {
    const auto restart = simulatedRestart(last, INT64_MAX, last + 3 * kW);
    ASSERT_TRUE(restart.has_value()) << last;
    const std::int64_t newest = kStart + (last - kStart) / kSamplePeriod * kSamplePeriod;
    EXPECT_GE(*restart - newest, kW + kW / 2) << "last sample at " << newest;
    EXPECT_LE(*restart - newest, 2 * kW) << "last sample at " << newest;
  }
}

TEST(Watchdog, AnOutageShorterThanWatchdogSecNeverRestartsGyrod) {
  const std::int64_t period = kW / 2;
  for (std::int64_t last = 60 * kW; last < 60 * kW + period; last += kSamplePeriod) {
    EXPECT_FALSE(simulatedRestart(last, last + kW - kSamplePeriod, last + 10 * kW).has_value()) << last;
    EXPECT_TRUE(simulatedRestart(last, last + 3 * kW, last + 10 * kW).has_value()) << last;  // a longer one does
  }
}
