#pragma once
// The mock MPU-6050's fault schedule: a FaultPlan checked and turned into a timeline of
// clock-time events, and the bus-side fault state those events drive (error bursts, the
// outage in progress, random transfer errors from their own seeded stream). What an event
// does to the chip (power loss, brown-out, forced overflow, a stuck INT line) is the
// chip's business (MockMpu6050::applyFaultEvent, mock_faults.cpp).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "driver/mock/mock_faults.hpp"
#include "driver/mock/mock_time.hpp"
#include "processing/base/portable_random.hpp"

namespace gyrod::driver::mock {

// Declaration order is the order of events at the same instant: ends before starts, so
// back-to-back windows work.
enum class FaultEventKind : std::uint8_t {
  OutageEnd,
  StuckEnd,
  OutageStart,
  StuckStart,
  BurstStart,
  Brownout,
  ForcedOverflow,
};

struct FaultEvent {
  std::int64_t time_ns;  // clock time
  FaultEventKind kind;
  std::size_t index;  // into the plan's vector of that kind
};

class FaultSchedule {
 public:
  // The plan's events in clock time (epoch_ns + sensor time), sorted. Throws
  // std::invalid_argument for a probability outside 0..1, a non-positive errno, a
  // non-positive duration, an event before now_sensor_ns, or overlapping windows.
  static std::vector<FaultEvent> timeline(const FaultPlan& plan, std::int64_t epoch_ns, std::int64_t now_sensor_ns);

  // Replaces the plan: events from the start, random errors reseeded, no burst pending,
  // no outage. `events` is timeline(plan, ...).
  void replace(const FaultPlan& plan, std::vector<FaultEvent> events);

  const FaultPlan& plan() const { return plan_; }
  // Clock time of the next event not yet taken, kNever if none.
  std::int64_t nextEventNs() const { return next_ < events_.size() ? events_[next_].time_ns : kNever; }
  FaultEvent takeNextEvent() { return events_[next_++]; }

  // Bus-side effects of BurstStart, OutageStart and OutageEnd.
  void startBurst(std::size_t index);
  void startOutage(std::size_t index);
  void endOutage() { outage_ = false; }
  bool inOutage() const { return outage_; }
  int outageError() const { return outage_error_; }

  // The error the plan injects into the next transfer (a burst first, then the random
  // errors), counted in `counters`; 0 for none.
  int drawTransferError(MockCounters& counters);
  // WHO_AM_I as the plan fakes it, if it does.
  std::optional<std::uint8_t> fakeWhoAmI() const { return plan_.who_am_i; }
  bool errorsAfterTransfer() const { return plan_.injected_errors_after_transfer; }

 private:
  FaultPlan plan_;
  std::vector<FaultEvent> events_;
  std::size_t next_ = 0;
  processing::SplitMix64 transfer_rng_{1};
  std::uint32_t burst_remaining_ = 0;
  int burst_error_ = EIO;
  bool outage_ = false;
  int outage_error_ = EREMOTEIO;
};

}  // namespace gyrod::driver::mock
