// Timestamps from the sensor's sample clock: drift estimation, jitter smoothing, rejection
// of implausible edges, and the polling fallback, against the mock's true sample times.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <ctime>

#include "driver/mock/mock_signal_source.hpp"
#include "tests/driver/driver_rig.hpp"

namespace gyrod::driver::test {
namespace {

SinusoidSource movingTimestampSource() {
  return SinusoidSource(
      {SinusoidAxis{5.0, 100.0, 0.37, 0.0}, SinusoidAxis{-3.0, 80.0, 0.23, 1.0}, SinusoidAxis{1.0, 60.0, 0.61, 2.0}},
      25.0);
}

// Timestamp errors (driver − truth) of the samples after `skip`.
std::vector<double> timeErrors(const DriverRig& rig, std::size_t skip) {
  std::vector<double> e;
  std::size_t j = 0;
  for (std::size_t i = skip; i < rig.recorder.samples.size(); ++i) {
    const GyroSample& s = rig.recorder.samples[i];
    while (j < rig.truth.size() && rig.truth[j].time_ns < s.t_ns - 5'000'000) ++j;
    for (std::size_t k = j; k < rig.truth.size() && rig.truth[k].time_ns < s.t_ns + 5'000'000; ++k) {
      if (rig.truth[k].gyro == s.raw_gyro) {
        e.push_back(static_cast<double>(s.t_ns - rig.truth[k].time_ns));
        break;
      }
    }
  }
  return e;
}

TEST(Mpu6050DriverTimestamps, ChipClockErrorOfSeveralPercentIsMeasured) {
  for (double ppm : {30'000.0, -25'000.0, 70'000.0}) {
    SinusoidSource source = movingTimestampSource();
    RigOptions o;
    o.mock.clock_error_ppm = ppm;
    DriverRig rig(source, o);
    rig.startStreaming();
    rig.runFor(60 * kNsPerSecond);
    // With exact edge times the estimate is limited by the mock's 1 ns rounding of ticks.
    EXPECT_NEAR(rig.driver.estimatedSamplePeriodNs() / rig.truePeriodNs(), 1.0, 1e-6) << ppm;
    const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), {1'000.0, 0});
    EXPECT_GT(c.matched, 2500u);
    EXPECT_LT(c.max_abs_time_error_ns, 1'000.0);
  }
}

TEST(Mpu6050DriverTimestamps, InterruptLatencyJitterIsSmoothedNotFollowed) {
  // Edges arrive 0..200 µs late (uniform: mean 100 µs, s.d. 200/√12 = 57.7 µs). The model
  // eases with β = 0.1, so its error has s.d. ≈ 57.7·√(β/(2−β)) ≈ 13 µs; a model that
  // jumped to each edge would show the full 57.7 µs. Accept < 29 µs (half the latency s.d.).
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    SinusoidSource source = movingTimestampSource();
    RigOptions o;
    o.mock.clock_error_ppm = 15'000.0;
    o.edge_latency_ns = 200'000;
    o.jitter_seed = seed;
    DriverRig rig(source, o);
    rig.startStreaming();
    rig.runFor(60 * kNsPerSecond);
    // Latency cannot be told from a later sample: timestamps sit between the tick and the
    // latest possible edge.
    const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), {250'000.0, 0});
    EXPECT_TRUE(rig.recorder.gaps.empty());
    const std::vector<double> e = timeErrors(rig, 500);
    ASSERT_GT(e.size(), 2000u);
    double mean = 0.0;
    for (double x : e) mean += x;
    mean /= static_cast<double>(e.size());
    double var = 0.0;
    for (double x : e) var += (x - mean) * (x - mean);
    const double sd = std::sqrt(var / static_cast<double>(e.size() - 1));
    std::printf("[ figures  ] seed %llu: timestamp error mean %.1f us, s.d. %.1f us, period error %.2e\n",
                static_cast<unsigned long long>(seed), mean / 1e3, sd / 1e3,
                rig.driver.estimatedSamplePeriodNs() / rig.truePeriodNs() - 1.0);
    EXPECT_NEAR(mean, 100'000.0, 30'000.0) << seed;
    EXPECT_LT(sd, 29'000.0) << seed;
    // Period over a 60 s baseline: error ≲ 2 · 200 µs / 60 s ≈ 7e-6.
    EXPECT_NEAR(rig.driver.estimatedSamplePeriodNs() / rig.truePeriodNs(), 1.0, 2e-5) << seed;
  }
}

TEST(Mpu6050DriverTimestamps, ImplausibleEdgesAreRejectedAndDoNotMoveTheTimestamps) {
  SinusoidSource source = movingTimestampSource();
  RigOptions o;
  o.edge_latency_ns = 1;  // route edges through the wrapper (latency 0..1 ns)
  DriverRig rig(source, o);
  rig.jitter.setGlitches(37, -8'000'000);  // every 37th edge reported 8 ms early (> P/4)
  rig.startStreaming();
  rig.runFor(20 * kNsPerSecond);
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), {1'000.0, 0});
  EXPECT_TRUE(rig.recorder.gaps.empty());
  EXPECT_GE(rig.driver.counters().timestamp_rejections, 20u);  // ~1000 edges / 37
  EXPECT_EQ(rig.driver.counters().timestamp_relocks, 0u);
  EXPECT_LT(c.max_abs_time_error_ns, 1'000.0);
}

TEST(Mpu6050DriverTimestamps, PollingModeTimestampsWithinAPeriodAndGapsWithinOne) {
  // Without edges the newest sample is 0..P old at each poll: timestamps are good to a
  // fraction of a period and a gap's count may be off by one (docs/driver.md).
  SinusoidSource source = movingTimestampSource();
  RigOptions o;
  o.driver = withPolling(o.driver);
  o.mock.clock_error_ppm = 20'000.0;
  DriverRig rig(source, o);
  rig.startStreaming();
  FaultPlan plan;
  plan.forced_fifo_overflows_ns.push_back(rig.clock.nowNs() - rig.mock.epochNs() + 300 * kNsPerSecond + 3'000'000);
  rig.mock.setFaultPlan(plan);
  rig.runFor(600 * kNsPerSecond);
  const double p = rig.truePeriodNs();
  const StreamCheck c = checkStream(rig.recorder, rig.truth, p, {0.75 * p, 1});
  EXPECT_GT(c.matched, 29'000u);
  EXPECT_EQ(rig.driver.counters().fifo_overflows, 1u);
  ASSERT_EQ(c.gaps.size(), 1u);
  EXPECT_EQ(c.gaps[0].gap.cause, GapCause::FifoOverflow);
  EXPECT_NEAR(rig.driver.estimatedSamplePeriodNs() / p, 1.0, 1e-3);
  std::printf(
      "[ figures  ] polling: max |timestamp error| %.2f ms (P = %.2f ms), gap %llu vs %llu produced, "
      "period error %.2e\n",
      c.max_abs_time_error_ns / 1e6, p / 1e6, static_cast<unsigned long long>(c.gaps[0].gap.count),
      static_cast<unsigned long long>(c.gaps[0].produced_between), rig.driver.estimatedSamplePeriodNs() / p - 1.0);
}

}  // namespace

// The wall clock of a sample is its t plus the clock's realtime offset, read once per burst
// (driver/clock.hpp): on the virtual clock, a fixed offset, so wall − t is that offset exactly.
TEST(Mpu6050DriverTimestamps, WallClockIsTheSameEdgeOnTheRealtimeClock) {
  SinusoidSource source = movingTimestampSource();
  DriverRig rig(source);
  constexpr std::int64_t kOffset = 1'795'000'000'000'000'000;
  rig.clock.setRealtimeOffsetNs(kOffset);
  rig.startStreaming();
  rig.runFor(2 * kNsPerSecond);
  ASSERT_GT(rig.recorder.samples.size(), 50u);
  for (const GyroSample& s : rig.recorder.samples) ASSERT_EQ(s.wall_ns - s.t_ns, kOffset) << s.seq;
}

TEST(Clock, TheRealtimeOffsetIsMeasuredBackToBack) {
  std::int64_t uncertainty = -1;
  const std::int64_t offset = measureRealtimeOffsetNs(&uncertainty);
  EXPECT_GE(uncertainty, 0);
  EXPECT_LT(uncertainty, 50'000'000) << "two clock reads 100 ms apart";
  timespec real{}, mono{};
  clock_gettime(CLOCK_REALTIME, &real);
  clock_gettime(CLOCK_MONOTONIC, &mono);
  const std::int64_t now_offset = (real.tv_sec - mono.tv_sec) * kNsPerSecond + (real.tv_nsec - mono.tv_nsec);
  EXPECT_NEAR(static_cast<double>(offset), static_cast<double>(now_offset), 1e8);  // unless the clock was stepped
  MonotonicClock monotonic;
  EXPECT_NEAR(static_cast<double>(monotonic.realtimeOffsetNs()), static_cast<double>(offset), 1e8);
  VirtualClock virtual_clock(7 * kNsPerSecond);  // its wall clock starts at the real time of its construction
  EXPECT_NEAR(static_cast<double>(virtual_clock.realtimeOffsetNs() + 7 * kNsPerSecond),
              static_cast<double>(real.tv_sec * kNsPerSecond + real.tv_nsec), 1e9);
  const std::int64_t before = virtual_clock.realtimeOffsetNs();
  virtual_clock.advanceNs(3600 * kNsPerSecond);  // an accelerated hour: its wall clock moves with it
  EXPECT_EQ(virtual_clock.realtimeOffsetNs(), before);
}

}  // namespace gyrod::driver::test
