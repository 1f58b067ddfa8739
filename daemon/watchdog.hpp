#pragma once
// systemd's watchdog (WatchdogSec= in gyrod.service): systemd kills and restarts the service
// when WATCHDOG=1 has not come for WatchdogSec (the W that sd_watchdog_enabled returns).
// gyrod sends it from a timer every W/2, as sd_watchdog_enabled(3) recommends (a ping delayed
// by up to W/2 of scheduling still arrives in time), and only while its newest sample is
// younger than W: a timer that pinged blindly would keep a dead sensor's gyrod running.
// What follows for a sensor that stops (tests/daemon/test_watchdog.cpp simulates it):
//  - the last ping comes within W/2 before the newest sample turns W old, and systemd restarts
//    gyrod W after that ping: between 1.5 W and 2 W after the last sample (15-20 s at
//    WatchdogSec=10s; the systemd VM measured 24-26 s, the stop and the new start included);
//  - an outage shorter than W (a device reset, a bus that recovers) never restarts gyrod.
#include <chrono>
#include <cstdint>

namespace gyrod::daemon {

// The period of the ping timer for sd_watchdog_enabled's `watchdog_usec`.
constexpr std::chrono::microseconds watchdogPingPeriod(std::uint64_t watchdog_usec) {
  return std::chrono::microseconds(watchdog_usec / 2);
}

// Whether the ping timer sends WATCHDOG=1 at `now_ns`, the newest sample having arrived at
// `last_sample_ns` (monotonic clock; 0: no sample yet).
constexpr bool watchdogPingDue(std::int64_t now_ns, std::int64_t last_sample_ns, std::uint64_t watchdog_usec) {
  return last_sample_ns != 0 && now_ns - last_sample_ns < static_cast<std::int64_t>(watchdog_usec) * 1000;
}

}  // namespace gyrod::daemon
