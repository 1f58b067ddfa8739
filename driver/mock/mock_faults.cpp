// Faults: a new plan, and what each scheduled fault does to the chip. The plan's checks,
// its timeline and the transfer errors are mock::FaultSchedule's (fault_schedule.cpp).
#include <utility>

#include "driver/mock/mock_mpu6050.hpp"

namespace gyrod::driver {

void MockMpu6050::setFaultPlan(const FaultPlan& plan) {
  sync();
  std::vector<mock::FaultEvent> events = mock::FaultSchedule::timeline(plan, epoch_ns_, now_ns_ - epoch_ns_);

  // A new plan ends whatever the old one had started.
  faults_.replace(plan, std::move(events));
  if (!powered_) {
    powered_ = true;
    resetChip();
  }
  int_line_.unstick(now_ns_);
  recomputeNextEvent();
  int_line_.host().updateReadiness(true);
}

void MockMpu6050::applyFaultEvent(const mock::FaultEvent& event, std::int64_t t_ns) {
  using Kind = mock::FaultEventKind;
  const FaultPlan& plan = faults_.plan();
  switch (event.kind) {
    case Kind::BurstStart: faults_.startBurst(event.index); break;
    case Kind::OutageStart:
      faults_.startOutage(event.index);
      ++counters_.outages_started;
      if (plan.outages[event.index].power_lost) {
        resetChip();
        powered_ = false;
        updateSampling();
      }
      break;
    case Kind::OutageEnd:
      faults_.endOutage();
      if (plan.outages[event.index].power_lost) {
        powered_ = true;
        resetChip();  // power-on state: reset values, asleep
      }
      break;
    case Kind::Brownout:
      ++counters_.brownouts;
      resetChip();
      break;
    case Kind::ForcedOverflow: forceFifoOverflow(t_ns); break;
    case Kind::StuckStart: int_line_.stick(plan.stuck_data_ready[event.index].level_high, t_ns); break;
    case Kind::StuckEnd: int_line_.unstick(t_ns); break;
  }
}

}  // namespace gyrod::driver
