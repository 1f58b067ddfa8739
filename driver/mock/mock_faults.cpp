// Faults: a new plan, and what each scheduled fault does to the chip. The plan's checks,
// its timeline and the transfer errors are mock::FaultSchedule's (fault_schedule.cpp).
#include <algorithm>
#include <stdexcept>
#include <utility>

#include "driver/mock/mock_mpu6050.hpp"

namespace gyrod::driver {

void MockMpu6050::setFaultPlan(const FaultPlan& plan) {
  sync();
  std::vector<mock::FaultEvent> events = mock::FaultSchedule::timeline(plan, epoch_ns_, now_ns_ - epoch_ns_);

  // A new plan ends whatever the old one had started.
  faults_.replace(plan, std::move(events));
  glitches_.clear();
  next_glitch_ = 0;
  for (const GlitchBurst& g : plan.glitch_bursts) {
    if (g.axis < 0 || g.axis > 2 || g.bit < 0 || g.bit > 15 || g.count == 0 || g.duration_ns < 0 || g.start_ns < 0)
      throw std::invalid_argument("FaultPlan.glitch_bursts: axis 0..2, bit 0..15, count >= 1, times >= 0");
    for (std::uint32_t k = 0; k < g.count; ++k)
      glitches_.push_back(
          {g.start_ns + static_cast<std::int64_t>(static_cast<double>(g.duration_ns) * static_cast<double>(k) /
                                                  static_cast<double>(g.count)),
           g.axis, g.bit});
  }
  std::sort(glitches_.begin(), glitches_.end(), [](const Glitch& a, const Glitch& b) { return a.at_ns < b.at_ns; });
  while (next_glitch_ < glitches_.size() && glitches_[next_glitch_].at_ns < now_ns_ - epoch_ns_) ++next_glitch_;
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
