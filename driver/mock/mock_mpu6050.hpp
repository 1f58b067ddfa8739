#pragma once
// A register-level emulator of the InvenSense MPU-6050 on an I2C bus: the mock IS the bus
// and the chip at its address (other addresses NACK). It keeps the chip's registers with
// their reset values, samples a SignalSource at the internal gyro rate through the DLPF
// model of processing/sensor_model.hpp, decimates by SMPLRT_DIV, latches the output
// registers, fills the 1024-byte FIFO, raises INT_STATUS bits and drives the INT line.
// Time comes from a Clock: virtual (tests step it) or CLOCK_MONOTONIC (demo); the chip
// catches up to the clock whenever it is touched. Faults are scripted with a FaultPlan.
// What is and is not modelled: docs/mock-device.md.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "driver/clock.hpp"
#include "driver/data_ready.hpp"
#include "driver/i2c_bus.hpp"
#include "driver/mock/mock_faults.hpp"
#include "driver/mock/mock_signal_source.hpp"
#include "driver/mpu6050_registers.hpp"
#include "processing/sensor_model.hpp"

namespace gyrod::driver {

struct MockMpu6050Config {
  std::uint8_t address = mpu6050::kI2cAddressAd0Low;
  // The chip's oscillator error: true internal rate = nominal · (1 + ppm·1e−6). Real parts
  // are off by up to a few percent; |ppm| ≤ 100 000 (10 %).
  double clock_error_ppm = 0.0;
  // Time DEVICE_RESET stays set after it is written (PX4 waits 100 ms before checking).
  std::int64_t reset_duration_ns = 100 * kNsPerMillisecond;
  // Longest burst the emulated adapter allows: 32 is the SMBus block limit.
  std::size_t max_burst_length = 32;
  // The accelerometer sees a fixed vector (g) plus white noise of this standard deviation.
  std::array<double, 3> accel_g = {0.0, 0.0, 1.0};
  double accel_noise_g = 0.002;
  std::uint64_t accel_noise_seed = 1;
  // The host's view of the INT line: which edges count, and how many may queue unread
  // (16, like the kernel's GPIO line-event FIFO).
  EdgeDirection data_ready_edge = EdgeDirection::Rising;
  std::size_t data_ready_queue_depth = 16;
};

// Ground truth for one sample the chip produced (what the output registers were loaded
// with), so tests can check a driver sample by sample.
struct SampleRecord {
  std::uint64_t sequence = 0;  // 0, 1, 2, ... over the mock's life; resets do not restart it
  std::int64_t time_ns = 0;    // clock time of the sample tick
  std::array<std::int16_t, 3> accel{};
  std::int16_t temperature = 0;
  std::array<std::int16_t, 3> gyro{};
  bool written_to_fifo = false;
};

class MockMpu6050 final : public I2cBus {
 public:
  // `clock` and `source` must outlive the mock. Throws std::invalid_argument for a bad
  // config (address above 0x7F, clock error beyond 10 %, negative reset time, burst
  // length 0, non-finite accel values, queue depth 0) and std::system_error when the
  // data-ready file descriptor cannot be created.
  MockMpu6050(Clock& clock, SignalSource& source, MockMpu6050Config config = {});
  MockMpu6050(const MockMpu6050&) = delete;
  MockMpu6050& operator=(const MockMpu6050&) = delete;
  ~MockMpu6050() override;

  // I2cBus. Every call first catches the chip up to the clock.
  [[nodiscard]] int selectDevice(std::uint8_t address) override;
  std::uint8_t selectedDevice() const override { return selected_; }
  [[nodiscard]] int readByte(std::uint8_t reg, std::uint8_t& value) override;
  [[nodiscard]] int writeByte(std::uint8_t reg, std::uint8_t value) override;
  [[nodiscard]] int readWordBigEndian(std::uint8_t reg, std::uint16_t& value) override;
  [[nodiscard]] int readBlock(std::uint8_t reg, std::span<std::uint8_t> out) override;
  std::size_t maxBurstLength() const override { return config_.max_burst_length; }

  // Runs the chip up to clock.nowNs(): every internal tick and scheduled event.
  void sync();
  // Clock time at construction; fault times in a FaultPlan count from here.
  std::int64_t epochNs() const { return epoch_ns_; }
  // Clock time of the next sample tick if the chip is sampling (a virtual-time test can
  // set its clock there and sync() to step one sample at a time).
  std::optional<std::int64_t> nextSampleTimeNs() const;
  // True internal tick rate (Hz) for the current DLPF_CFG and clock error.
  double internalTickRateHz() const;

  // Replaces the fault plan. Throws std::invalid_argument for a probability outside 0..1,
  // a non-positive errno, a negative duration, an event before the current sensor time,
  // or overlapping outages / stuck-line windows.
  void setFaultPlan(const FaultPlan& plan);
  const MockCounters& counters() const { return counters_; }
  std::optional<SampleRecord> lastSample() const { return last_sample_; }
  // Called for every sample, in order (set before running; may be empty).
  void setSampleObserver(std::function<void(const SampleRecord&)> observer) { observer_ = std::move(observer); }

  // The host side of the INT line: an fd readable when an edge is pending.
  DataReadySource& dataReady() { return data_ready_; }
  // Electrical level of INT as the host sees it now (after any stuck-line fault).
  bool intLineHigh() const;

 private:
  class DataReadyLine final : public DataReadySource {
   public:
    DataReadyLine(MockMpu6050& owner, EdgeDirection direction, std::size_t depth);
    ~DataReadyLine() override;
    DataReadyLine(const DataReadyLine&) = delete;
    DataReadyLine& operator=(const DataReadyLine&) = delete;
    int fd() const override { return fd_; }
    [[nodiscard]] int consumeEdge(std::int64_t& timestamp_ns) override;
    std::uint64_t edgesDropped() const override { return dropped_; }

    void lineMoved(std::int64_t t_ns, bool rising);
    // Arms the timerfd: now if an edge is queued; in real-time mode, at the next time the
    // chip could move the line; otherwise disarmed.
    void updateReadiness(bool force = false);

   private:
    MockMpu6050& owner_;
    int fd_ = -1;
    EdgeDirection direction_;
    std::vector<std::int64_t> queue_;  // ring, allocated once
    std::size_t head_ = 0;
    std::size_t count_ = 0;
    std::uint64_t dropped_ = 0;
    std::int64_t armed_at_ns_ = -1;  // what the timerfd is set to; 0 = disarmed
  };

  enum class EventKind : std::uint8_t {
    OutageEnd,
    StuckEnd,
    OutageStart,
    StuckStart,
    BurstStart,
    Brownout,
    ForcedOverflow,
  };
  struct ScheduledEvent {
    std::int64_t time_ns;  // clock time
    EventKind kind;
    std::size_t index;  // into the plan's vector of that kind
  };

  // Time.
  void advanceTo(std::int64_t t_ns);
  void processNextEvent();
  void recomputeNextEvent();
  void internalTick(std::int64_t t_ns);
  void sampleTick(std::int64_t t_ns);
  std::int64_t tickTimeNs(std::int64_t k) const;
  std::int64_t nextPossibleEdgeNs() const;

  // Power and configuration.
  void resetChip();  // registers to reset values, FIFO empty, asleep, line inactive
  void updateSampling();
  void startSampling(std::int64_t t_ns);
  void applyDlpfConfig(int cfg);
  int dlpfCfg() const;

  // Registers.
  std::uint8_t readRegister(std::uint8_t reg);
  void writeRegister(std::uint8_t reg, std::uint8_t value);
  void afterRead();

  // FIFO.
  void pushFifo(const std::uint8_t* bytes, std::size_t n, std::int64_t t_ns);
  std::size_t buildFrame(std::uint8_t* out) const;
  void clearFifo();
  void forceFifoOverflow(std::int64_t t_ns);

  // Interrupts and the INT line.
  void raiseInterrupt(std::uint8_t status_bit, std::uint8_t enable_bit, std::int64_t t_ns);
  void clearInterruptStatus(std::uint8_t bits, std::int64_t t_ns);
  void setChipPinActive(bool active, std::int64_t t_ns);
  bool chipLineHigh() const;
  void lineMaybeMoved(bool was_high, std::int64_t t_ns);

  // Transfers.
  int beginTransfer(bool& deferred_error);
  int readBurst(std::uint8_t reg, std::span<std::uint8_t> out);
  int finishTransfer(int result);

  // Random numbers (seeded): splitmix64 and Box–Muller.
  static std::uint64_t splitmix64(std::uint64_t& state);
  double uniform01(std::uint64_t& state);
  double accelNoise();

  static constexpr std::int64_t kNever = INT64_MAX;

  Clock& clock_;
  SignalSource& source_;
  MockMpu6050Config config_;
  std::int64_t epoch_ns_;
  std::int64_t now_ns_;
  std::uint8_t selected_ = 0;

  std::array<std::uint8_t, 128> regs_{};
  bool powered_ = true;
  bool reset_busy_ = false;
  std::int64_t reset_done_ns_ = kNever;

  // Sample clock: internal tick k (k ≥ 1) happens at anchor + round(k · period).
  bool sampling_ = false;
  std::int64_t anchor_ns_ = 0;
  double period_ns_ = 0.0;
  std::int64_t tick_index_ = 1;
  std::int64_t next_tick_ns_ = kNever;
  int ticks_since_sample_ = 0;
  bool prime_filters_ = true;
  bool rate_mismatch_ = false;

  // Signal path.
  bool dlpf_bypass_ = false;
  std::array<processing::DigitalLowPassFilter, 3> filters_;
  std::array<double, 3> filtered_dps_{};
  double temperature_c_ = 25.0;

  // FIFO: a ring of 1024 bytes.
  std::array<std::uint8_t, mpu6050::fifo::kSize> fifo_{};
  std::size_t fifo_head_ = 0;
  std::size_t fifo_count_ = 0;
  std::uint8_t fifo_last_read_ = 0;
  std::uint16_t fifo_count_shadow_ = 0;

  // INT line: the chip's output, pulse timing, and the stuck-line fault.
  bool pin_active_ = false;
  std::int64_t pulse_end_ns_ = kNever;
  bool stuck_ = false;
  bool stuck_high_ = false;

  // Faults.
  FaultPlan plan_;
  std::vector<ScheduledEvent> events_;
  std::size_t next_plan_event_ = 0;
  std::int64_t next_event_ns_ = kNever;
  std::uint64_t transfer_rng_ = 1;
  std::uint32_t burst_remaining_ = 0;
  int burst_error_ = EIO;
  bool outage_ = false;
  int outage_error_ = EREMOTEIO;

  std::uint64_t accel_rng_;
  std::optional<double> spare_normal_;

  MockCounters counters_;
  std::optional<SampleRecord> last_sample_;
  std::function<void(const SampleRecord&)> observer_;
  DataReadyLine data_ready_;
};

}  // namespace gyrod::driver
