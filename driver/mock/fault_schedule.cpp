#include "driver/mock/fault_schedule.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "driver/mock/mock_random.hpp"

namespace gyrod::driver::mock {
namespace {

void checkErrno(int e, const std::string& what) {
  if (e <= 0) throw std::invalid_argument(what + ": error must be a positive errno value, got " + std::to_string(e));
}

void checkDuration(std::int64_t d, const std::string& what) {
  if (d <= 0) throw std::invalid_argument(what + ": duration_ns must be > 0, got " + std::to_string(d));
}

// Builds the timeline while checking each entry against the current sensor time.
class TimelineBuilder {
 public:
  TimelineBuilder(std::int64_t epoch_ns, std::int64_t now_sensor_ns) : epoch_ns_(epoch_ns), now_(now_sensor_ns) {}

  void checkTime(std::int64_t t, const std::string& what) const {
    if (t < now_) {
      throw std::invalid_argument(what + " at " + std::to_string(t) + " ns is before the current sensor time " +
                                  std::to_string(now_) + " ns");
    }
  }

  void add(std::int64_t sensor_ns, FaultEventKind kind, std::size_t index) {
    events_.push_back({epoch_ns_ + sensor_ns, kind, index});
  }

  // Outages and stuck lines: a start and an end event each; windows of one kind must not
  // overlap.
  template <typename Window>
  void addWindows(const std::vector<Window>& windows, const char* name, FaultEventKind start, FaultEventKind end) {
    std::vector<std::pair<std::int64_t, std::int64_t>> spans;
    for (std::size_t i = 0; i < windows.size(); ++i) {
      const std::string what = std::string("FaultPlan.") + name + "[" + std::to_string(i) + "]";
      checkTime(windows[i].start_ns, what);
      checkDuration(windows[i].duration_ns, what);
      spans.emplace_back(windows[i].start_ns, windows[i].start_ns + windows[i].duration_ns);
      add(windows[i].start_ns, start, i);
      add(windows[i].start_ns + windows[i].duration_ns, end, i);
    }
    std::sort(spans.begin(), spans.end());
    for (std::size_t i = 1; i < spans.size(); ++i) {
      if (spans[i].first < spans[i - 1].second) {
        throw std::invalid_argument(std::string("FaultPlan.") + name + ": windows overlap (one starts at " +
                                    std::to_string(spans[i].first) + " ns, before the previous ends at " +
                                    std::to_string(spans[i - 1].second) + " ns)");
      }
    }
  }

  std::vector<FaultEvent> sorted() && {
    // Same instant: ends before starts (FaultEventKind order).
    std::stable_sort(events_.begin(), events_.end(), [](const FaultEvent& a, const FaultEvent& b) {
      return a.time_ns != b.time_ns ? a.time_ns < b.time_ns : a.kind < b.kind;
    });
    return std::move(events_);
  }

 private:
  std::int64_t epoch_ns_;
  std::int64_t now_;
  std::vector<FaultEvent> events_;
};

}  // namespace

std::vector<FaultEvent> FaultSchedule::timeline(const FaultPlan& plan, std::int64_t epoch_ns,
                                                std::int64_t now_sensor_ns) {
  const double p = plan.random_errors.probability;
  if (!(p >= 0.0 && p <= 1.0)) {
    throw std::invalid_argument("FaultPlan.random_errors.probability must be within 0..1, got " + std::to_string(p));
  }
  checkErrno(plan.random_errors.error, "FaultPlan.random_errors");

  TimelineBuilder events(epoch_ns, now_sensor_ns);
  for (std::size_t i = 0; i < plan.error_bursts.size(); ++i) {
    const auto& b = plan.error_bursts[i];
    const std::string what = "FaultPlan.error_bursts[" + std::to_string(i) + "]";
    checkErrno(b.error, what);
    events.checkTime(b.start_ns, what);
    events.add(b.start_ns, FaultEventKind::BurstStart, i);
  }
  for (std::size_t i = 0; i < plan.outages.size(); ++i) {
    checkErrno(plan.outages[i].error, "FaultPlan.outages[" + std::to_string(i) + "]");
  }
  events.addWindows(plan.outages, "outages", FaultEventKind::OutageStart, FaultEventKind::OutageEnd);
  events.addWindows(plan.stuck_data_ready, "stuck_data_ready", FaultEventKind::StuckStart, FaultEventKind::StuckEnd);
  for (std::size_t i = 0; i < plan.brownouts_ns.size(); ++i) {
    events.checkTime(plan.brownouts_ns[i], "FaultPlan.brownouts_ns[" + std::to_string(i) + "]");
    events.add(plan.brownouts_ns[i], FaultEventKind::Brownout, i);
  }
  for (std::size_t i = 0; i < plan.forced_fifo_overflows_ns.size(); ++i) {
    events.checkTime(plan.forced_fifo_overflows_ns[i], "FaultPlan.forced_fifo_overflows_ns[" + std::to_string(i) + "]");
    events.add(plan.forced_fifo_overflows_ns[i], FaultEventKind::ForcedOverflow, i);
  }
  return std::move(events).sorted();
}

void FaultSchedule::replace(const FaultPlan& plan, std::vector<FaultEvent> events) {
  plan_ = plan;
  events_ = std::move(events);
  next_ = 0;
  transfer_rng_ = processing::SplitMix64(plan.random_errors.seed);
  burst_remaining_ = 0;
  outage_ = false;
}

void FaultSchedule::startBurst(std::size_t index) {
  burst_remaining_ += plan_.error_bursts[index].transfers;
  burst_error_ = plan_.error_bursts[index].error;
}

void FaultSchedule::startOutage(std::size_t index) {
  outage_ = true;
  outage_error_ = plan_.outages[index].error;
}

int FaultSchedule::drawTransferError(MockCounters& counters) {
  if (burst_remaining_ > 0) {
    --burst_remaining_;
    ++counters.injected_burst_errors;
    return burst_error_;
  }
  if (plan_.random_errors.probability > 0.0 && uniform01(transfer_rng_) < plan_.random_errors.probability) {
    ++counters.injected_random_errors;
    return plan_.random_errors.error;
  }
  return 0;
}

}  // namespace gyrod::driver::mock
