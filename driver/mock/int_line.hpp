#pragma once
// The mock MPU-6050's INT line, from the chip's output pin to the host's edge events:
//  - the pin: active or not, its polarity (INT_PIN_CFG.INT_LEVEL) and the 50 µs pulse;
//  - the stuck-line fault, which holds the level the host sees;
//  - the host side (HostDataReadyLine): edges queued as a GPIO line-event FIFO would, and
//    an fd that is readable while one is pending.
// When the chip raises or clears an interrupt is the chip's business (mock_int_line.cpp).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "driver/clock.hpp"
#include "driver/data_ready.hpp"
#include "driver/mock/mock_time.hpp"

namespace gyrod::driver::mock {

// What the host side needs from the chip: to catch it up to the clock before looking
// for edges, and when it could next move the line (to wake a real-time loop).
class ChipTimeline {
 public:
  virtual void advanceTo(std::int64_t t_ns) = 0;
  // kNever when nothing is scheduled that could move the line.
  virtual std::int64_t nextPossibleEdgeNs() const = 0;

 protected:
  ~ChipTimeline() = default;
};

class HostDataReadyLine final : public DataReadySource {
 public:
  // Throws std::invalid_argument for depth 0 and std::system_error when the timerfd
  // cannot be created.
  HostDataReadyLine(Clock& clock, ChipTimeline& chip, EdgeDirection direction, std::size_t depth);
  ~HostDataReadyLine() override;
  HostDataReadyLine(const HostDataReadyLine&) = delete;
  HostDataReadyLine& operator=(const HostDataReadyLine&) = delete;

  int fd() const override { return fd_; }
  [[nodiscard]] int consumeEdge(std::int64_t& timestamp_ns) override;
  std::uint64_t edgesDropped() const override { return dropped_; }

  // The level the host sees changed at t_ns.
  void lineMoved(std::int64_t t_ns, bool rising);
  // Arms the timerfd: now if an edge is queued; in real-time mode, at the next time the
  // chip could move the line; otherwise disarmed.
  void updateReadiness(bool force = false);

 private:
  Clock& clock_;
  ChipTimeline& chip_;
  int fd_ = -1;
  EdgeDirection direction_;
  std::vector<std::int64_t> queue_;  // ring, allocated once
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::uint64_t dropped_ = 0;
  std::int64_t armed_at_ns_ = -1;  // what the timerfd is set to; 0 = disarmed
};

class IntLine {
 public:
  // `hidden_edges` counts the chip's edges the host could not see while the line was stuck.
  IntLine(Clock& clock, ChipTimeline& chip, EdgeDirection direction, std::size_t depth, std::uint64_t& hidden_edges)
      : host_(clock, chip, direction, depth), hidden_edges_(hidden_edges) {}

  // Electrical level as the host sees it (after any stuck-line fault).
  bool high() const { return stuck_ ? stuck_high_ : chipHigh(); }
  bool pinActive() const { return pin_active_; }
  // Clock time the current pulse ends, kNever when none is running.
  std::int64_t pulseEndNs() const { return pulse_end_ns_; }

  void setPinActive(bool active, std::int64_t t_ns);
  // A pulse of kIntPulseWidthNs (the non-latched mode); the chip ends it at pulseEndNs().
  void startPulse(std::int64_t t_ns);
  void endPulse(std::int64_t t_ns);
  // INT_PIN_CFG written: the new polarity, and whether the pin is now held. Leaving latch
  // mode releases a held line; entering it with a status bit set holds the line.
  void configure(bool active_low, bool latched, bool status_pending, std::int64_t t_ns);
  // Power-on state: inactive, active high, no pulse (a stuck fault stays).
  void powerOnReset(std::int64_t t_ns);

  void stick(bool level_high, std::int64_t t_ns);
  void unstick(std::int64_t t_ns);

  HostDataReadyLine& host() { return host_; }

 private:
  bool chipHigh() const { return pin_active_ != active_low_; }
  void notifyIfMoved(bool was_high, std::int64_t t_ns);

  HostDataReadyLine host_;
  std::uint64_t& hidden_edges_;
  bool active_low_ = false;  // mirrors INT_PIN_CFG.INT_LEVEL
  bool pin_active_ = false;
  std::int64_t pulse_end_ns_ = kNever;
  bool stuck_ = false;
  bool stuck_high_ = false;
};

}  // namespace gyrod::driver::mock
