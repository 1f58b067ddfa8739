// The mock's sample clock, scaling, temperature encoding, signal path and sources.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <numbers>

#include "driver/mock/mock_signal_source.hpp"
#include "processing/simulation/sensor_model.hpp"
#include "tests/driver/mock_rig.hpp"

namespace gyrod::driver::test {
namespace {

namespace m = mpu6050;

struct RateCase {
  int dlpf_cfg;
  int smplrt_div;
  double clock_error_ppm;
};

class SampleRate : public ::testing::TestWithParam<RateCase> {};

TEST_P(SampleRate, CountOverTenSecondsIsInternalRateOverOnePlusDivider) {
  const RateCase c = GetParam();
  ConstantSource source({0, 0, 0});
  MockMpu6050Config config = Rig::quietConfig();
  config.clock_error_ppm = c.clock_error_ppm;
  Rig rig(source, config);
  std::vector<std::int64_t> times;
  rig.mock.setSampleObserver([&](const SampleRecord& s) {
    if (times.size() < 3) times.push_back(s.time_ns);
  });
  rig.wake(c.dlpf_cfg, static_cast<std::uint8_t>(c.smplrt_div));
  const std::int64_t t0 = rig.clock.nowNs();
  // Gyro output rate (RM §4.2): 8 kHz for DLPF_CFG 0 and 7, else 1 kHz; the chip's own
  // clock error scales it. Observe for 10 s plus a quarter sample so that no tick falls
  // on the boundary.
  const double internal_hz =
      ((c.dlpf_cfg == 0 || c.dlpf_cfg == 7) ? 8000.0 : 1000.0) * (1.0 + c.clock_error_ppm * 1e-6);
  const double sample_hz = internal_hz / (1 + c.smplrt_div);
  const double window_s = 10.0 + 0.25 / sample_hz;
  for (int i = 0; i < 100; ++i) rig.advance(100 * kNsPerMillisecond);
  rig.advance(static_cast<std::int64_t>(std::llround((window_s - 10.0) * 1e9)));
  const auto expected = static_cast<std::uint64_t>(std::floor(window_s * sample_hz));
  EXPECT_EQ(rig.mock.counters().samples_produced, expected);
  EXPECT_EQ(rig.mock.counters().internal_ticks, static_cast<std::uint64_t>(std::floor(window_s * internal_hz)));
  ASSERT_EQ(times.size(), 3u);
  const double period_ns = 1e9 / sample_hz;
  EXPECT_NEAR(static_cast<double>(times[0] - t0), period_ns, 1.0);
  EXPECT_NEAR(static_cast<double>(times[2] - times[1]), period_ns, 1.0);
}

INSTANTIATE_TEST_SUITE_P(Configurations, SampleRate,
                         ::testing::Values(RateCase{1, 0, 0.0},        // 1 kHz
                                           RateCase{3, 9, 0.0},        // 100 Hz
                                           RateCase{6, 4, 0.0},        // 200 Hz
                                           RateCase{0, 7, 0.0},        // 8 kHz / 8
                                           RateCase{7, 79, 0.0},       // 8 kHz / 80
                                           RateCase{2, 0, 20'000.0},   // 2 % fast
                                           RateCase{4, 9, -35'000.0},  // 3.5 % slow
                                           RateCase{0, 0, 1'500.0}));  // 8 kHz, 1500 ppm

struct ScaleCase {
  int fs_sel;
  double rate_dps;
  std::int16_t expected_raw;
};

class GyroScaling : public ::testing::TestWithParam<ScaleCase> {};

TEST_P(GyroScaling, ConstantRateGivesTheDatasheetCount) {
  const ScaleCase c = GetParam();
  ConstantSource source({c.rate_dps, -c.rate_dps, 0.0});
  Rig rig(source);
  write(rig.mock, Register::GYRO_CONFIG, static_cast<std::uint8_t>(c.fs_sel << 3));
  rig.wake(3, 0);  // a constant passes any DLPF setting at DC gain 1
  rig.advance(50 * kNsPerMillisecond);
  std::array<std::uint8_t, 6> b{};
  ASSERT_EQ(rig.mock.readBlock(A(Register::GYRO_XOUT_H), b), 0);
  EXPECT_EQ(be16(b[0], b[1]), c.expected_raw);
  // The negated rate saturates at −32768 rather than wrapping (INT16_MIN has no positive twin).
  const std::int16_t negated = c.expected_raw == 32767 ? -32768 : static_cast<std::int16_t>(-c.expected_raw);
  EXPECT_EQ(be16(b[2], b[3]), negated);
  EXPECT_EQ(be16(b[4], b[5]), 0);
}

// Sensitivities 131 / 65.5 / 32.8 / 16.4 LSB per °/s (product spec §6.1), worked by hand.
INSTANTIATE_TEST_SUITE_P(FullScaleRanges, GyroScaling,
                         ::testing::Values(ScaleCase{0, 100.0, 13100}, ScaleCase{1, 100.0, 6550},
                                           ScaleCase{2, 100.0, 3280}, ScaleCase{3, 100.0, 1640}, ScaleCase{0, 1.0, 131},
                                           ScaleCase{1, 1.1, 72},  // 72.05 → 72
                                           ScaleCase{2, 0.5, 16},  // 16.4 → 16
                                           ScaleCase{3, 1000.0, 16400}, ScaleCase{0, 250.0, 32750},
                                           ScaleCase{0, 300.0, 32767},     // 39300 saturates
                                           ScaleCase{3, 2500.0, 32767}));  // 41000 saturates

TEST(MockMpu6050Sampling, RegisterMapSensitivitiesAgreeWithTheSensorModel) {
  for (int fs = 0; fs < 4; ++fs) {
    EXPECT_EQ(m::kGyroLsbPerDps[fs], processing::gyroSensitivityLsbPerDps(fs)) << "FS_SEL " << fs;
  }
}

TEST(MockMpu6050Sampling, TemperatureEncodingFollowsTheRegisterMapFormula) {
  // TEMP_OUT = round((T − 36.53) · 340), worked out by hand for each T.
  const std::pair<double, std::int16_t> cases[] = {{36.53, 0},    {25.0, -3920},   {0.0, -12420},
                                                   {85.0, 16480}, {-40.0, -26020}, {37.53, 340}};
  for (const auto& [t_c, raw] : cases) {
    ConstantSource source({0, 0, 0}, t_c);
    Rig rig(source);
    rig.wake(1, 0);
    rig.advance(kNsPerMillisecond);
    std::uint16_t w = 0;
    ASSERT_EQ(rig.mock.readWordBigEndian(A(Register::TEMP_OUT_H), w), 0);
    EXPECT_EQ(static_cast<std::int16_t>(w), raw) << t_c << " °C";
    EXPECT_NEAR(m::temperatureDegCFromRaw(static_cast<std::int16_t>(w)), t_c, 0.5 / 340.0 + 1e-12);
  }
}

TEST(MockMpu6050Sampling, AccelSeesOneGOnZWithTheConfiguredNoise) {
  ConstantSource source({0, 0, 0});
  MockMpu6050Config config;
  config.accel_noise_g = 0.002;  // σ = 32.8 LSB at AFS_SEL 0
  Rig rig(source, config);
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  rig.mock.setSampleObserver([&](const SampleRecord& s) {
    const double z = s.accel[2];
    sum += z;
    sum2 += z * z;
    ++n;
  });
  rig.wake(1, 0);
  rig.advance(4 * kNsPerSecond);
  ASSERT_EQ(n, 4000);
  const double mean = sum / n;
  const double sd = std::sqrt(sum2 / n - mean * mean);
  const double sigma_lsb = 0.002 * 16384.0;
  EXPECT_NEAR(mean, 16384.0, 5.0 * sigma_lsb / std::sqrt(n));
  // The sample s.d. of n normals has standard error ≈ σ/√(2n).
  EXPECT_NEAR(sd, sigma_lsb, 5.0 * sigma_lsb / std::sqrt(2.0 * n) + 0.5);
}

TEST(MockMpu6050Sampling, ConstantPassesEveryDlpfSettingAtUnitGain) {
  for (int cfg = 0; cfg <= 7; ++cfg) {
    ConstantSource source({12.3, -7.25, 100.0});
    Rig rig(source);
    rig.wake(cfg, 0);
    rig.advance(200 * kNsPerMillisecond);
    std::array<std::uint8_t, 6> b{};
    ASSERT_EQ(rig.mock.readBlock(A(Register::GYRO_XOUT_H), b), 0);
    // 12.3·131 = 1611.3 → 1611; −7.25·131 = −949.75 → −950 (no ties: rounding mode-proof).
    EXPECT_EQ(be16(b[0], b[1]), 1611) << "DLPF_CFG " << cfg;
    EXPECT_EQ(be16(b[2], b[3]), -950) << "DLPF_CFG " << cfg;
    EXPECT_EQ(be16(b[4], b[5]), 13100) << "DLPF_CFG " << cfg;
  }
}

TEST(MockMpu6050Sampling, ReplayFeedsOneValuePerInternalTickInOrder) {
  // DLPF bypassed at 8 kHz, SMPLRT_DIV 0: each tick is a sample, so raw = round(v · 131).
  const std::vector<double> x = {0.0, 1.0, -1.0, 2.4, 100.0, -250.0};
  const std::vector<double> y = {1.0, 1.0, 1.0, 1.0, 1.0, 1.0};
  const std::vector<double> z(6, 0.0), t(6, 36.53);
  ReplaySource source(x, y, z, t, 8000.0, ReplaySource::AtEnd::Loop);
  Rig rig(source);
  std::vector<std::int16_t> got;
  rig.mock.setSampleObserver([&](const SampleRecord& s) { got.push_back(s.gyro[0]); });
  rig.wake(7, 0);
  rig.advance(9 * 125'000);  // nine ticks: the replay wraps once
  const std::vector<std::int16_t> expected = {0, 131, -131, 314, 13100, -32750, 0, 131, -131};
  EXPECT_EQ(got, expected);  // 2.4·131 = 314.4 → 314
  EXPECT_EQ(source.timesExhausted(), 1u);
  EXPECT_EQ(rig.mock.counters().source_rate_mismatch_ticks, 0u);
}

TEST(MockMpu6050Sampling, ReplayAtTheWrongRateIsCounted) {
  ReplaySource source({1.0}, {1.0}, {1.0}, {25.0}, 1000.0, ReplaySource::AtEnd::HoldLast);
  Rig rig(source);
  rig.wake(0, 0);  // 8 kHz ticks, but the replay was made for 1 kHz
  rig.advance(kNsPerMillisecond);
  EXPECT_EQ(rig.mock.counters().internal_ticks, 8u);
  EXPECT_EQ(rig.mock.counters().source_rate_mismatch_ticks, 8u);
  EXPECT_EQ(source.timesExhausted(), 1u);  // held the last value after the first tick
}

TEST(MockMpu6050Sampling, SourcesRejectBadInput) {
  EXPECT_THROW(ReplaySource({1.0, 2.0}, {1.0}, {1.0, 2.0}, {25.0, 25.0}, 1000.0), std::invalid_argument);
  EXPECT_THROW(ReplaySource({}, {}, {}, {}, 1000.0), std::invalid_argument);
  EXPECT_THROW(ReplaySource({1.0}, {1.0}, {1.0}, {25.0}, 0.0), std::invalid_argument);
  EXPECT_THROW(ReplaySource({NAN}, {1.0}, {1.0}, {25.0}, 1000.0), std::invalid_argument);
  EXPECT_THROW(ConstantSource({INFINITY, 0, 0}), std::invalid_argument);
  EXPECT_THROW(SinusoidSource({SinusoidAxis{0, 1, -1, 0}, SinusoidAxis{}, SinusoidAxis{}}), std::invalid_argument);
}

TEST(MockMpu6050Sampling, SampleSequenceNumbersCountEverySampleAcrossResets) {
  ConstantSource source({0, 0, 0});
  MockMpu6050Config config = Rig::quietConfig();
  config.reset_duration_ns = kNsPerMillisecond;
  Rig rig(source, config);
  std::vector<std::uint64_t> seq;
  rig.mock.setSampleObserver([&](const SampleRecord& s) { seq.push_back(s.sequence); });
  rig.wake(1, 0);
  rig.advance(5 * kNsPerMillisecond);
  write(rig.mock, Register::PWR_MGMT_1, m::DEVICE_RESET);
  rig.advance(2 * kNsPerMillisecond);
  rig.wake(1, 0);
  rig.advance(5 * kNsPerMillisecond);
  ASSERT_EQ(seq.size(), 10u);
  for (std::size_t i = 0; i < seq.size(); ++i) EXPECT_EQ(seq[i], i);
  ASSERT_TRUE(rig.mock.lastSample().has_value());
  EXPECT_EQ(rig.mock.lastSample()->sequence, 9u);
}

TEST(MockMpu6050Sampling, OneVirtualHourRuns) {
  // No timing assertion (speed belongs in benchmarks); the wall time is printed for the
  // record. 1 kHz, FIFO on and never read, data-ready pulses nobody consumes.
  SinusoidSource source({SinusoidAxis{0.1, 2.0, 0.5, 0.0}, SinusoidAxis{}, SinusoidAxis{-0.2, 0.0, 0.0, 0.0}});
  MockMpu6050Config config;  // with accel noise, as in use
  Rig rig(source, config);
  write(rig.mock, Register::FIFO_EN, 0xF0);
  write(rig.mock, Register::INT_ENABLE, m::DATA_RDY_EN | m::FIFO_OFLOW_EN);
  write(rig.mock, Register::USER_CTRL, m::USER_CTRL_BIT::FIFO_EN);
  rig.wake(3, 0);
  const auto start = std::chrono::steady_clock::now();
  for (int s = 0; s < 3600; ++s) rig.advance(kNsPerSecond);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "[ measure  ] one virtual hour at 1 kHz took " << wall_s << " s wall time\n";
  ::testing::Test::RecordProperty("virtual_hour_wall_seconds", std::to_string(wall_s));
  EXPECT_EQ(rig.mock.counters().samples_produced, 3'600'000u);
  EXPECT_EQ(rig.mock.counters().internal_ticks, 3'600'000u);
  EXPECT_EQ(fifoCount(rig.mock), 1024);
  EXPECT_EQ(rig.mock.counters().fifo_bytes_written, 8u * 3'600'000u);
  EXPECT_EQ(rig.mock.counters().fifo_bytes_overwritten, 8u * 3'600'000u - 1024u);
}

}  // namespace
}  // namespace gyrod::driver::test
