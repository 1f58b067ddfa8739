// The mock replays a recording at the recording's own rate: a whole number of chip ticks per
// sample, the chip's clock fast or slow by what the rounding leaves (driver/mock/replay_clock.hpp).
#include <gtest/gtest.h>

#include <vector>

#include "driver/mock/mock_signal_source.hpp"
#include "driver/mock/replay_clock.hpp"

using gyrod::driver::replayClockFor;

TEST(MockReplayClock, ARateThatDividesTheInternalRateNeedsNoClockError) {
  const auto clock = replayClockFor(50.0, 1000.0);
  ASSERT_TRUE(clock);
  EXPECT_EQ(clock->hold, 20u);
  EXPECT_EQ(clock->clock_error_ppm, 0.0);
  EXPECT_EQ(replayClockFor(1000.0, 8000.0)->hold, 8u);
}

TEST(MockReplayClock, ARealRecordsRateRunsTheChipClockFastOrSlow) {
  const auto real = replayClockFor(100.31, 1000.0);  // the sensor-fusion records' rate
  ASSERT_TRUE(real);
  EXPECT_EQ(real->hold, 10u);
  EXPECT_NEAR(real->clock_error_ppm, 3100.0, 1e-6);
  const auto thirty = replayClockFor(30.0, 1000.0);  // 33.3 ticks: 33, the clock 1 % slow
  ASSERT_TRUE(thirty);
  EXPECT_EQ(thirty->hold, 33u);
  EXPECT_NEAR(thirty->clock_error_ppm, -10000.0, 1e-6);
}

TEST(MockReplayClock, BeyondTheMocksTenPercentClockToleranceIsRefused) {
  EXPECT_FALSE(replayClockFor(400.0, 1000.0));  // 2.5 ticks: 20 % off either way
  EXPECT_FALSE(replayClockFor(0.0, 1000.0));
  EXPECT_TRUE(replayClockFor(1050.0, 1000.0));  // 1 tick, the clock 5 % fast
}

TEST(MockReplayClock, TheReplaySourceCallsBackAtEachEnd) {
  gyrod::driver::ReplaySource source({1.0, 2.0}, {0.0, 0.0}, {0.0, 0.0}, {25.0, 25.0}, 1000.0);
  std::vector<std::uint64_t> ends;
  source.onEnd([&](std::uint64_t n) { ends.push_back(n); });
  for (int i = 0; i < 5; ++i) (void)source.nextTick(0.0);
  EXPECT_EQ(ends, (std::vector<std::uint64_t>{1, 2}));
}
