// The sample-clock model on its own: observations built from a known true clock.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "driver/sample_clock.hpp"

namespace gyrod::driver {
namespace {

SampleClockConfig config20ms() {
  SampleClockConfig c;
  c.nominal_period_ns = 20e6;
  c.observation_tolerance_ns = 5e6;
  return c;
}

TEST(SampleClock, ExactObservationsOfASlowClockGiveExactTimesAndPeriod) {
  const double p_true = 20e6 * 1.03;  // a chip 3 % slow
  SampleClock clock(config20ms());
  for (std::uint64_t k = 0; k <= 200; ++k) {
    clock.observe(1'000'000'000 + static_cast<std::int64_t>(std::llround(k * p_true)), k);
  }
  EXPECT_NEAR(clock.periodNs(), p_true, 1e-3);
  for (std::uint64_t k : {150u, 200u, 260u}) {
    EXPECT_NEAR(static_cast<double>(clock.timeOf(k)), 1e9 + k * p_true, 2.0) << k;
  }
  EXPECT_EQ(clock.rejections(), 0u);
}

TEST(SampleClock, AnImplausibleObservationIsRejectedAndChangesNothing) {
  SampleClock clock(config20ms());
  for (std::uint64_t k = 0; k <= 50; ++k) clock.observe(static_cast<std::int64_t>(k * 20'000'000), k);
  const std::int64_t before = clock.timeOf(60);
  EXPECT_EQ(clock.observe(51 * 20'000'000 - 6'000'000, 51), SampleClock::Verdict::Rejected);  // 6 ms > 5 ms
  EXPECT_EQ(clock.timeOf(60), before);
  EXPECT_EQ(clock.rejections(), 1u);
}

TEST(SampleClock, PersistentDisagreementRelocksOnTheFourthObservation) {
  SampleClock clock(config20ms());
  for (std::uint64_t k = 0; k <= 50; ++k) clock.observe(static_cast<std::int64_t>(k * 20'000'000), k);
  const std::int64_t shift = 9'000'000;  // an unannounced phase jump
  for (std::uint64_t k = 51; k <= 53; ++k) {
    EXPECT_EQ(clock.observe(static_cast<std::int64_t>(k * 20'000'000) + shift, k), SampleClock::Verdict::Rejected);
  }
  EXPECT_EQ(clock.observe(54 * 20'000'000 + shift, 54), SampleClock::Verdict::Relocked);
  EXPECT_EQ(clock.timeOf(54), 54 * 20'000'000 + shift);
  EXPECT_EQ(clock.relocks(), 1u);
}

TEST(SampleClock, AfterAcquisitionTheAnchorEasesTowardAnObservationInsteadOfJumping) {
  SampleClock clock(config20ms());
  for (std::uint64_t k = 0; k <= 100; ++k) clock.observe(static_cast<std::int64_t>(k * 20'000'000), k);
  const std::int64_t predicted = clock.timeOf(101);
  const std::int64_t residual = 2'000'000;  // within tolerance
  EXPECT_EQ(clock.observe(predicted + residual, 101), SampleClock::Verdict::Accepted);
  const std::int64_t moved = clock.timeOf(101) - predicted;
  EXPECT_GT(moved, 0);
  EXPECT_LT(moved, residual / 2);  // easing 0.1 (plus a small period update), not a jump
}

TEST(SampleClock, PeriodsOutsideThePlausibleBoundAreNeverAdopted) {
  SampleClock clock(config20ms());                                                                       // ±10 %
  for (std::uint64_t k = 0; k <= 300; ++k) clock.observe(static_cast<std::int64_t>(k * 25'000'000), k);  // +25 %
  EXPECT_LE(std::fabs(clock.periodNs() / 20e6 - 1.0), 0.10 + 1e-12);
  EXPECT_GT(clock.rejections(), 0u);
}

TEST(SampleClock, BreakPhaseKeepsTheMeasuredPeriod) {
  const double p_true = 20e6 * 0.98;
  SampleClock clock(config20ms());
  for (std::uint64_t k = 0; k <= 200; ++k) clock.observe(static_cast<std::int64_t>(std::llround(k * p_true)), k);
  clock.breakPhase();
  EXPECT_FALSE(clock.locked());
  EXPECT_EQ(clock.observe(10'000'000'000, 500), SampleClock::Verdict::Locked);
  EXPECT_NEAR(static_cast<double>(clock.timeOf(510)), 1e10 + 10 * p_true, 2.0);
}

TEST(SampleClock, AnApproximateLockIsReplacedByTheNextObservationNotRefined) {
  SampleClock clock(config20ms());
  clock.lockApproximately(1'000'000'000 + 8'000'000, 0);  // 8 ms off
  EXPECT_EQ(clock.timeOf(0), 1'008'000'000);
  EXPECT_EQ(clock.observe(1'000'000'000 + 10 * 20'000'000, 10), SampleClock::Verdict::Locked);
  for (std::uint64_t k = 11; k <= 40; ++k) clock.observe(static_cast<std::int64_t>(1'000'000'000 + k * 20'000'000), k);
  // The period comes from exact observations only: a baseline at the rough placement
  // would give (30 · 20 ms − 8 ms) / 30 ≈ 19.73 ms.
  EXPECT_NEAR(clock.periodNs(), 20e6, 1.0);
}

TEST(SampleClock, ObservedIndexRoundsToTheNearestSlot) {
  SampleClock clock(config20ms());
  clock.observe(1'000'000'000, 10);
  EXPECT_EQ(clock.nearestIndexOfObservation(1'000'000'000 + 5 * 20'000'000 + 9'000'000), 15);
  EXPECT_EQ(clock.nearestIndexOfObservation(1'000'000'000 + 5 * 20'000'000 + 11'000'000), 16);
  EXPECT_EQ(clock.nearestIndexOfObservation(1'000'000'000 - 3 * 20'000'000), 7);
}

TEST(SampleClock, InvalidConfigurationsAreRejected) {
  SampleClockConfig c = config20ms();
  c.nominal_period_ns = 0;
  EXPECT_THROW(SampleClock{c}, std::invalid_argument);
  c = config20ms();
  c.easing = 0.0;
  EXPECT_THROW(SampleClock{c}, std::invalid_argument);
  c = config20ms();
  c.max_clock_error = 0.6;
  EXPECT_THROW(SampleClock{c}, std::invalid_argument);
  c = config20ms();
  c.observation_tolerance_ns = -1;
  EXPECT_THROW(SampleClock{c}, std::invalid_argument);
}

}  // namespace
}  // namespace gyrod::driver
