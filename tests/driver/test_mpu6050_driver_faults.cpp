// One test per fault the mock can inject (and the natural ones: a stalled loop, a
// misaligned stream, a capped backlog). Each asserts recovery, the exact gap accounting
// against the mock's record of every sample it produced, and that nothing crashed.
#include <gtest/gtest.h>

#include <cerrno>
#include <cstdio>
#include <numeric>

#include "driver/mock/mock_signal_source.hpp"
#include "tests/driver/driver_rig.hpp"

namespace gyrod::driver::test {
namespace {

// A signal that changes from sample to sample, so every sample is recognisable.
SinusoidSource movingSource() {
  return SinusoidSource(
      {SinusoidAxis{5.0, 100.0, 0.37, 0.0}, SinusoidAxis{-3.0, 80.0, 0.23, 1.0}, SinusoidAxis{1.0, 60.0, 0.61, 2.0}},
      25.0);
}

std::uint64_t lostIn(const Recorder& r) {
  return std::accumulate(r.gaps.begin(), r.gaps.end(), std::uint64_t{0},
                         [](std::uint64_t a, const SampleGap& g) { return a + g.count; });
}

// Samples and gaps tile the sequence; delivered + lost = last seq + 1.
void expectTotals(const DriverRig& rig, const StreamCheck& c) {
  EXPECT_EQ(rig.recorder.samples.size() + lostIn(rig.recorder), c.total_seq);
  EXPECT_EQ(rig.driver.counters().samples_delivered, rig.recorder.samples.size());
  EXPECT_EQ(rig.driver.counters().samples_lost, lostIn(rig.recorder));
  EXPECT_EQ(rig.driver.counters().gaps, rig.recorder.gaps.size());
}

// The mock samples between the first and last delivered one, against the driver's
// sequence span: equal when the chip's clock ran throughout.
void expectSpanEqualsProduced(const DriverRig& rig) {
  const auto& s = rig.recorder.samples;
  ASSERT_GE(s.size(), 2u);
  const auto find = [&](const GyroSample& g) {
    for (const SampleRecord& r : rig.truth) {
      if (std::llabs(r.time_ns - g.t_ns) < 1'000'000 && r.gyro == g.raw_gyro) return r.sequence;
    }
    ADD_FAILURE() << "no mock sample for seq " << g.seq;
    return std::uint64_t{0};
  };
  EXPECT_EQ(s.back().seq - s.front().seq, find(s.back()) - find(s.front()));
}

constexpr CheckOptions kEdgeCheck{1'000.0, 0};  // timestamps within 1 µs; gaps exact

TEST(Mpu6050DriverFaults, RandomTransferErrorsAreRetriedAndFailedFifoBurstsAccountedExactly) {
  SinusoidSource source = movingSource();
  DriverRig rig(source);
  rig.startStreaming();
  FaultPlan plan;
  plan.random_errors = {0.02, EIO, 7};
  rig.mock.setFaultPlan(plan);
  rig.runFor(120 * kNsPerSecond);
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
  expectTotals(rig, c);
  expectSpanEqualsProduced(rig);
  const DriverCounters& k = rig.driver.counters();
  EXPECT_GT(k.retries, 100u);                                   // ~3 register transfers per sample, 2 % fail
  EXPECT_GT(k.fifo_transfer_errors, 10u);                       // bursts are never retried...
  EXPECT_EQ(rig.recorder.gaps.size(), k.fifo_transfer_errors);  // ...each costs a FIFO reset and a gap
  for (const auto& g : rig.recorder.gaps) EXPECT_EQ(g.cause, GapCause::TransferError);
  for (const auto& g : c.gaps) EXPECT_TRUE(g.chip_ran);
  EXPECT_EQ(rig.driver.status().state, DeviceState::Streaming);
  EXPECT_EQ(rig.mock.counters().injected_random_errors, k.transfers_failed);
}

TEST(Mpu6050DriverFaults, ErrorsAfterTheTransferLoseFifoBytesAndTheGapCountsThem) {
  // The chip did the burst (bytes popped) but the adapter reported failure.
  SinusoidSource source = movingSource();
  DriverRig rig(source);
  rig.startStreaming();
  FaultPlan plan;
  plan.random_errors = {0.01, EIO, 11};
  plan.injected_errors_after_transfer = true;
  rig.mock.setFaultPlan(plan);
  rig.runFor(120 * kNsPerSecond);
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
  expectTotals(rig, c);
  expectSpanEqualsProduced(rig);
  EXPECT_GT(rig.driver.counters().fifo_transfer_errors, 5u);
  EXPECT_GT(rig.mock.counters().fifo_bytes_read, 8 * rig.recorder.samples.size());  // bytes really lost
  EXPECT_EQ(rig.driver.status().state, DeviceState::Streaming);
}

TEST(Mpu6050DriverFaults, BurstOfNacksLeadsToRecoveryWithAnExactGap) {
  SinusoidSource source = movingSource();
  DriverRig rig(source);
  rig.startStreaming();
  FaultPlan plan;
  // 12 NACKs: more than three operations' worth of attempts → the recovery path.
  plan.error_bursts.push_back({rig.clock.nowNs() - rig.mock.epochNs() + 3 * kNsPerSecond, 12, EREMOTEIO});
  rig.mock.setFaultPlan(plan);
  rig.runFor(10 * kNsPerSecond);
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
  expectTotals(rig, c);
  expectSpanEqualsProduced(rig);
  EXPECT_GE(rig.driver.counters().recoveries, 1u);
  EXPECT_TRUE(rig.recorder.everIn(DeviceState::Recovering));
  EXPECT_EQ(rig.driver.status().state, DeviceState::Streaming);
  ASSERT_EQ(rig.recorder.gaps.size(), 1u);
  EXPECT_EQ(rig.recorder.gaps[0].cause, GapCause::DeviceUnreachable);
  EXPECT_TRUE(c.gaps[0].chip_ran);
  EXPECT_EQ(rig.driver.counters().device_resets, 1u);  // registers intact: no second reset
  EXPECT_TRUE(rig.logged("EREMOTEIO"));
}

TEST(Mpu6050DriverFaults, LooseWireOutageOverflowsTheFifoAndRecoversWithAnExactGap) {
  for (int error : {EREMOTEIO, ETIMEDOUT, ENODEV}) {
    SinusoidSource source = movingSource();
    DriverRig rig(source);
    rig.startStreaming();
    FaultPlan plan;
    // 4 s without the bus: at 50 Hz the 128-frame FIFO fills in 2.56 s and overflows.
    plan.outages.push_back({rig.clock.nowNs() - rig.mock.epochNs() + 2 * kNsPerSecond, 4 * kNsPerSecond, error, false});
    rig.mock.setFaultPlan(plan);
    rig.runFor(12 * kNsPerSecond);
    const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
    expectTotals(rig, c);
    expectSpanEqualsProduced(rig);
    EXPECT_GT(rig.mock.counters().fifo_overflow_events, 0u);
    ASSERT_EQ(rig.recorder.gaps.size(), 1u) << busErrorName(-error);
    EXPECT_EQ(rig.recorder.gaps[0].cause, GapCause::DeviceUnreachable);
    ASSERT_EQ(c.gaps.size(), 1u);
    EXPECT_TRUE(c.gaps[0].chip_ran);
    // The 4 s outage at 50 Hz plus the wait for the next probe (backoff ≤ 2 s): exactly what
    // the mock produced meanwhile (checked above).
    EXPECT_GE(rig.recorder.gaps[0].count, 195u);
    EXPECT_LE(rig.recorder.gaps[0].count, 300u);
    EXPECT_EQ(rig.driver.status().state, DeviceState::Streaming);
    EXPECT_EQ(rig.driver.counters().device_resets, 1u);
  }
}

TEST(Mpu6050DriverFaults, LongOutageMarksTheSensorNotFunctionalUntilItAnswersAgain) {
  SinusoidSource source = movingSource();
  DriverRig rig(source);
  rig.startStreaming();
  EXPECT_FALSE(rig.driver.status().retrying);  // a fresh start that streams is not a retry
  FaultPlan plan;
  plan.outages.push_back({rig.clock.nowNs() - rig.mock.epochNs() + kNsPerSecond, 40 * kNsPerSecond, EREMOTEIO, false});
  rig.mock.setFaultPlan(plan);
  rig.runFor(30 * kNsPerSecond);
  EXPECT_EQ(rig.driver.status().state, DeviceState::Failed);
  EXPECT_TRUE(rig.driver.status().retrying);
  EXPECT_NE(rig.driver.status().reason.find("EREMOTEIO"), std::string::npos);
  rig.runFor(20 * kNsPerSecond);
  EXPECT_EQ(rig.driver.status().state, DeviceState::Streaming);
  EXPECT_FALSE(rig.driver.status().retrying);  // retrying only while it retries
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
  expectTotals(rig, c);
  expectSpanEqualsProduced(rig);  // 40 s at 50 Hz through one gap, still exact
  ASSERT_EQ(c.gaps.size(), 1u);
  EXPECT_NEAR(static_cast<double>(c.gaps[0].gap.count), 2000.0, 150.0);
}

TEST(Mpu6050DriverFaults, PowerLossReinitialisesAndTheGapCountsWholePeriodsOfTheHole) {
  SinusoidSource source = movingSource();
  DriverRig rig(source);
  rig.startStreaming();
  FaultPlan plan;
  plan.outages.push_back(
      {rig.clock.nowNs() - rig.mock.epochNs() + 2 * kNsPerSecond + 3 * kNsPerMillisecond, kNsPerSecond, ENXIO, true});
  rig.mock.setFaultPlan(plan);
  rig.runFor(10 * kNsPerSecond);
  // The chip slept during the outage and its reset: it produced fewer samples than the hole
  // has periods. Exactness in "samples produced" is impossible here (the driver cannot
  // see when the power went); the gap counts the hole's whole periods, checked against the
  // true times (checkStream), and is never less than what the chip produced.
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
  expectTotals(rig, c);
  ASSERT_EQ(c.gaps.size(), 1u);
  EXPECT_FALSE(c.gaps[0].chip_ran);
  EXPECT_GE(c.gaps[0].gap.count, c.gaps[0].produced_between);
  EXPECT_EQ(c.gaps[0].gap.count, c.gaps[0].slots);
  EXPECT_EQ(rig.driver.counters().device_resets, 2u);
  EXPECT_EQ(rig.driver.counters().configures, 2u);
  EXPECT_EQ(rig.driver.status().state, DeviceState::Streaming);
  EXPECT_TRUE(rig.logged("lost its configuration"));
}

TEST(Mpu6050DriverFaults, SilentResetIsDetectedByReadBackAndReconfigured) {
  SinusoidSource source = movingSource();
  DriverRig rig(source);
  rig.startStreaming();
  FaultPlan plan;
  plan.brownouts_ns.push_back(rig.clock.nowNs() - rig.mock.epochNs() + 3 * kNsPerSecond + 7 * kNsPerMillisecond);
  rig.mock.setFaultPlan(plan);
  rig.runFor(10 * kNsPerSecond);
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
  expectTotals(rig, c);
  EXPECT_EQ(rig.driver.counters().silent_resets, 1u);
  EXPECT_EQ(rig.driver.counters().configures, 2u);
  ASSERT_EQ(rig.recorder.gaps.size(), 1u);
  EXPECT_EQ(rig.recorder.gaps[0].cause, GapCause::SilentReset);
  ASSERT_EQ(c.gaps.size(), 1u);
  EXPECT_FALSE(c.gaps[0].chip_ran);
  EXPECT_GE(c.gaps[0].gap.count, c.gaps[0].produced_between);
  // Detected within one watchdog period (4 sample periods) by the PWR_MGMT_1 check, then
  // 100 ms reset wait and 50 ms settling: the hole is well under half a second.
  EXPECT_LT(c.gaps[0].gap.count, 25u);
  EXPECT_EQ(rig.driver.status().state, DeviceState::Streaming);
  EXPECT_TRUE(rig.logged("silent reset"));
}

TEST(Mpu6050DriverFaults, ForcedFifoOverflowResetsTheFifoAndNoCopyIsDelivered) {
  SinusoidSource source = movingSource();
  DriverRig rig(source);
  rig.startStreaming();
  FaultPlan plan;
  plan.forced_fifo_overflows_ns.push_back(rig.clock.nowNs() - rig.mock.epochNs() + 2 * kNsPerSecond +
                                          5 * kNsPerMillisecond);
  rig.mock.setFaultPlan(plan);
  rig.runFor(5 * kNsPerSecond);
  // checkStream matches each delivered sample to a distinct mock sample in order: a copy
  // the overflow pushed would repeat an earlier sample and fail the match.
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
  expectTotals(rig, c);
  expectSpanEqualsProduced(rig);
  EXPECT_EQ(rig.driver.counters().fifo_overflows, 1u);
  ASSERT_EQ(rig.recorder.gaps.size(), 1u);
  EXPECT_EQ(rig.recorder.gaps[0].cause, GapCause::FifoOverflow);
  EXPECT_TRUE(c.gaps[0].chip_ran);
}

TEST(Mpu6050DriverFaults, StalledLoopOverflowsTheFifoNaturally) {
  SinusoidSource source = movingSource();
  DriverRig rig(source);
  rig.startStreaming();
  rig.runFor(kNsPerSecond);
  rig.stall();
  rig.runFor(3 * kNsPerSecond);  // 150 samples > 128 frames
  rig.resume();
  rig.runFor(3 * kNsPerSecond);
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
  expectTotals(rig, c);
  expectSpanEqualsProduced(rig);
  EXPECT_EQ(rig.driver.counters().fifo_overflows, 1u);
  ASSERT_EQ(rig.recorder.gaps.size(), 1u);
  EXPECT_EQ(rig.recorder.gaps[0].cause, GapCause::FifoOverflow);
  // The gap holds the stall's samples; a late edge is still a data-ready edge, not a miss.
  EXPECT_NEAR(static_cast<double>(rig.recorder.gaps[0].count), 150.0, 2.0);
  // The 16-edge queue overflowed during the stall, keeping the oldest edges: the driver must
  // not pair the newest of those with the newest frame (that would be a rejected edge).
  EXPECT_GT(rig.mock.dataReady().edgesDropped(), 0u);
  EXPECT_EQ(rig.driver.counters().timestamp_rejections, 0u);
}

TEST(Mpu6050DriverFaults, ShortStallIsCaughtUpThroughTheBacklogCapWithoutLoss) {
  SinusoidSource source = movingSource();
  RigOptions o;
  o.driver.max_frames_per_wakeup = 4;
  DriverRig rig(source, o);
  rig.startStreaming();
  rig.stall();
  rig.runFor(kNsPerSecond);  // 50 frames wait in the FIFO
  rig.resume();
  rig.runFor(2 * kNsPerSecond);
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
  expectTotals(rig, c);
  EXPECT_TRUE(rig.recorder.gaps.empty());
  EXPECT_GE(rig.driver.counters().backlog_capped, 12u);  // 50 frames, 4 at a time
  EXPECT_EQ(rig.driver.counters().fifo_overflows, 0u);
  // The 16-edge queue kept the stall's first edges and dropped the rest: the newest queued
  // edge is 34 samples older than the newest frame and must not be paired with it.
  EXPECT_GT(rig.mock.dataReady().edgesDropped(), 0u);
  EXPECT_EQ(rig.driver.counters().timestamp_rejections, 0u);
}

TEST(Mpu6050DriverFaults, MisalignedStreamIsDetectedByTheTemperatureWordAndReset) {
  SinusoidSource source = movingSource();
  DriverRig rig(source);
  rig.startStreaming();
  rig.runFor(kNsPerSecond + 3 * kNsPerMillisecond);
  // One stray byte in the FIFO (the host may write FIFO_R_W): every later frame is shifted.
  ASSERT_EQ(rig.mock.writeByte(mpu6050::address(mpu6050::Register::FIFO_R_W), 0x5A), 0);
  rig.runFor(3 * kNsPerSecond);
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
  expectTotals(rig, c);
  expectSpanEqualsProduced(rig);
  EXPECT_EQ(rig.driver.counters().misaligned_bursts, 1u);
  ASSERT_EQ(rig.recorder.gaps.size(), 1u);
  EXPECT_EQ(rig.recorder.gaps[0].cause, GapCause::MisalignedFrames);
  EXPECT_TRUE(rig.logged("misaligned"));
}

TEST(Mpu6050DriverFaults, StuckDataReadyLineFallsBackToTheWatchdogWithoutLoss) {
  for (bool high : {false, true}) {
    SinusoidSource source = movingSource();
    DriverRig rig(source);
    rig.startStreaming();
    FaultPlan plan;
    plan.stuck_data_ready.push_back({rig.clock.nowNs() - rig.mock.epochNs() + kNsPerSecond, 2 * kNsPerSecond, high});
    rig.mock.setFaultPlan(plan);
    rig.runFor(5 * kNsPerSecond);
    // The FIFO buffers what the missing edges did not announce; the sample clock runs on
    // its period estimate meanwhile.
    const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
    expectTotals(rig, c);
    EXPECT_TRUE(rig.recorder.gaps.empty());
    EXPECT_GT(rig.mock.counters().data_ready_edges_hidden, 90u);
    EXPECT_GE(rig.driver.counters().data_ready_missed, 20u);  // 2 s / 88 ms watchdog
    EXPECT_TRUE(rig.logged("no data-ready edge came"));
    EXPECT_EQ(rig.driver.status().state, DeviceState::Streaming);
  }
}

TEST(Mpu6050DriverFaults, ChipRestartWhileTheLineIsStuckIsPlacedFromTheReadTime) {
  // The documented inexact case. After a FIFO restart the first frames are placed on the
  // sample clock by the newest data-ready edge. If the chip's clock ran on, the old model
  // places them exactly even without edges; but after a chip restart (here a brown-out)
  // the phase is new, and with the line stuck there is no edge: after three watchdog
  // wake-ups the newest frame is put half a period before the read. The gap may then be
  // off by one slot and timestamps off by up to half a period, until the first edge after
  // the line recovers re-anchors the model.
  SinusoidSource source = movingSource();
  DriverRig rig(source);
  rig.startStreaming();
  const std::int64_t now = rig.clock.nowNs() - rig.mock.epochNs();
  FaultPlan plan;
  plan.stuck_data_ready.push_back({now + kNsPerSecond, 4 * kNsPerSecond, false});
  plan.brownouts_ns.push_back(now + 2 * kNsPerSecond + 3 * kNsPerMillisecond);
  rig.mock.setFaultPlan(plan);
  rig.runFor(9 * kNsPerSecond);
  const double p = rig.truePeriodNs();
  const StreamCheck c = checkStream(rig.recorder, rig.truth, p, {p / 2.0 + 1.0, 1});
  expectTotals(rig, c);
  ASSERT_EQ(c.gaps.size(), 1u);
  EXPECT_EQ(c.gaps[0].gap.cause, GapCause::SilentReset);
  EXPECT_FALSE(c.gaps[0].chip_ran);
  EXPECT_EQ(rig.driver.status().state, DeviceState::Streaming);
  std::printf("[ figures  ] brown-out with INT stuck: gap %llu, hole %llu whole periods, max |t error| %.2f ms\n",
              static_cast<unsigned long long>(c.gaps[0].gap.count), static_cast<unsigned long long>(c.gaps[0].slots),
              c.max_abs_time_error_ns / 1e6);
  EXPECT_GT(c.max_abs_time_error_ns, 1'000.0);  // the read-time placement was used
  // Once edges are back the timestamps are exact again.
  const GyroSample& last = rig.recorder.samples.back();
  const auto it = std::find_if(rig.truth.rbegin(), rig.truth.rend(),
                               [&](const SampleRecord& r) { return r.gyro == last.raw_gyro; });
  ASSERT_NE(it, rig.truth.rend());
  EXPECT_LT(std::llabs(it->time_ns - last.t_ns), 1'000);
}

TEST(Mpu6050DriverFaults, CloneChipStreamsLikeTheGenuinePart) {
  SinusoidSource source = movingSource();
  DriverRig rig(source);
  FaultPlan plan;
  plan.who_am_i = 0x98;
  rig.mock.setFaultPlan(plan);
  rig.startStreaming();
  rig.runFor(5 * kNsPerSecond);
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), kEdgeCheck);
  expectTotals(rig, c);
  EXPECT_TRUE(rig.recorder.gaps.empty());
}

}  // namespace
}  // namespace gyrod::driver::test
