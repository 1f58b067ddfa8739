// The mock's INT line as the host sees it through DataReadySource: edges per INT_PIN_CFG
// (pulse or latch, active level), readiness of the fd, the bounded queue, real-time mode.
#include <gtest/gtest.h>
#include <poll.h>

#include <cerrno>

#include "driver/mock/mock_signal_source.hpp"
#include "tests/driver/mock_rig.hpp"

namespace gyrod::driver::test {
namespace {

namespace m = mpu6050;

bool readable(int fd) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, 0) == 1 && (p.revents & POLLIN);
}

std::vector<std::int64_t> drain(DataReadySource& dr) {
  std::vector<std::int64_t> out;
  std::int64_t ts = 0;
  while (dr.consumeEdge(ts) == 0) out.push_back(ts);
  return out;
}

TEST(MockMpu6050DataReady, PulseModeGivesOneRisingEdgeAtEachSampleTime) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  std::vector<std::int64_t> sample_times;
  rig.mock.setSampleObserver([&](const SampleRecord& s) { sample_times.push_back(s.time_ns); });
  write(rig.mock, Register::INT_ENABLE, m::DATA_RDY_EN);
  rig.wake(1, 1);  // 500 Hz
  DataReadySource& dr = rig.mock.dataReady();
  EXPECT_FALSE(readable(dr.fd()));
  rig.advance(10 * kNsPerMillisecond);
  EXPECT_TRUE(readable(dr.fd()));
  const std::vector<std::int64_t> edges = drain(dr);
  EXPECT_FALSE(readable(dr.fd()));
  ASSERT_EQ(sample_times.size(), 5u);
  EXPECT_EQ(edges, sample_times);
  for (std::size_t i = 0; i < edges.size(); ++i) EXPECT_EQ(edges[i], static_cast<std::int64_t>(i + 1) * 2'000'000);
  std::int64_t ts = 0;
  EXPECT_EQ(dr.consumeEdge(ts), -EAGAIN);
}

TEST(MockMpu6050DataReady, NoEdgesWithoutDataRdyEn) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  rig.wake(1, 0);
  rig.advance(10 * kNsPerMillisecond);
  EXPECT_FALSE(readable(rig.mock.dataReady().fd()));
  EXPECT_TRUE(drain(rig.mock.dataReady()).empty());
  EXPECT_FALSE(rig.mock.intLineHigh());
}

TEST(MockMpu6050DataReady, ActiveLowPulsesFallAtTheSampleAndRiseFiftyMicrosecondsLater) {
  ConstantSource source({0, 0, 0});
  MockMpu6050Config config = Rig::quietConfig();
  config.data_ready_edge = EdgeDirection::Both;
  Rig rig(source, config);
  write(rig.mock, Register::INT_PIN_CFG, m::INT_LEVEL);  // idle high: one rising edge now
  EXPECT_TRUE(rig.mock.intLineHigh());
  EXPECT_EQ(drain(rig.mock.dataReady()).size(), 1u);
  write(rig.mock, Register::INT_ENABLE, m::DATA_RDY_EN);
  rig.wake(1, 0);
  rig.advance(2 * kNsPerMillisecond + 100'000);
  const std::vector<std::int64_t> expected = {1'000'000, 1'050'000, 2'000'000, 2'050'000};
  EXPECT_EQ(drain(rig.mock.dataReady()), expected);
}

TEST(MockMpu6050DataReady, LatchedLineStaysUpUntilIntStatusIsRead) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  write(rig.mock, Register::INT_PIN_CFG, m::LATCH_INT_EN);
  write(rig.mock, Register::INT_ENABLE, m::DATA_RDY_EN);
  rig.wake(1, 0);
  rig.advance(5 * kNsPerMillisecond);
  // Nobody cleared the status: one edge for five samples, the line still high.
  EXPECT_EQ(drain(rig.mock.dataReady()), std::vector<std::int64_t>{1'000'000});
  EXPECT_TRUE(rig.mock.intLineHigh());
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS), m::DATA_RDY_INT);
  EXPECT_FALSE(rig.mock.intLineHigh());
  rig.advance(kNsPerMillisecond);
  EXPECT_EQ(drain(rig.mock.dataReady()), std::vector<std::int64_t>{6'000'000});
}

TEST(MockMpu6050DataReady, QueueHoldsSixteenEdgesAndCountsTheRest) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  write(rig.mock, Register::INT_ENABLE, m::DATA_RDY_EN);
  rig.wake(1, 0);
  rig.advance(40 * kNsPerMillisecond);
  const std::vector<std::int64_t> edges = drain(rig.mock.dataReady());
  ASSERT_EQ(edges.size(), 16u);
  EXPECT_EQ(edges.front(), 1'000'000);  // the oldest are kept, new ones dropped
  EXPECT_EQ(edges.back(), 16'000'000);
  EXPECT_EQ(rig.mock.dataReady().edgesDropped(), 24u);
}

TEST(MockMpu6050DataReady, VirtualTimeCanStepFromSampleToSample) {
  ConstantSource source({0, 0, 0});
  MockMpu6050Config config = Rig::quietConfig();
  config.clock_error_ppm = 12'345.0;
  Rig rig(source, config);
  write(rig.mock, Register::INT_ENABLE, m::DATA_RDY_EN);
  rig.wake(3, 4);
  const double period_ns = 5.0 * 1e9 / (1000.0 * 1.012345);
  for (int k = 1; k <= 50; ++k) {
    const std::optional<std::int64_t> next = rig.mock.nextSampleTimeNs();
    ASSERT_TRUE(next.has_value());
    EXPECT_NEAR(static_cast<double>(*next), k * period_ns, 1.0);
    rig.clock.setNs(*next);
    rig.mock.sync();
    std::int64_t ts = 0;
    ASSERT_EQ(rig.mock.dataReady().consumeEdge(ts), 0);
    EXPECT_EQ(ts, *next);
    EXPECT_EQ(rig.mock.counters().samples_produced, static_cast<std::uint64_t>(k));
  }
}

TEST(MockMpu6050DataReady, RealTimeModeWakesAnEpollStyleWaiter) {
  // Functional only: wait (up to 2 s) for edges from a mock running on CLOCK_MONOTONIC.
  MonotonicClock clock;
  ConstantSource source({0, 0, 0});
  MockMpu6050 mock(clock, source);
  write(mock, Register::INT_ENABLE, m::DATA_RDY_EN);
  write(mock, Register::CONFIG, 1);
  write(mock, Register::SMPLRT_DIV, 4);  // 200 Hz
  write(mock, Register::PWR_MGMT_1, 0x01);
  const std::int64_t start = clock.nowNs();
  std::int64_t last = start;
  int edges = 0;
  for (int waits = 0; waits < 400 && edges < 5; ++waits) {
    pollfd p{mock.dataReady().fd(), POLLIN, 0};
    ASSERT_GE(::poll(&p, 1, 2000), 0);
    std::int64_t ts = 0;
    while (mock.dataReady().consumeEdge(ts) == 0) {
      EXPECT_GT(ts, last);
      EXPECT_LE(ts, clock.nowNs());
      last = ts;
      ++edges;
    }
  }
  EXPECT_GE(edges, 5);
}

}  // namespace
}  // namespace gyrod::driver::test
