#pragma once
// The name of every driver counter, as STATUS publishes it ("counters", docs/protocol.md).
// One table, read by the daemon to fill STATUS and by the test that checks the doc.
#include <array>
#include <cstdint>
#include <string_view>

#include "driver/mpu6050_types.hpp"

namespace gyrod::driver {

struct CounterName {
  std::string_view name;
  std::uint64_t DriverCounters::*member;
};

inline constexpr std::array<CounterName, 20> kDriverCounterNames = {{
    {"transfers_failed", &DriverCounters::transfers_failed},
    {"retries", &DriverCounters::retries},
    {"operations_failed", &DriverCounters::operations_failed},
    {"fifo_overflows", &DriverCounters::fifo_overflows},
    {"fifo_resets", &DriverCounters::fifo_resets},
    {"misaligned_bursts", &DriverCounters::misaligned_bursts},
    {"fifo_transfer_errors", &DriverCounters::fifo_transfer_errors},
    {"device_resets", &DriverCounters::device_resets},
    {"configures", &DriverCounters::configures},
    {"silent_resets", &DriverCounters::silent_resets},
    {"recoveries", &DriverCounters::recoveries},
    {"data_ready_missed", &DriverCounters::data_ready_missed},
    {"empty_wakeups", &DriverCounters::empty_wakeups},
    {"backlog_capped", &DriverCounters::backlog_capped},
    {"samples_delivered", &DriverCounters::samples_delivered},
    {"samples_lost", &DriverCounters::samples_lost},
    {"gaps", &DriverCounters::gaps},
    {"timestamp_rejections", &DriverCounters::timestamp_rejections},
    {"timestamp_relocks", &DriverCounters::timestamp_relocks},
    {"register_checks", &DriverCounters::register_checks},
}};

// A counter added to DriverCounters without a name here would be missing from STATUS.
static_assert(sizeof(DriverCounters) == kDriverCounterNames.size() * sizeof(std::uint64_t),
              "every DriverCounters member needs an entry in kDriverCounterNames");

}  // namespace gyrod::driver
