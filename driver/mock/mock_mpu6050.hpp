#pragma once
// A register-level emulator of the InvenSense MPU-6050 on an I2C bus: the mock IS the bus
// and the chip at its address (other addresses NACK). It keeps the chip's registers with
// their reset values, samples a SignalSource at the internal gyro rate through the DLPF
// model of processing/simulation/sensor_model.hpp, decimates by SMPLRT_DIV, latches the output
// registers, fills the 1024-byte FIFO, raises INT_STATUS bits and drives the INT line.
// Time comes from a Clock: virtual (tests step it) or CLOCK_MONOTONIC (demo); the chip
// catches up to the clock whenever it is touched. Faults are scripted with a FaultPlan.
// What is and is not modelled: docs/mock-device.md. The parts live in driver/mock/: the
// register file, the FIFO, the fault schedule, the INT line and the tick train, each with
// the chip's side of it in a mock_<part>.cpp.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>

#include "driver/clock.hpp"
#include "driver/data_ready.hpp"
#include "driver/i2c_bus.hpp"
#include "driver/mock/fault_schedule.hpp"
#include "driver/mock/fifo.hpp"
#include "driver/mock/int_line.hpp"
#include "driver/mock/mock_faults.hpp"
#include "driver/mock/mock_random.hpp"
#include "driver/mock/mock_signal_source.hpp"
#include "driver/mock/mock_time.hpp"
#include "driver/mock/register_file.hpp"
#include "driver/mock/tick_train.hpp"
#include "driver/mpu6050_registers.hpp"
#include "processing/simulation/sensor_model.hpp"

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
  // The accelerometer sees a fixed vector (g) — or, when the SignalSource knows it, gravity at
  // the board's attitude — plus a constant bias and white noise of this standard deviation,
  // saturated at the AFS_SEL range like the chip.
  std::array<double, 3> accel_g = {0.0, 0.0, 1.0};
  std::array<double, 3> accel_bias_g = {0.0, 0.0, 0.0};
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

class MockMpu6050 final : public I2cBus, private mock::ChipTimeline {
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
  DataReadySource& dataReady() { return int_line_.host(); }
  // Electrical level of INT as the host sees it now (after any stuck-line fault).
  bool intLineHigh() const;

 private:
  // mock::ChipTimeline: runs every internal tick and scheduled event up to t_ns.
  void advanceTo(std::int64_t t_ns) override;
  // Only a sample tick with an interrupt enabled, or a scheduled event, can move INT.
  std::int64_t nextPossibleEdgeNs() const override;

  // Scheduled events (mock_mpu6050.cpp, mock_faults.cpp).
  void recomputeNextEvent();
  void processNextEvent();
  void applyFaultEvent(const mock::FaultEvent& event, std::int64_t t_ns);

  // Sampling and power (mock_sampling.cpp).
  void internalTick(std::int64_t t_ns);
  void sampleTick(std::int64_t t_ns);
  void latchOutputs(const SampleRecord& s);
  void resetChip();  // registers to reset values, FIFO empty, asleep, line inactive
  void updateSampling();
  void startSampling(std::int64_t t_ns);
  void applyDlpfConfig(int cfg);
  double accelNoise();

  // Registers (mock_registers.cpp).
  std::uint8_t readRegister(std::uint8_t reg);
  void writeRegister(std::uint8_t reg, std::uint8_t value);
  void writePowerManagement(std::uint8_t value);
  void writeConfig(std::uint8_t value);
  void writeUserControl(std::uint8_t value);
  void writeIntPinConfig(std::uint8_t value);
  void afterRead();

  // FIFO (mock_fifo.cpp).
  void pushFifo(const std::uint8_t* bytes, std::size_t n, std::int64_t t_ns);
  std::uint8_t popFifo();
  std::size_t buildFrame(std::uint8_t* out) const;
  void forceFifoOverflow(std::int64_t t_ns);

  // Interrupts (mock_int_line.cpp).
  void raiseInterrupt(std::uint8_t status_bit, std::uint8_t enable_bit, std::int64_t t_ns);
  void clearInterruptStatus(std::uint8_t bits, std::int64_t t_ns);

  // Transfers (mock_mpu6050.cpp).
  int beginTransfer(bool& deferred_error);
  int readBurst(std::uint8_t reg, std::span<std::uint8_t> out);
  int finishTransfer(int result);

  Clock& clock_;
  SignalSource& source_;
  MockMpu6050Config config_;
  std::int64_t epoch_ns_;
  std::int64_t now_ns_;
  std::uint8_t selected_ = 0;

  mock::RegisterFile regs_;
  bool powered_ = true;
  bool reset_busy_ = false;
  std::int64_t reset_done_ns_ = mock::kNever;

  mock::TickTrain ticks_;
  bool prime_filters_ = true;
  bool rate_mismatch_ = false;

  // Signal path.
  bool dlpf_bypass_ = false;
  std::array<processing::DigitalLowPassFilter, 3> filters_;
  std::array<double, 3> filtered_dps_{};
  double temperature_c_ = 25.0;
  std::array<double, 3> true_accel_g_{};  // the source's gravity at the last tick, or accel_g
  mock::BoxMullerNormal accel_noise_;

  mock::Fifo fifo_;
  mock::FaultSchedule faults_;
  // The plan's glitches in sensor time, sorted, and the next one due.
  struct Glitch {
    std::int64_t at_ns = 0;
    int axis = 0, bit = 0;
  };
  std::vector<Glitch> glitches_;
  std::size_t next_glitch_ = 0;
  std::int64_t next_event_ns_ = mock::kNever;  // reset done, pulse end or the next fault

  MockCounters counters_;
  std::optional<SampleRecord> last_sample_;
  std::function<void(const SampleRecord&)> observer_;
  mock::IntLine int_line_;  // after counters_, which it counts hidden edges in
};

}  // namespace gyrod::driver
