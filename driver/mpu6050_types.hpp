#pragma once
// What the MPU6050 driver hands to the daemon: samples, gap records, the device state, its
// counters and its log lines; and what the daemon hands to the driver: its configuration.
// No logging library and no I/O here, so driver/ stays free of the daemon's choices.
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <string_view>

#include "driver/mpu6050_registers.hpp"

namespace gyrod::driver {

// One gyro sample, as read from one FIFO frame.
struct GyroSample {
  // 0, 1, 2, ... over the driver's life. Sequence numbers are slots of the sensor's sample
  // clock: a sample that could not be delivered still used up its number (see SampleGap).
  std::uint64_t seq = 0;
  // CLOCK_MONOTONIC ns when the chip produced the sample (its data-ready edge), from the
  // sensor's own sample clock anchored to the edges. Never wall-clock time.
  std::int64_t t_ns = 0;
  std::array<double, 3> rate_dps{};        // x, y, z in °/s (chip axes, signs as the chip reports)
  double temp_c = 0.0;                     // die temperature, °C
  std::array<std::int16_t, 3> raw_gyro{};  // the frame's words, for recording and tests
  std::int16_t raw_temp = 0;
  // x, y, z specific force [g] from the same FIFO frame; NaN when the FIFO carries no accel.
  std::array<double, 3> accel_g{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                                std::numeric_limits<double>::quiet_NaN()};
  std::array<std::int16_t, 3> raw_accel{};
  // CLOCK_REALTIME ns at the same data-ready edge as t_ns; 0 when unknown.
  std::int64_t wall_ns = 0;
};

enum class GapCause : std::uint8_t {
  FifoOverflow,       // the reader fell behind; the FIFO overwrote data and was reset
  MisalignedFrames,   // a burst failed the temperature sync check; the FIFO was reset
  TransferError,      // a FIFO burst (or the check after it) failed on the bus; FIFO reset
  DeviceUnreachable,  // the chip stopped answering; recovered after backoff
  SilentReset,        // the chip lost its configuration (brown-out); re-initialised
  Reinitialised,      // the driver reset the chip after repeated errors
};
// The cause's token, e.g. "fifo_overflow": what the daemon publishes and the driver logs.
const char* gapCauseName(GapCause cause);

// Samples the driver could not deliver: sequence numbers first_seq .. first_seq+count−1.
// count is the number of sample-clock slots in the hole. While the chip kept sampling
// (overflow, misalignment, transfer errors, a loose wire) that is exactly the number of
// samples it produced and the driver lost. When the chip itself stopped (brown-out,
// power loss, a reset by the driver) it counts the slots the hole spans, rounded to the
// nearest whole period, which is at least the number the chip produced meanwhile.
struct SampleGap {
  std::uint64_t first_seq = 0;
  std::uint64_t count = 0;
  GapCause cause = GapCause::FifoOverflow;
};

enum class DeviceState : std::uint8_t {
  Probing,      // looking for the chip (WHO_AM_I)
  Configuring,  // reset, register table, FIFO start
  Streaming,    // samples are flowing
  Recovering,   // an error happened; backing off and re-initialising
  Failed,       // not functional: `reason` says why; `retrying` says whether it keeps trying
};
const char* deviceStateName(DeviceState state);

struct DeviceStatus {
  DeviceState state = DeviceState::Probing;
  std::string reason;  // empty while all is well
  // Whether the driver is retrying now: while recovering, probing again after an error, and in
  // Failed while it keeps trying (false there only for a refusal that retrying cannot fix,
  // a wrong chip). False on the first probe, while configuring and while streaming.
  bool retrying = false;
  std::uint8_t who_am_i = 0;  // last value read, 0 before the first probe
};

// Everything the driver counts, for STATUS. Monotonic over the driver's life.
struct DriverCounters {
  std::uint64_t transfers_failed = 0;   // every failed bus transfer (each attempt)
  std::uint64_t retries = 0;            // transfers repeated after a transient error
  std::uint64_t operations_failed = 0;  // register operations that failed after retries
  std::uint64_t fifo_overflows = 0;
  std::uint64_t fifo_resets = 0;           // every FIFO reset, whatever the cause
  std::uint64_t misaligned_bursts = 0;     // temperature sync check failed
  std::uint64_t fifo_transfer_errors = 0;  // FIFO bursts that failed (contents then unknown)
  std::uint64_t device_resets = 0;         // DEVICE_RESET written
  std::uint64_t configures = 0;            // register table written (first time included)
  std::uint64_t silent_resets = 0;         // register read-back found the table lost
  std::uint64_t recoveries = 0;            // entries into the backoff/recovery path
  std::uint64_t data_ready_missed = 0;     // watchdog reads that found data no edge announced
  std::uint64_t empty_wakeups = 0;         // data-ready or poll with an empty FIFO
  std::uint64_t backlog_capped = 0;        // wake-ups that left frames for the next one
  std::uint64_t samples_delivered = 0;
  std::uint64_t samples_lost = 0;  // sum of all gap counts
  std::uint64_t gaps = 0;
  std::uint64_t timestamp_rejections = 0;  // edge observations outside the plausible bound
  std::uint64_t timestamp_relocks = 0;     // the sample clock was re-anchored hard
  std::uint64_t register_checks = 0;       // periodic read-backs done
};

enum class LogLevel : std::uint8_t { Debug, Info, Warning, Error };
const char* logLevelName(LogLevel level);
// Called for every state change and every event worth a human's attention. The daemon
// plugs its logger in; messages are complete sentences that say what to do.
using LogFunction = std::function<void(LogLevel, std::string_view)>;

// Where samples and gaps go, in sequence order: a gap is reported before the first sample
// after it. Called from inside onDataReady()/onTimer(); must not call back into the driver.
class SampleSink {
 public:
  virtual ~SampleSink() = default;
  virtual void onSample(const GyroSample& sample) = 0;
  virtual void onGap(const SampleGap& gap) = 0;
  virtual void onStatus(const DeviceStatus& /*status*/) {}
};

// How the driver learns that data are waiting.
enum class DataReadyMode : std::uint8_t {
  // The DataReadySource reports the INT line's edges with their times (GPIO line events,
  // the mock's line). Edge times anchor the sample clock.
  InterruptEdges,
  // The DataReadySource is a periodic timer (PollingDataReady): each tick means "look at
  // FIFO_COUNT"; its time says only that the newest sample is at most one period old.
  Polling,
};

struct Mpu6050Config {
  std::uint8_t address = mpu6050::kI2cAddressAd0Low;  // 0x68 or 0x69
  // Output data rate. Must be 1 kHz / n (or 8 kHz / n with dlpf_cfg 0), n = 1..256.
  double sample_rate_hz = 50.0;
  // CONFIG.DLPF_CFG 0..6: 4 is 20 Hz gyro bandwidth, below the 25 Hz Nyquist of 50 Hz.
  int dlpf_cfg = 4;
  int fs_sel = 0;               // GYRO_CONFIG.FS_SEL 0..3: ±250, ±500, ±1000, ±2000 °/s
  bool int_active_low = false;  // INT_PIN_CFG.INT_LEVEL
  bool int_open_drain = false;  // INT_PIN_CFG.INT_OPEN
  DataReadyMode data_ready_mode = DataReadyMode::InterruptEdges;
  // Only for DataReadyMode::Polling: the poll period the DataReadySource uses (see
  // pollingPeriodNs()); the driver needs it to judge how old the newest sample can be.
  std::int64_t polling_period_ns = 0;

  // Robustness knobs; the defaults are what the tests and docs/driver.md assume.
  int transfer_attempts = 3;                              // per register transfer (1 + 2 retries)
  int max_frames_per_wakeup = 32;                         // backlog cap per wake-up
  std::int64_t register_check_interval_ns = 100'000'000;  // one table entry per interval
  double alignment_bound_c = 1.0;                         // |frame temperature − TEMP_OUT| allowed, °C
  double max_clock_error = 0.10;                          // plausible |period/nominal − 1|
  int failures_before_recovery = 3;                       // failed operations (decaying score) → recovery
  std::int64_t backoff_initial_ns = 50'000'000;
  std::int64_t backoff_max_ns = 2'000'000'000;
  int recovery_attempts_before_failed = 5;   // then DeviceState::Failed (still retrying)
  std::int64_t reset_wait_ns = 100'000'000;  // after DEVICE_RESET (PX4 waits 100 ms)
  std::int64_t settle_ns = 50'000'000;       // after waking: gyro start-up is ~30 ms
  std::string bus_name = "I2C bus";          // for messages: the device path, e.g. "/dev/i2c-1"

  // The accelerometer in the FIFO (14-byte frames: accel, temperature, gyro). Off, the FIFO
  // carries the 8-byte temperature + gyro frame and ACCEL_CONFIG is not written.
  bool accel = false;
  int afs_sel = 0;  // ACCEL_CONFIG.AFS_SEL 0..3: ±2, ±4, ±8, ±16 g (16384 / 8192 / 4096 / 2048 LSB/g)
};

// The rules about a config (validation, SMPLRT_DIV, periods, the register table) are in
// driver/mpu6050_config.hpp.

}  // namespace gyrod::driver
