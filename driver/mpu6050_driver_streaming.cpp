// The Streaming state: FIFO restarts, the streaming timers, reading and checking the FIFO,
// placing each FIFO segment on the sample clock and delivering its frames.
#include <algorithm>
#include <cerrno>
#include <string>

#include "driver/fifo_frame.hpp"
#include "driver/i2c_messages.hpp"
#include "driver/mpu6050_driver.hpp"

namespace gyrod::driver {
namespace {

using mpu6050::Register;
namespace reg = mpu6050;

// Wake-ups a new FIFO segment may wait for a usable data-ready edge before its first
// frames are placed on the sample clock from the read time instead.
constexpr int kMaxSyncWaits = 3;

}  // namespace

// ---------------------------------------------------------------------------------------
// Streaming

bool Mpu6050Driver::restartFifo() {
  // RM Register 106: FIFO_RESET resets the FIFO "while FIFO_EN equals 0"; so disable,
  // reset, enable. Samples taken in between are not written; the gap accounting counts them.
  std::uint8_t user_ctrl = 0;
  for (const RegisterSetting& s : table_) {
    if (s.reg == Register::USER_CTRL) user_ctrl = s.set;
  }
  const auto off = static_cast<std::uint8_t>(user_ctrl & ~reg::USER_CTRL_BIT::FIFO_EN);
  int r = writeRegister(Register::USER_CTRL, off);
  if (r == 0) r = writeRegister(Register::USER_CTRL, static_cast<std::uint8_t>(off | reg::USER_CTRL_BIT::FIFO_RESET));
  if (r == 0) r = writeRegister(Register::USER_CTRL, user_ctrl);
  if (r != 0) {
    enterRecovery(GapCause::TransferError, r, "resetting the FIFO of the " + where() + " failed");
    return false;
  }
  ++counters_.fifo_resets;
  const std::int64_t now = clock_.nowNs();
  segment_start_ns_ = now;
  segment_base_known_ = false;
  segment_frames_ = 0;
  sync_waits_ = 0;
  stashed_edge_.reset();
  step_ = Step::Streaming;
  step_deadline_.reset();
  watchdog_due_ = now + watchdog_ns_;
  if (check_due_ < now) check_due_ = now + config_.register_check_interval_ns;
  continue_pending_ = false;
  return true;
}

void Mpu6050Driver::endSegment(GapCause cause) {
  if (!pending_cause_) pending_cause_ = cause;
  segment_base_known_ = false;
}

void Mpu6050Driver::streamingTimers(std::int64_t now) {
  if (continue_pending_ && now >= continue_due_) {
    continue_pending_ = false;
    readFifo(Trigger::Continue);
    if (step_ != Step::Streaming) return;
  }
  if (now >= watchdog_due_) {
    // No data-ready for several periods. Look at the FIFO, and at PWR_MGMT_1: a chip that
    // browned out sleeps and stops producing edges, so this is the fast silent-reset check.
    watchdog_due_ = now + watchdog_ns_;
    readFifo(Trigger::Watchdog);
    if (step_ != Step::Streaming) return;
    if (!checkOneRegister(0)) return;
  }
  if (now >= check_due_) {
    check_due_ = now + config_.register_check_interval_ns;
    const std::size_t i = next_check_;
    next_check_ = (next_check_ + 1) % table_.size();
    checkOneRegister(i);
  }
}

bool Mpu6050Driver::checkOneRegister(std::size_t index) {
  ++counters_.register_checks;
  std::uint8_t v = 0;
  const int r = readRegister(table_[index].reg, v);
  if (r != 0) {
    operationFailed(r, "the periodic register check");
    return step_ == Step::Streaming;
  }
  if (table_[index].matches(v)) return true;
  ++counters_.silent_resets;
  const std::string what = "register " + hexByte(mpu6050::address(table_[index].reg)) + " of the " + where() +
                           " reads " + hexByte(v) +
                           ": the chip lost its configuration without a bus error (a silent reset, "
                           "e.g. a brown-out on a weak 3.3 V supply); re-initialising";
  log(LogLevel::Error, what);
  endSegment(GapCause::SilentReset);
  phase_broken_ = true;
  setState(DeviceState::Recovering, what);
  goTo(Step::Reset, clock_.nowNs());
  return false;
}

void Mpu6050Driver::collectEdges(std::int64_t before_ns, std::int64_t after_ns, std::optional<std::int64_t>& newest,
                                 bool& ambiguous) {
  std::optional<std::int64_t> later;
  const auto classify = [&](std::int64_t e) {
    if (e <= segment_start_ns_) return;  // belongs to frames the FIFO reset discarded
    if (e <= before_ns) {
      newest = newest ? std::max(*newest, e) : e;
    } else if (e <= after_ns) {
      ambiguous = true;  // during the FIFO_COUNT read: counted or not, we cannot tell
    } else {
      later = later ? std::max(*later, e) : e;
    }
  };
  if (stashed_edge_) classify(*stashed_edge_);
  stashed_edge_.reset();
  std::int64_t e = 0;
  for (int i = 0; i < 4096; ++i) {
    const int r = data_ready_.consumeEdge(e);
    if (r != 0) break;
    classify(e);
  }
  stashed_edge_ = later;
  // A full edge queue drops the newest edges (as the kernel's line-event FIFO does): the
  // newest edge left is then older than the newest frame and must not be paired with it.
  const std::uint64_t dropped = data_ready_.edgesDropped();
  if (dropped != edges_dropped_seen_) {
    edges_dropped_seen_ = dropped;
    ambiguous = true;
  }
}

void Mpu6050Driver::readFifo(Trigger trigger) {
  const std::int64_t t0 = clock_.nowNs();
  std::uint16_t count = 0;
  const int r = readWord(Register::FIFO_COUNTH, count);
  if (r != 0) {
    operationFailed(r, "reading FIFO_COUNT");
    return;
  }
  const std::int64_t t1 = clock_.nowNs();
  std::optional<std::int64_t> newest_edge;
  bool ambiguous = false;
  if (config_.data_ready_mode == DataReadyMode::InterruptEdges) {
    collectEdges(t0, t1, newest_edge, ambiguous);
  }

  if (count > mpu6050::fifo::kSize) {
    abandonSegment(GapCause::TransferError, counters_.fifo_transfer_errors,
                   "FIFO_COUNT of the " + where() + " reads " + std::to_string(count) +
                       ", more than the FIFO holds: the read was corrupted; resetting the FIFO");
    return;
  }
  if (count >= fifo_capacity_) {
    // Full: the chip has overwritten (or is about to overwrite) the oldest bytes. Where
    // frames start is then unknown in general (1024 is not a multiple of most frame sizes,
    // and the map does not promise whole-frame overwrites), so reset rather than guess.
    abandonSegment(GapCause::FifoOverflow, counters_.fifo_overflows,
                   "FIFO overflow on the " + where() +
                       ": the reader fell behind by a full FIFO; resetting the FIFO (the lost "
                       "samples are reported as a gap)");
    return;
  }
  const std::size_t available = count / frame_bytes_;
  if (available == 0) {
    if (trigger == Trigger::Edge || trigger == Trigger::Poll) ++counters_.empty_wakeups;
    return;
  }
  if (trigger == Trigger::Watchdog && config_.data_ready_mode == DataReadyMode::InterruptEdges) {
    noteMissedDataReady(t0);
  }

  std::optional<std::int64_t> observation;
  if (config_.data_ready_mode == DataReadyMode::Polling) {
    observation = t0;
  } else if (newest_edge && !ambiguous) {
    observation = newest_edge;
  }
  if (!segment_base_known_) {
    if (!determineSegmentBase(observation, available, t0)) return;  // frames wait in the FIFO
  } else if (observation) {
    // The newest edge announced the newest frame counted.
    observeNewestFrame(*observation, available);
  }

  const std::size_t frames = std::min<std::size_t>(available, static_cast<std::size_t>(config_.max_frames_per_wakeup));
  if (!readFrames(frames) || !framesAligned(frames)) return;
  deliverFrames(frames);
  failure_score_ = std::max(0, failure_score_ - 1);
  const std::int64_t now = clock_.nowNs();
  watchdog_due_ = now + watchdog_ns_;
  if (frames < available) {
    ++counters_.backlog_capped;
    continue_pending_ = true;
    continue_due_ = now;  // at once, but through the loop, so other sources get their turn
  }
}

void Mpu6050Driver::abandonSegment(GapCause cause, std::uint64_t& counter, const std::string& message, int error) {
  ++counter;
  log(LogLevel::Warning, message);
  endSegment(cause);
  if (error != 0) operationFailed(error, nullptr);  // may enter recovery, which leaves Streaming
  if (step_ == Step::Streaming) restartFifo();
}

void Mpu6050Driver::noteMissedDataReady(std::int64_t now) {
  ++counters_.data_ready_missed;
  // Once a minute at most: data arrive but no edge announced them.
  if (last_missed_log_ns_ != INT64_MIN && now - last_missed_log_ns_ < 60 * kNsPerSecond) return;
  last_missed_log_ns_ = now;
  log(LogLevel::Warning, "the FIFO of the " + where() + " has data but no data-ready edge came for " +
                             ms(watchdog_ns_) +
                             ": check the INT wire and the GPIO chip, line and edge settings (reading on a "
                             "timer meanwhile)");
}

void Mpu6050Driver::observeNewestFrame(std::int64_t observation_ns, std::size_t frames_available) {
  const auto verdict = sample_clock_.observe(observation_ns, segment_base_ + segment_frames_ + frames_available - 1);
  if (verdict == SampleClock::Verdict::Rejected) ++counters_.timestamp_rejections;
  if (verdict == SampleClock::Verdict::Relocked) {
    ++counters_.timestamp_rejections;
    ++counters_.timestamp_relocks;
    log(LogLevel::Warning, "data-ready edges of the " + where() +
                               " disagree with its sample clock repeatedly; re-anchoring the timestamps");
  }
}

bool Mpu6050Driver::readFrames(std::size_t frames) {
  const std::size_t bytes = frames * frame_bytes_;
  const std::size_t burst = bus_.maxBurstLength();
  const std::size_t chunk =
      burst >= frame_bytes_ ? burst / frame_bytes_ * frame_bytes_ : std::max<std::size_t>(burst, 1);
  for (std::size_t off = 0; off < bytes;) {
    const std::size_t len = std::min(chunk, bytes - off);
    const int br = bus_.readBlock(mpu6050::address(Register::FIFO_R_W), std::span(fifo_bytes_.data() + off, len));
    if (br != 0) {
      // Never retried: the failed burst may have popped some or all of its bytes, so the
      // FIFO's position is unknown. Reset it; the sample clock counts what was lost.
      ++counters_.transfers_failed;
      abandonSegment(GapCause::TransferError, counters_.fifo_transfer_errors,
                     "FIFO read from the " + where() + " failed: " + describeTransferError(br) + "; resetting the FIFO",
                     br);
      return false;
    }
    off += len;
  }
  return true;
}

bool Mpu6050Driver::framesAligned(std::size_t frames) {
  // Every frame carries the temperature word (first, or after the three accel words), which
  // must agree with TEMP_OUT (the newest sample's temperature; the die warms by far less than
  // the bound within one FIFO's worth of samples). A gyro or accel word in that place almost
  // never does — except near 36.53 °C, where TEMP_OUT ≈ 0 and a still gyro (or a level
  // board's x/y accel) also reads ≈ 0.
  std::uint16_t temp_word = 0;
  const int tr = readWord(Register::TEMP_OUT_H, temp_word);
  if (tr != 0) {
    abandonSegment(GapCause::TransferError, counters_.fifo_transfer_errors,
                   "reading TEMP_OUT from the " + where() + " failed: " + describeTransferError(tr) +
                       "; the frames just read cannot be checked and are dropped",
                   tr);
    return false;
  }
  const auto temp_out = static_cast<std::int16_t>(temp_word);
  const FifoFrames burst(std::span<const std::uint8_t>(fifo_bytes_.data(), frames * frame_bytes_), frame_bytes_);
  const std::optional<std::size_t> bad = firstMisalignedFrame(burst, temp_out, alignment_bound_lsb_);
  if (!bad) return true;
  abandonSegment(GapCause::MisalignedFrames, counters_.misaligned_bursts,
                 "FIFO frames from the " + where() + " are misaligned (frame " + std::to_string(*bad) +
                     " has temperature word " + std::to_string(burst[*bad].temp) + ", TEMP_OUT is " +
                     std::to_string(temp_out) + "); resetting the FIFO");
  return false;
}

bool Mpu6050Driver::determineSegmentBase(std::optional<std::int64_t> observation, std::size_t available,
                                         std::int64_t read_time_ns) {
  const double period = sample_clock_.periodNs();
  const bool edges = config_.data_ready_mode == DataReadyMode::InterruptEdges;
  bool approximate = false;
  if (edges && observation) {
    // The FIFO was reset at segment_start_ns_ while the chip was sampling, so its first
    // frame came within one period after that. An edge that puts it elsewhere is not the
    // newest frame's (an edge was lost): do not use it.
    const double first = static_cast<double>(*observation) - static_cast<double>(available - 1) * period;
    const double tol = period / 4.0;
    const double start = static_cast<double>(segment_start_ns_);
    if (first <= start - tol || first > start + period * (1.0 + config_.max_clock_error) + tol) {
      observation.reset();
    }
  }
  if (edges && !observation) {
    if (++sync_waits_ <= kMaxSyncWaits) return false;
    // No usable edge (a stuck INT line?): place the newest frame half a period before the
    // read, as polling does. Its sequence number may be off by one.
    observation = read_time_ns - static_cast<std::int64_t>(period / 2.0);
    approximate = true;
  }

  const std::uint64_t newest_local = available - 1;
  std::uint64_t base = next_seq_;
  if (sample_clock_.locked()) {
    // Sequence numbers are sample-clock slots: the newest frame's slot is where its time
    // falls on the (old) clock. With the chip's clock running on, this is the exact count of
    // samples in between; after a restart of the chip's clock, the number of whole periods.
    const std::int64_t newest = sample_clock_.nearestIndexOfObservation(*observation);
    const std::int64_t signed_base = newest - static_cast<std::int64_t>(newest_local);
    if (signed_base > static_cast<std::int64_t>(next_seq_)) base = static_cast<std::uint64_t>(signed_base);
  }
  if (phase_broken_ || !sample_clock_.locked()) {
    sample_clock_.breakPhase();
    if (approximate) {
      sample_clock_.lockApproximately(*observation, base + newest_local);
    } else {
      (void)sample_clock_.observe(*observation, base + newest_local);
    }
  } else if (!approximate) {
    const auto verdict = sample_clock_.observe(*observation, base + newest_local);
    if (verdict == SampleClock::Verdict::Rejected || verdict == SampleClock::Verdict::Relocked) {
      ++counters_.timestamp_rejections;
    }
  }

  if (base > next_seq_) {
    const SampleGap gap{next_seq_, base - next_seq_, pending_cause_.value_or(GapCause::Reinitialised)};
    ++counters_.gaps;
    counters_.samples_lost += gap.count;
    log(LogLevel::Warning, "lost " + std::to_string(gap.count) + " samples (seq " + std::to_string(gap.first_seq) +
                               ".." + std::to_string(gap.first_seq + gap.count - 1) + ", " + gapCauseName(gap.cause) +
                               ")");
    sink_.onGap(gap);
  }
  pending_cause_.reset();
  phase_broken_ = false;
  segment_base_ = base;
  segment_base_known_ = true;
  next_seq_ = base;
  sync_waits_ = 0;
  return true;
}

void Mpu6050Driver::deliverFrames(std::size_t frames) {
  const FifoFrames burst(std::span<const std::uint8_t>(fifo_bytes_.data(), frames * frame_bytes_), frame_bytes_);
  GyroSample s;
  const std::int64_t realtime_offset_ns = clock_.realtimeOffsetNs();  // once per burst (driver/clock.hpp)
  for (std::size_t i = 0; i < frames; ++i) {
    s.seq = segment_base_ + segment_frames_ + i;
    std::int64_t t = sample_clock_.timeOf(s.seq);
    if (t <= last_t_ns_) t = last_t_ns_ + 1;  // strictly increasing, even across a re-anchor
    s.t_ns = t;
    s.wall_ns = t + realtime_offset_ns;
    last_t_ns_ = t;
    convertFifoFrame(burst[i], gyro_lsb_per_dps_, s, accel_lsb_per_g_);
    sink_.onSample(s);
  }
  segment_frames_ += frames;
  next_seq_ = segment_base_ + segment_frames_;
  counters_.samples_delivered += frames;
  ever_streamed_ = true;
  if (status_.state != DeviceState::Streaming) {
    recovery_attempts_ = 0;
    setState(DeviceState::Streaming);
    log(LogLevel::Info,
        "streaming from the " + where() + " at " + std::to_string(config_.sample_rate_hz) + " Hz (FS_SEL " +
            std::to_string(config_.fs_sel) + ", DLPF_CFG " + std::to_string(config_.dlpf_cfg) +
            (config_.accel ? ", accel AFS_SEL " + std::to_string(config_.afs_sel) : ", no accel") + ")");
  }
}

}  // namespace gyrod::driver
