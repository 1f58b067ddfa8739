#pragma once
// Faults the mock MPU-6050 can inject, as a plain plan a test (or later a config file)
// fills in, and the counters of what was injected and what the chip did, so a test can
// check a driver's error and gap accounting exactly.
//
// Times are sensor time: nanoseconds since the mock was created. Error codes are
// positive errno values (EIO, EREMOTEIO, ETIMEDOUT, ENXIO, ENODEV); the bus returns them
// negated.
#include <cerrno>
#include <cstdint>
#include <optional>
#include <vector>

namespace gyrod::driver {

// Each transfer fails with this probability, independently (seeded, reproducible).
struct RandomTransferErrors {
  double probability = 0.0;  // 0..1
  int error = EIO;
  std::uint64_t seed = 1;
};

// The first `transfers` transfers at or after start_ns fail.
struct TransferErrorBurst {
  std::int64_t start_ns = 0;
  std::uint32_t transfers = 1;
  int error = EREMOTEIO;
};

// The device stops answering (every transfer fails with `error`) for a while. A loose
// wire keeps the chip running; power_lost = true also powers it down for the outage and
// brings it back in its power-on state (registers at reset values, FIFO empty, asleep).
struct DeviceOutage {
  std::int64_t start_ns = 0;
  std::int64_t duration_ns = 0;
  int error = EREMOTEIO;
  bool power_lost = false;
};

// The INT line as seen by the host is stuck at one electrical level for a while (a broken
// trace, a GPIO misconfigured); edges the chip makes meanwhile are not seen.
struct StuckDataReadyLine {
  std::int64_t start_ns = 0;
  std::int64_t duration_ns = 0;
  bool level_high = false;
};

// Corrupted samples: `count` of them, spread evenly over [start, start + duration) in sensor
// time, have bit `bit` of one axis's gyro word flipped as the chip writes it (output registers
// and FIFO alike): an outlier the chip reports as data, as EMI or a marginal supply makes one.
struct GlitchBurst {
  std::int64_t start_ns = 0;
  std::int64_t duration_ns = 0;
  std::uint32_t count = 1;
  int axis = 0;  // 0..2: x, y, z
  int bit = 8;   // 0..15 (8: 256 LSB, 1.95 °/s at ±250 °/s)
};

struct FaultPlan {
  RandomTransferErrors random_errors;
  std::vector<TransferErrorBurst> error_bursts;
  std::vector<DeviceOutage> outages;
  // Silent reset (brown-out): registers back to reset values, FIFO cleared, chip asleep,
  // with no error on the bus. A driver notices only by reading registers back.
  std::vector<std::int64_t> brownouts_ns;
  // Fill the FIFO with copies of the current frame until it overflows (as if the reader
  // had stalled), setting FIFO_OFLOW_INT and leaving the stream misaligned.
  std::vector<std::int64_t> forced_fifo_overflows_ns;
  // WHO_AM_I answers this instead of 0x68 (clones: 0x70, 0x72, 0x98, ...).
  std::optional<std::uint8_t> who_am_i;
  std::vector<StuckDataReadyLine> stuck_data_ready;
  std::vector<GlitchBurst> glitch_bursts;
  // When false (default) an injected EIO/burst/random error happens before the chip sees
  // the transfer. When true the chip has done it and only the report fails: a FIFO burst
  // lost its bytes, INT_STATUS was cleared, a write landed. NACKs never take effect.
  bool injected_errors_after_transfer = false;
};

struct MockCounters {
  // Bus side.
  std::uint64_t transfers = 0;             // every transfer attempted
  std::uint64_t transfers_ok = 0;          // returned 0
  std::uint64_t nacks_absent_address = 0;  // selected address is not the chip's
  std::uint64_t injected_random_errors = 0;
  std::uint64_t injected_burst_errors = 0;
  std::uint64_t nacks_during_outage = 0;
  std::uint64_t outages_started = 0;
  std::uint64_t brownouts = 0;
  std::uint64_t forced_fifo_overflows = 0;
  std::uint64_t who_am_i_faked_reads = 0;
  std::uint64_t data_ready_edges_hidden = 0;  // chip-side edges while the line was stuck
  std::uint64_t writes_ignored = 0;           // read-only/unknown register, or during reset
  std::uint64_t device_resets = 0;            // DEVICE_RESET writes

  // Chip side.
  std::uint64_t internal_ticks = 0;              // gyro output ticks (1 or 8 kHz) while awake
  std::uint64_t source_rate_mismatch_ticks = 0;  // ticks taken at a rate the source did not expect
  std::uint64_t samples_produced = 0;            // sample-rate ticks; also the next sequence number
  std::uint64_t fifo_frames_written = 0;         // samples appended to the FIFO
  std::uint64_t glitched_samples = 0;            // samples with a bit flipped (GlitchBurst)
  std::uint64_t fifo_bytes_written = 0;
  std::uint64_t fifo_bytes_overwritten = 0;  // oldest bytes lost to overflow
  std::uint64_t fifo_overflow_events = 0;    // appends that overwrote something
  std::uint64_t fifo_bytes_read = 0;         // popped through FIFO_R_W
  std::uint64_t fifo_empty_reads = 0;        // FIFO_R_W reads with the FIFO empty
  std::uint64_t fifo_resets = 0;
  std::uint64_t data_ready_interrupts = 0;  // DATA_RDY_INT raised (enabled)
};

}  // namespace gyrod::driver
