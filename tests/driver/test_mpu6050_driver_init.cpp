// The driver's probe, reset and configuration sequence against the mock chip, its
// configuration checks, and its handling of the chip's identity.
#include <gtest/gtest.h>

#include <cerrno>
#include <cstdio>
#include <limits>
#include <optional>
#include <vector>

#include "driver/mock/mock_signal_source.hpp"
#include "tests/driver/driver_rig.hpp"

namespace gyrod::driver::test {
namespace {

// Records every transfer the driver makes (operation, register, value, time) and passes it
// to the mock.
class RecordingBus final : public I2cBus {
 public:
  struct Transfer {
    char op;  // 'S' select, 'R' read byte, 'W' write byte, 'w' read word, 'B' burst
    std::uint8_t reg;
    std::uint32_t value;  // written value, value read, or burst length
    std::int64_t t_ns;
  };
  RecordingBus(I2cBus& inner, const Clock& clock) : inner_(inner), clock_(clock) {}
  int selectDevice(std::uint8_t a) override {
    log_.push_back({'S', a, 0, clock_.nowNs()});
    return inner_.selectDevice(a);
  }
  std::uint8_t selectedDevice() const override { return inner_.selectedDevice(); }
  int readByte(std::uint8_t reg, std::uint8_t& v) override {
    const int r = inner_.readByte(reg, v);
    log_.push_back({'R', reg, v, clock_.nowNs()});
    return r;
  }
  int writeByte(std::uint8_t reg, std::uint8_t v) override {
    log_.push_back({'W', reg, v, clock_.nowNs()});
    return inner_.writeByte(reg, v);
  }
  int readWordBigEndian(std::uint8_t reg, std::uint16_t& v) override {
    const int r = inner_.readWordBigEndian(reg, v);
    log_.push_back({'w', reg, v, clock_.nowNs()});
    return r;
  }
  int readBlock(std::uint8_t reg, std::span<std::uint8_t> out) override {
    log_.push_back({'B', reg, static_cast<std::uint32_t>(out.size()), clock_.nowNs()});
    return inner_.readBlock(reg, out);
  }
  std::size_t maxBurstLength() const override { return inner_.maxBurstLength(); }
  const std::vector<Transfer>& log() const { return log_; }

 private:
  I2cBus& inner_;
  const Clock& clock_;
  std::vector<Transfer> log_;
};

TEST(Mpu6050DriverInit, FullInitSequenceProbesResetsWaitsConfiguresVerifiesAndStartsTheFifo) {
  // Expected register values written independently from the register map (RM rev 4.2):
  // 50 Hz with DLPF_CFG 4 → 1 kHz / (1 + 19); FS_SEL 0; FIFO_EN = TEMP|XG|YG|ZG = 0xF0;
  // INT_ENABLE = FIFO_OFLOW_EN|DATA_RDY_EN = 0x11; USER_CTRL.FIFO_EN = 0x40; PLL X gyro = 0x01.
  VirtualClock clock(kNsPerSecond);
  ConstantSource source({1.0, -2.0, 3.0}, 25.0);
  MockMpu6050 mock(clock, source, quietMock());
  RecordingBus bus(mock, clock);
  Recorder rec;
  Mpu6050Driver driver(bus, mock.dataReady(), clock, rec, Mpu6050Config{});
  driver.start();
  for (int i = 0; i < 400 && rec.samples.empty(); ++i) {
    if (auto d = driver.nextDeadlineNs(); d && *d > clock.nowNs()) clock.setNs(*d);
    mock.sync();
    driver.onTimer(clock.nowNs());
    driver.onDataReady();
    if (driver.status().state == DeviceState::Configuring || driver.status().state == DeviceState::Probing) continue;
    clock.advanceNs(kNsPerMillisecond);
  }
  ASSERT_FALSE(rec.samples.empty());
  const auto& log = bus.log();
  struct Step {
    char op;
    std::uint8_t reg;
    std::uint32_t value;
  };
  const std::vector<Step> expected = {
      {'S', 0x68, 0},    {'R', 0x75, 0x68},  // probe
      {'W', 0x6B, 0x80},                     // DEVICE_RESET
      {'R', 0x6B, 0x40},                     // reset done: asleep
      {'W', 0x6B, 0x01}, {'W', 0x6C, 0x00}, {'W', 0x19, 19},   {'W', 0x1A, 4},    {'W', 0x1B, 0x00},
      {'W', 0x37, 0x00}, {'W', 0x38, 0x11}, {'W', 0x23, 0xF0}, {'W', 0x6A, 0x40},  // table
      {'R', 0x6B, 0x01}, {'R', 0x6C, 0x00}, {'R', 0x19, 19},   {'R', 0x1A, 4},    {'R', 0x1B, 0x00},
      {'R', 0x37, 0x00}, {'R', 0x38, 0x11}, {'R', 0x23, 0xF0}, {'R', 0x6A, 0x40},  // read-back
      {'W', 0x6A, 0x00}, {'W', 0x6A, 0x04}, {'W', 0x6A, 0x40},                     // FIFO off, reset, on
  };
  ASSERT_GE(log.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(log[i].op, expected[i].op) << "transfer " << i;
    EXPECT_EQ(log[i].reg, expected[i].reg) << "transfer " << i;
    EXPECT_EQ(log[i].value, expected[i].value) << "transfer " << i;
  }
  // PX4 waits 100 ms after DEVICE_RESET before checking; the driver never sleeps but its
  // deadline must not come sooner. The gyro needs ~30 ms to start: 50 ms before read-back.
  EXPECT_GE(log[3].t_ns - log[2].t_ns, 100 * kNsPerMillisecond);
  EXPECT_GE(log[13].t_ns - log[12].t_ns, 30 * kNsPerMillisecond);
  // After the FIFO start: FIFO_COUNT reads, then the first burst of whole frames from
  // FIFO_R_W right after a FIFO_COUNT read, then TEMP_OUT for the alignment check.
  EXPECT_EQ(log[expected.size()].op, 'w');
  EXPECT_EQ(log[expected.size()].reg, 0x72);
  std::size_t burst = expected.size();
  while (burst < log.size() && log[burst].op != 'B') ++burst;
  ASSERT_LT(burst + 1, log.size());
  EXPECT_EQ(log[burst].reg, 0x74);
  EXPECT_EQ(log[burst].value % 8, 0u);
  EXPECT_EQ(log[burst - 1].reg, 0x72);
  EXPECT_EQ(log[burst + 1].op, 'w');
  EXPECT_EQ(log[burst + 1].reg, 0x41);
  EXPECT_EQ(driver.status().state, DeviceState::Streaming);
  EXPECT_EQ(driver.counters().device_resets, 1u);
  EXPECT_EQ(driver.counters().configures, 1u);
}

TEST(Mpu6050DriverInit, StreamsTenSecondsWithoutGapsAtTheConfiguredRate) {
  ConstantSource source({1.0, -2.0, 3.0}, 25.0);
  DriverRig rig(source);
  rig.startStreaming();
  rig.runFor(10 * kNsPerSecond);
  EXPECT_TRUE(rig.recorder.gaps.empty());
  const StreamCheck c = checkStream(rig.recorder, rig.truth, rig.truePeriodNs(), {2'000.0, 0});
  // 10 s at 50 Hz: 500 samples, give or take the one in flight at each end.
  EXPECT_NEAR(static_cast<double>(c.matched), 500.0, 2.0);
  EXPECT_EQ(rig.driver.counters().samples_delivered, rig.recorder.samples.size());
  EXPECT_EQ(rig.driver.status().state, DeviceState::Streaming);
  EXPECT_EQ(rig.driver.counters().fifo_resets, 1u);
  EXPECT_GT(rig.driver.counters().register_checks, 90u);  // one per 100 ms
  EXPECT_EQ(rig.driver.counters().silent_resets, 0u);
}

TEST(Mpu6050DriverInit, AddressAd0HighIsUsed) {
  ConstantSource source({0.5, 0.5, 0.5});
  RigOptions o;
  o.mock.address = 0x69;
  o.driver.address = 0x69;
  DriverRig rig(source, o);
  rig.startStreaming();
  EXPECT_EQ(rig.mock.selectedDevice(), 0x69);
  EXPECT_EQ(rig.mock.counters().nacks_absent_address, 0u);
}

TEST(Mpu6050DriverInit, KnownClonesAreAcceptedWithAWarning) {
  for (std::uint8_t id : {0x70, 0x72, 0x98}) {
    ConstantSource source({0.5, 0.5, 0.5});
    DriverRig rig(source);
    FaultPlan plan;
    plan.who_am_i = id;
    rig.mock.setFaultPlan(plan);
    rig.startStreaming();
    EXPECT_EQ(rig.driver.status().who_am_i, id);
    EXPECT_EQ(rig.driver.status().state, DeviceState::Streaming);
    EXPECT_TRUE(rig.logged("warning: WHO_AM_I")) << int(id);
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(id));
    EXPECT_TRUE(rig.logged(hex)) << int(id);
  }
}

TEST(Mpu6050DriverInit, UnknownWhoAmIIsRefusedAndNothingIsWritten) {
  ConstantSource source({0.5, 0.5, 0.5});
  DriverRig rig(source);
  FaultPlan plan;
  plan.who_am_i = 0x12;
  rig.mock.setFaultPlan(plan);
  rig.start();
  rig.runFor(5 * kNsPerSecond);
  const DeviceStatus& s = rig.driver.status();
  EXPECT_EQ(s.state, DeviceState::Failed);
  EXPECT_FALSE(s.retrying);
  EXPECT_NE(s.reason.find("0x12"), std::string::npos) << s.reason;
  EXPECT_NE(s.reason.find("not an MPU6050"), std::string::npos) << s.reason;
  EXPECT_FALSE(rig.driver.nextDeadlineNs().has_value());
  EXPECT_EQ(rig.mock.counters().device_resets, 0u);
  EXPECT_TRUE(rig.recorder.samples.empty());
}

TEST(Mpu6050DriverInit, NothingAtTheAddressBacksOffThenReportsNotFunctionalAndKeepsTrying) {
  ConstantSource source({0.5, 0.5, 0.5});
  RigOptions o;
  o.driver.address = 0x69;  // the chip answers at 0x68 only
  o.driver.bus_name = "/dev/i2c-1";
  DriverRig rig(source, o);
  rig.start();
  rig.runFor(200 * kNsPerMillisecond);
  EXPECT_EQ(rig.driver.status().state, DeviceState::Recovering);
  rig.runFor(30 * kNsPerSecond);
  const DeviceStatus& s = rig.driver.status();
  EXPECT_EQ(s.state, DeviceState::Failed);
  EXPECT_TRUE(s.retrying);
  EXPECT_NE(s.reason.find("0x69 on /dev/i2c-1"), std::string::npos) << s.reason;
  EXPECT_NE(s.reason.find("EREMOTEIO"), std::string::npos) << s.reason;
  EXPECT_NE(s.reason.find("i2cdetect"), std::string::npos) << s.reason;
  ASSERT_TRUE(rig.driver.nextDeadlineNs().has_value());  // still retrying, at the maximum backoff
  // Backoff 50, 100, 200, ... ms capped at 2 s: over 30 s about 20 probes, not thousands.
  const auto probes = rig.mock.counters().nacks_absent_address;
  EXPECT_GT(probes, 10u);
  EXPECT_LT(probes, 100u);
  EXPECT_TRUE(rig.recorder.samples.empty());
}

TEST(Mpu6050DriverInit, ConfigurationIsValidatedWithMessagesNamingTheField) {
  const auto message = [](Mpu6050Config c) {
    try {
      validateConfig(c);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  Mpu6050Config c;
  c.sample_rate_hz = 300.0;  // 1000/300 is not an integer
  EXPECT_NE(message(c).find("sample_rate_hz"), std::string::npos);
  c = {};
  c.fs_sel = 4;
  EXPECT_NE(message(c).find("fs_sel"), std::string::npos);
  c = {};
  c.address = 0x50;
  EXPECT_NE(message(c).find("0x50"), std::string::npos);
  c = {};
  c.dlpf_cfg = 7;
  EXPECT_NE(message(c).find("dlpf_cfg"), std::string::npos);
  c = {};
  c.max_frames_per_wakeup = 200;  // 200 frames of 8 bytes exceed the FIFO
  EXPECT_NE(message(c).find("max_frames_per_wakeup"), std::string::npos);
  c = {};
  c.data_ready_mode = DataReadyMode::Polling;
  EXPECT_NE(message(c).find("polling_period_ns"), std::string::npos);
  c.polling_period_ns = 5 * kNsPerSecond;  // the FIFO would overflow between polls
  EXPECT_NE(message(c).find("overflow"), std::string::npos);
  EXPECT_EQ(message(Mpu6050Config{}), "");
}

TEST(Mpu6050DriverInit, SampleRateDividerAndPollingPeriod) {
  Mpu6050Config c;
  EXPECT_EQ(sampleRateDivider(c), 19);  // 1000 / (1 + 19) = 50
  c.sample_rate_hz = 1000.0;
  EXPECT_EQ(sampleRateDivider(c), 0);
  c.sample_rate_hz = 1000.0 / 256.0;
  EXPECT_EQ(sampleRateDivider(c), 255);
  c.dlpf_cfg = 0;  // 8 kHz internal rate
  c.sample_rate_hz = 500.0;
  EXPECT_EQ(sampleRateDivider(c), 15);
  EXPECT_DOUBLE_EQ(nominalSamplePeriodNs(c), 2e6);

  // Polling: the FIFO of a clone holds 512 / 8 = 64 frames; at the fastest plausible clock
  // (+10 %) it fills in 64 · P / 1.1; a quarter of that, capped at 100 ms.
  Mpu6050Config p;
  EXPECT_EQ(pollingPeriodNs(p), 100 * kNsPerMillisecond);  // 50 Hz: 64 · 18.2 ms / 4 = 291 ms → 100 ms
  p.sample_rate_hz = 1000.0;
  p.dlpf_cfg = 1;
  EXPECT_NEAR(static_cast<double>(pollingPeriodNs(p)), 64.0 * (1e6 / 1.1) / 4.0, 1.0);
}

TEST(Mpu6050DriverInit, TheSampleRateRuleTheDaemonConfigSharesAcceptsOnlyWholeDivisors) {
  EXPECT_EQ(smplrtDivFor(4, 50.0), std::optional<std::uint8_t>(19));
  EXPECT_EQ(smplrtDivFor(0, 500.0), std::optional<std::uint8_t>(15));  // 8 kHz / 16
  EXPECT_EQ(smplrtDivFor(1, 1000.0 / 256.0), std::optional<std::uint8_t>(255));
  EXPECT_EQ(smplrtDivFor(1, 300.0), std::nullopt);   // 1000 / 300 is not whole
  EXPECT_EQ(smplrtDivFor(1, 2000.0), std::nullopt);  // faster than the output rate
  EXPECT_EQ(smplrtDivFor(1, 1000.0 / 257.0), std::nullopt);
  EXPECT_EQ(smplrtDivFor(1, 0.0), std::nullopt);
  EXPECT_EQ(smplrtDivFor(1, -50.0), std::nullopt);
  EXPECT_EQ(smplrtDivFor(1, std::numeric_limits<double>::infinity()), std::nullopt);
  EXPECT_EQ(smplrtDivFor(1, std::numeric_limits<double>::quiet_NaN()), std::nullopt);
}

}  // namespace
}  // namespace gyrod::driver::test
