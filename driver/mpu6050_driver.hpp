#pragma once
// The MPU6050 driver: a non-blocking, timer-driven state machine that probes, resets and
// configures the chip, streams its FIFO into timestamped samples, and recovers from what a
// real I2C bus does to it. It never sleeps and never throws after construction: the
// daemon's epoll loop calls it when its data-ready fd is readable or its deadline passes.
//
//   Probe ──► Reset ──► WaitReset ──► Configure ──► StartFifo ──► Streaming
//     ▲                                                 │  ▲          │
//     │   (table intact after an outage: FIFO restart) ─┘  └─ FIFO restart (overflow,
//     │                                                       misalignment, FIFO transfer
//   Backoff ◄──── repeated errors, device gone ◄──────────────  error)
//                 silent reset (table lost) ──► Reset
//
// Every path and its gap accounting is described in docs/driver.md. The config rules and the
// register table are in mpu6050_config.*, FIFO frame decoding in fifo_frame.*; the states
// before streaming are in mpu6050_driver.cpp, streaming in mpu6050_driver_streaming.cpp.
//
// Usage (the daemon):
//   Mpu6050Driver drv(bus, data_ready, clock, sink, config, log);
//   drv.start();
//   epoll: drv.pollFd() for EPOLLIN → drv.onDataReady();
//          a timerfd set to drv.nextDeadlineNs() (absolute CLOCK_MONOTONIC) → drv.onTimer(now)
//   re-read nextDeadlineNs() after every call.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "driver/clock.hpp"
#include "driver/data_ready.hpp"
#include "driver/i2c_bus.hpp"
#include "driver/mpu6050_config.hpp"
#include "driver/mpu6050_registers.hpp"
#include "driver/mpu6050_types.hpp"
#include "driver/sample_clock.hpp"

namespace gyrod::driver {

class Mpu6050Driver {
 public:
  // All references must outlive the driver. Throws std::invalid_argument for a bad config
  // (validateConfig) — the only exception it ever throws.
  Mpu6050Driver(I2cBus& bus, DataReadySource& data_ready, const Clock& clock, SampleSink& sink, Mpu6050Config config,
                LogFunction log = {});
  Mpu6050Driver(const Mpu6050Driver&) = delete;
  Mpu6050Driver& operator=(const Mpu6050Driver&) = delete;

  // Begins probing at the next onTimer() (the deadline becomes "now").
  void start();

  // The data-ready source's fd, for EPOLLIN.
  int pollFd() const { return data_ready_.fd(); }
  // Absolute CLOCK_MONOTONIC time at which onTimer() must be called, if any.
  std::optional<std::int64_t> nextDeadlineNs() const;
  // The data-ready fd is readable. Always drains the source, in every state.
  void onDataReady();
  // A deadline has passed (now_ns: the loop's CLOCK_MONOTONIC reading).
  void onTimer(std::int64_t now_ns);

  const DeviceStatus& status() const { return status_; }
  const DriverCounters& counters() const { return counters_; }
  std::span<const RegisterSetting> registerTable() const { return table_; }
  // The sample clock's current period estimate, ns (nominal until measured).
  double estimatedSamplePeriodNs() const { return sample_clock_.periodNs(); }
  double estimatedSampleRateHz() const { return 1e9 / sample_clock_.periodNs(); }

 private:
  enum class Step : std::uint8_t { Idle, Probe, Reset, WaitReset, Configure, StartFifo, Streaming, Backoff, Failed };
  enum class Trigger : std::uint8_t { Edge, Poll, Watchdog, Continue };

  // Steps.
  void runStep(std::int64_t now);
  void doProbe();
  void doReset();
  void doWaitReset();
  void doConfigure();
  void doStartFifo();
  void streamingTimers(std::int64_t now);

  // Streaming.
  void readFifo(Trigger trigger);
  // Every way a FIFO read can fail ends here: count it, say why, end the segment (its gap
  // is counted when the next one starts) and restart the FIFO. `error` (a failed transfer)
  // also counts towards recovery, which may take the driver out of Streaming instead.
  void abandonSegment(GapCause cause, std::uint64_t& counter, const std::string& message, int error = 0);
  void noteMissedDataReady(std::int64_t now);
  void observeNewestFrame(std::int64_t observation_ns, std::size_t frames_available);
  bool readFrames(std::size_t frames);     // false: abandoned
  bool framesAligned(std::size_t frames);  // false: abandoned
  void collectEdges(std::int64_t before_ns, std::int64_t after_ns, std::optional<std::int64_t>& newest,
                    bool& ambiguous);
  bool determineSegmentBase(std::optional<std::int64_t> observation_ns, std::size_t frames_available,
                            std::int64_t read_time_ns);
  void deliverFrames(std::size_t frames);
  bool checkOneRegister(std::size_t index);
  bool restartFifo();
  void endSegment(GapCause cause);

  // Errors.
  void operationFailed(int error, const char* what);
  void enterRecovery(GapCause cause, int error, const std::string& what);
  void fail(const std::string& reason, bool retrying);

  // Transfers with bounded retries (register operations only; FIFO bursts are never retried).
  int readRegister(mpu6050::Register reg, std::uint8_t& value);
  int writeRegister(mpu6050::Register reg, std::uint8_t value);
  int readWord(mpu6050::Register reg, std::uint16_t& value);
  template <typename Op>
  int withRetries(Op&& op);

  // State and messages.
  void setState(DeviceState state, std::string reason = {}, bool retrying = true);
  void log(LogLevel level, const std::string& message) const;
  void goTo(Step step, std::int64_t at_ns);
  std::string where() const;
  static std::string ms(std::int64_t ns);

  I2cBus& bus_;
  DataReadySource& data_ready_;
  const Clock& clock_;
  SampleSink& sink_;
  Mpu6050Config config_;
  LogFunction log_;
  std::vector<RegisterSetting> table_;
  SampleClock sample_clock_;

  // Derived constants.
  double nominal_period_ns_;
  std::size_t fifo_capacity_ = mpu6050::fifo::kSize;
  std::int64_t watchdog_ns_;
  std::int16_t alignment_bound_lsb_;
  double gyro_lsb_per_dps_;
  double accel_lsb_per_g_;
  std::size_t frame_bytes_;  // kFrameBytes, or kAccelFrameBytes with accel

  // State machine.
  Step step_ = Step::Idle;
  std::optional<std::int64_t> step_deadline_;
  DeviceStatus status_;
  bool ever_streamed_ = false;
  bool configured_before_ = false;
  int wait_reset_polls_ = 0;
  int configure_attempts_ = 0;
  int recovery_attempts_ = 0;
  int failure_score_ = 0;
  bool clone_warned_ = false;
  std::int64_t last_missed_log_ns_ = INT64_MIN;

  // Streaming timers.
  std::int64_t watchdog_due_ = 0;
  std::int64_t check_due_ = 0;
  bool continue_pending_ = false;
  std::int64_t continue_due_ = 0;
  std::size_t next_check_ = 0;

  // The current FIFO segment: frames since the last FIFO reset.
  std::int64_t segment_start_ns_ = 0;  // time the FIFO reset completed
  bool segment_base_known_ = false;
  std::uint64_t segment_base_ = 0;         // sequence number of the segment's frame 0
  std::uint64_t segment_frames_ = 0;       // frames delivered (or consumed) in this segment
  int sync_waits_ = 0;                     // wake-ups spent waiting for a usable edge
  bool phase_broken_ = false;              // the chip restarted its sample clock since the last segment
  std::optional<GapCause> pending_cause_;  // why the previous segment ended

  // Sequence and time.
  std::uint64_t next_seq_ = 0;
  std::int64_t last_t_ns_ = INT64_MIN;
  std::optional<std::int64_t> stashed_edge_;  // newest edge seen after the last FIFO_COUNT read
  std::uint64_t edges_dropped_seen_ = 0;

  // FIFO bytes: one wake-up's worth at most, allocated once.
  std::array<std::uint8_t, mpu6050::fifo::kSize> fifo_bytes_{};

  DriverCounters counters_;
};

}  // namespace gyrod::driver
