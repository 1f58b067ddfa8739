// Each fault of the FaultPlan, observed through the bus, and its counter.
#include <gtest/gtest.h>

#include <cerrno>
#include <cmath>

#include "driver/mock/mock_signal_source.hpp"
#include "tests/driver/mock_rig.hpp"

namespace gyrod::driver::test {
namespace {

namespace m = mpu6050;

TEST(MockMpu6050Faults, RandomErrorsHitTheConfiguredFractionOfTransfers) {
  // Each transfer fails independently with p = 0.1: over n = 10000 the count is
  // Binomial(n, p) with s.d. √(n p (1−p)) = 30; accept ±5 s.d. Several seeds.
  for (std::uint64_t seed : {1u, 2u, 99u, 12345u}) {
    ConstantSource source({0, 0, 0});
    Rig rig(source);
    FaultPlan plan;
    plan.random_errors = {0.1, EIO, seed};
    rig.mock.setFaultPlan(plan);
    int failed = 0;
    for (int i = 0; i < 10000; ++i) {
      std::uint8_t v = 0;
      const int r = rig.mock.readByte(A(Register::WHO_AM_I), v);
      if (r != 0) {
        EXPECT_EQ(r, -EIO);
        ++failed;
      } else {
        EXPECT_EQ(v, 0x68);
      }
    }
    EXPECT_NEAR(failed, 1000, 5 * 30) << "seed " << seed;
    EXPECT_EQ(rig.mock.counters().injected_random_errors, static_cast<std::uint64_t>(failed));
    EXPECT_EQ(rig.mock.counters().transfers_ok, 10000u - failed);
  }
}

TEST(MockMpu6050Faults, RandomErrorsAreReproducibleFromTheSeed) {
  const auto pattern = [](std::uint64_t seed) {
    ConstantSource source({0, 0, 0});
    Rig rig(source);
    FaultPlan plan;
    plan.random_errors = {0.3, EREMOTEIO, seed};
    rig.mock.setFaultPlan(plan);
    std::vector<int> results;
    for (int i = 0; i < 200; ++i) {
      std::uint8_t v = 0;
      results.push_back(rig.mock.readByte(0x75, v));
    }
    return results;
  };
  EXPECT_EQ(pattern(7), pattern(7));
  EXPECT_NE(pattern(7), pattern(8));
}

TEST(MockMpu6050Faults, ErrorBurstFailsExactlyTheNextNTransfersAfterItsStart) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  FaultPlan plan;
  plan.error_bursts.push_back({kNsPerSecond, 5, ETIMEDOUT});
  rig.mock.setFaultPlan(plan);
  std::uint8_t v = 0;
  rig.advance(kNsPerSecond - 1);
  EXPECT_EQ(rig.mock.readByte(0x75, v), 0);
  rig.advance(1);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(rig.mock.readByte(0x75, v), -ETIMEDOUT) << i;
  EXPECT_EQ(rig.mock.readByte(0x75, v), 0);
  EXPECT_EQ(rig.mock.counters().injected_burst_errors, 5u);
}

TEST(MockMpu6050Faults, LooseWireOutageNacksButTheChipKeepsRunning) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  FaultPlan plan;
  plan.outages.push_back({2 * kNsPerSecond, kNsPerSecond, EREMOTEIO, false});
  rig.mock.setFaultPlan(plan);
  rig.wake(1, 9);  // 100 Hz
  write(rig.mock, Register::GYRO_CONFIG, m::FS_SEL_500_DPS);
  rig.advance(2 * kNsPerSecond);
  std::uint8_t v = 0;
  EXPECT_EQ(rig.mock.readByte(0x75, v), -EREMOTEIO);
  EXPECT_EQ(rig.mock.writeByte(0x1B, 0x00), -EREMOTEIO);
  rig.advance(kNsPerSecond);
  EXPECT_EQ(read(rig.mock, Register::WHO_AM_I), 0x68);
  EXPECT_EQ(read(rig.mock, Register::GYRO_CONFIG), m::FS_SEL_500_DPS);  // the failed write did nothing
  EXPECT_EQ(rig.mock.counters().samples_produced, 300u);                // sampling went on
  EXPECT_EQ(rig.mock.counters().nacks_during_outage, 2u);
  EXPECT_EQ(rig.mock.counters().outages_started, 1u);
}

TEST(MockMpu6050Faults, PowerLossOutageComesBackInThePowerOnState) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  FaultPlan plan;
  plan.outages.push_back({kNsPerSecond + 5 * kNsPerMillisecond, kNsPerSecond / 2, ENXIO, true});
  rig.mock.setFaultPlan(plan);
  rig.wake(1, 9);
  rig.advance(kNsPerSecond + 6 * kNsPerMillisecond);
  std::uint8_t v = 0;
  EXPECT_EQ(rig.mock.readByte(0x6B, v), -ENXIO);
  const std::uint64_t at_loss = rig.mock.counters().samples_produced;
  EXPECT_EQ(at_loss, 100u);
  rig.advance(kNsPerSecond);
  EXPECT_EQ(rig.mock.counters().samples_produced, at_loss);  // powered down, then asleep
  EXPECT_EQ(read(rig.mock, Register::PWR_MGMT_1), 0x40);
  EXPECT_EQ(read(rig.mock, Register::SMPLRT_DIV), 0x00);
}

TEST(MockMpu6050Faults, BrownOutSilentlyRestoresResetValuesAndEmptiesTheFifo) {
  ConstantSource source({5, 5, 5});
  Rig rig(source);
  FaultPlan plan;
  plan.brownouts_ns.push_back(505 * kNsPerMillisecond);
  rig.mock.setFaultPlan(plan);
  write(rig.mock, Register::FIFO_EN, 0x70);
  write(rig.mock, Register::USER_CTRL, m::USER_CTRL_BIT::FIFO_EN);
  write(rig.mock, Register::INT_ENABLE, m::DATA_RDY_EN);
  rig.wake(3, 9);
  rig.advance(400 * kNsPerMillisecond);
  EXPECT_EQ(fifoCount(rig.mock), 240);
  rig.advance(200 * kNsPerMillisecond);
  // No bus error: only the register contents tell.
  EXPECT_EQ(read(rig.mock, Register::PWR_MGMT_1), 0x40);
  EXPECT_EQ(read(rig.mock, Register::CONFIG), 0x00);
  EXPECT_EQ(read(rig.mock, Register::SMPLRT_DIV), 0x00);
  EXPECT_EQ(read(rig.mock, Register::USER_CTRL), 0x00);
  EXPECT_EQ(read(rig.mock, Register::FIFO_EN), 0x00);
  EXPECT_EQ(fifoCount(rig.mock), 0);
  EXPECT_EQ(rig.mock.counters().samples_produced, 50u);  // 100 Hz until 0.5 s, then asleep
  EXPECT_EQ(rig.mock.counters().brownouts, 1u);
  EXPECT_EQ(rig.mock.counters().transfers, rig.mock.counters().transfers_ok);
}

// Five samples spread over 0.2–0.3 s have bit 8 of z flipped: 393 LSB (3 °/s) reads 137; the
// other samples and axes are untouched.
TEST(MockMpu6050Faults, AGlitchBurstFlipsOneBitOfOneAxisInTheSamplesItSpreadsOver) {
  ConstantSource source({1, 2, 3});
  Rig rig(source);
  FaultPlan plan;
  plan.glitch_bursts.push_back({200 * kNsPerMillisecond, 100 * kNsPerMillisecond, 5, 2, 8});
  rig.mock.setFaultPlan(plan);
  std::vector<SampleRecord> samples;
  rig.mock.setSampleObserver([&samples](const SampleRecord& s) { samples.push_back(s); });
  rig.wake(3, 9);  // 100 Hz
  rig.advance(kNsPerSecond);
  ASSERT_GE(samples.size(), 90u);
  std::size_t glitched = 0;
  for (const SampleRecord& s : samples) {
    EXPECT_EQ(s.gyro[0], 131);
    EXPECT_EQ(s.gyro[1], 262);
    if (s.gyro[2] == (393 ^ 256)) {
      ++glitched;
      const double t = static_cast<double>(s.time_ns - rig.mock.epochNs()) * 1e-9;
      EXPECT_GE(t, 0.2);
      EXPECT_LT(t, 0.3 + 0.011);
    } else {
      EXPECT_EQ(s.gyro[2], 393);
    }
  }
  EXPECT_EQ(glitched, 5u);
  EXPECT_EQ(rig.mock.counters().glitched_samples, 5u);
  plan.glitch_bursts[0].bit = 16;
  EXPECT_THROW(rig.mock.setFaultPlan(plan), std::invalid_argument);
}

TEST(MockMpu6050Faults, ForcedOverflowFillsTheFifoPastItsEnd) {
  ConstantSource source({1, 2, 3});
  Rig rig(source);
  FaultPlan plan;
  plan.forced_fifo_overflows_ns.push_back(10 * kNsPerMillisecond + 1);
  rig.mock.setFaultPlan(plan);
  write(rig.mock, Register::FIFO_EN, 0xF0);  // 8-byte frames: 1024 = 128 frames exactly
  write(rig.mock, Register::USER_CTRL, m::USER_CTRL_BIT::FIFO_EN);
  write(rig.mock, Register::INT_ENABLE, m::FIFO_OFLOW_EN);
  rig.wake(1, 0);
  rig.advance(20 * kNsPerMillisecond);
  EXPECT_EQ(fifoCount(rig.mock), 1024);
  EXPECT_EQ(read(rig.mock, Register::INT_STATUS), m::FIFO_OFLOW_INT);
  EXPECT_EQ(rig.mock.counters().forced_fifo_overflows, 1u);
  EXPECT_GE(rig.mock.counters().fifo_overflow_events, 1u);
  EXPECT_EQ(rig.mock.counters().samples_produced, 20u);  // forced bytes are not samples
}

TEST(MockMpu6050Faults, CloneWhoAmIIsAnsweredAndCounted) {
  for (std::uint8_t clone : {0x70, 0x72, 0x98}) {
    ConstantSource source({0, 0, 0});
    Rig rig(source);
    FaultPlan plan;
    plan.who_am_i = clone;
    rig.mock.setFaultPlan(plan);
    EXPECT_EQ(read(rig.mock, Register::WHO_AM_I), clone);
    EXPECT_EQ(rig.mock.counters().who_am_i_faked_reads, 1u);
  }
}

TEST(MockMpu6050Faults, ErrorsAfterTheTransferStillConsumeFifoBytes) {
  ConstantSource source({1, 2, 3});
  Rig rig(source);
  FaultPlan plan;
  plan.error_bursts.push_back({5 * kNsPerMillisecond, 1, EIO});
  plan.injected_errors_after_transfer = true;
  rig.mock.setFaultPlan(plan);
  write(rig.mock, Register::FIFO_EN, 0x70);
  write(rig.mock, Register::USER_CTRL, m::USER_CTRL_BIT::FIFO_EN);
  rig.wake(1, 0);
  rig.advance(5 * kNsPerMillisecond);  // 5 frames of 6 bytes; the burst is now armed
  std::array<std::uint8_t, 6> frame{};
  EXPECT_EQ(rig.mock.readBlock(A(Register::FIFO_R_W), frame), -EIO);
  EXPECT_EQ(fifoCount(rig.mock), 24);  // the failed read still popped 6 bytes
  EXPECT_EQ(rig.mock.counters().fifo_bytes_read, 6u);
}

TEST(MockMpu6050Faults, ErrorsBeforeTheTransferLeaveTheChipUntouched) {
  ConstantSource source({1, 2, 3});
  Rig rig(source);
  FaultPlan plan;
  plan.error_bursts.push_back({5 * kNsPerMillisecond, 1, EIO});
  rig.mock.setFaultPlan(plan);
  write(rig.mock, Register::FIFO_EN, 0x70);
  write(rig.mock, Register::USER_CTRL, m::USER_CTRL_BIT::FIFO_EN);
  rig.wake(1, 0);
  rig.advance(5 * kNsPerMillisecond);
  std::array<std::uint8_t, 6> frame{};
  EXPECT_EQ(rig.mock.readBlock(A(Register::FIFO_R_W), frame), -EIO);
  EXPECT_EQ(fifoCount(rig.mock), 30);
}

TEST(MockMpu6050Faults, StuckLineHidesDataReadyEdges) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  FaultPlan plan;
  // From 10.5 ms to 20.5 ms: between pulses at both ends, so the window hides whole pulses.
  plan.stuck_data_ready.push_back({10 * kNsPerMillisecond + kNsPerMillisecond / 2, 10 * kNsPerMillisecond, false});
  rig.mock.setFaultPlan(plan);
  write(rig.mock, Register::INT_ENABLE, m::DATA_RDY_EN);
  rig.wake(1, 0);  // pulses at 1 kHz, active high
  DataReadySource& dr = rig.mock.dataReady();
  std::int64_t ts = 0;
  int edges = 0;
  for (int ms = 0; ms < 30; ++ms) {
    rig.advance(kNsPerMillisecond);
    while (dr.consumeEdge(ts) == 0) ++edges;
  }
  EXPECT_EQ(edges, 20);  // ms 1..10 and 21..30
  EXPECT_EQ(rig.mock.counters().data_ready_interrupts, 30u);
  // Each hidden pulse is two hidden transitions.
  EXPECT_EQ(rig.mock.counters().data_ready_edges_hidden, 20u);
}

TEST(MockMpu6050Faults, BadPlansAreRejected) {
  ConstantSource source({0, 0, 0});
  Rig rig(source);
  FaultPlan p;
  p.random_errors.probability = 1.5;
  EXPECT_THROW(rig.mock.setFaultPlan(p), std::invalid_argument);
  p = {};
  p.error_bursts.push_back({0, 1, 0});
  EXPECT_THROW(rig.mock.setFaultPlan(p), std::invalid_argument);
  p = {};
  p.outages.push_back({0, 0, EIO, false});
  EXPECT_THROW(rig.mock.setFaultPlan(p), std::invalid_argument);
  p = {};
  p.outages.push_back({0, 10, EIO, false});
  p.outages.push_back({5, 10, EIO, false});
  EXPECT_THROW(rig.mock.setFaultPlan(p), std::invalid_argument);
  rig.advance(kNsPerSecond);
  p = {};
  p.brownouts_ns.push_back(kNsPerSecond / 2);  // already past
  EXPECT_THROW(rig.mock.setFaultPlan(p), std::invalid_argument);
}

}  // namespace
}  // namespace gyrod::driver::test
