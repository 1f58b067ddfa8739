// The MPU6050 sensor model: the DLPF table against the register map (rev 4.2, CONFIG
// 0x1A), the implemented filter's measured response against its own claimed H (and H
// against the documented −3 dB bandwidth), steady state, and quantisation edges.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>

#include "processing/simulation/sensor_model.hpp"

using namespace gyrod::processing;

namespace {
constexpr double kPiSensor = std::numbers::pi;
}

TEST(DlpfSetting, MatchesRegisterMapTable) {
  // Register Map rev 4.2 §4.3, gyroscope columns: bandwidth [Hz], delay [ms], Fs [kHz].
  const double expected[7][3] = {{256, 0.98, 8}, {188, 1.9, 1}, {98, 2.8, 1}, {42, 4.8, 1},
                                 {20, 8.3, 1},   {10, 13.4, 1}, {5, 18.6, 1}};
  for (int cfg = 0; cfg <= 6; ++cfg) {
    const DlpfSetting& s = dlpfSetting(cfg);
    EXPECT_EQ(s.cfg, cfg);
    EXPECT_EQ(s.bandwidth_hz, expected[cfg][0]);
    EXPECT_EQ(s.delay_ms, expected[cfg][1]);
    EXPECT_EQ(s.internal_rate_hz, expected[cfg][2] * 1000.0);
  }
  EXPECT_THROW(dlpfSetting(-1), std::invalid_argument);
  EXPECT_THROW(dlpfSetting(7), std::invalid_argument);
  EXPECT_THROW(DigitalLowPassFilter(7), std::invalid_argument);
}

TEST(DigitalLowPassFilter, MeasuredGainAndPhaseOfSinusoidEqualFrequencyResponse) {
  // Drive the filter with A·sin(2πft + φ) (random phase from a fixed seed), let it
  // settle, then recover amplitude and phase of the output by correlating over a whole
  // number of periods. Both must match H(f) that the filter claims to implement.
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> phase_dist(0.0, 2.0 * kPiSensor);
  for (int cfg : {0, 1, 2, 3, 4, 5, 6}) {
    const DlpfSetting& s = dlpfSetting(cfg);
    const double fs = s.internal_rate_hz;
    const std::size_t n = static_cast<std::size_t>(fs);  // 1 s → integer-Hz frequencies have whole periods
    for (double f : {1.0, 0.5 * s.bandwidth_hz, s.bandwidth_hz, 2.0 * s.bandwidth_hz, 0.4 * fs}) {
      f = std::round(f);
      DigitalLowPassFilter filter(cfg);
      const double phase = phase_dist(rng);
      const double amplitude = 3.0;
      double sum_sin = 0.0, sum_cos = 0.0;
      const std::size_t settle = 4 * n;  // slowest pole (cfg 6) decays by e^-200 in 4 s
      for (std::size_t i = 0; i < settle + n; ++i) {
        const double t = static_cast<double>(i) / fs;
        const double y = filter.update(amplitude * std::sin(2.0 * kPiSensor * f * t + phase));
        if (i >= settle) {
          sum_sin += y * std::sin(2.0 * kPiSensor * f * t + phase);
          sum_cos += y * std::cos(2.0 * kPiSensor * f * t + phase);
        }
      }
      const std::complex<double> measured(2.0 * sum_sin / (amplitude * n), 2.0 * sum_cos / (amplitude * n));
      const std::complex<double> h = filter.frequencyResponse(f);
      EXPECT_NEAR(std::abs(measured), std::abs(h), 1e-3) << "cfg " << cfg << " f " << f;
      if (std::abs(h) > 1e-2) {
        EXPECT_NEAR(std::arg(measured), std::arg(h), 1e-3) << "cfg " << cfg << " f " << f;
      }
    }
  }
}

TEST(DigitalLowPassFilter, MinusThreeDecibelsAtDocumentedBandwidthUnityAtDc) {
  for (int cfg = 0; cfg <= 6; ++cfg) {
    const DigitalLowPassFilter filter(cfg);
    const double bw = filter.setting().bandwidth_hz;
    EXPECT_NEAR(std::norm(filter.frequencyResponse(bw)), 0.5, 1e-12) << "cfg " << cfg;
    EXPECT_NEAR(std::abs(filter.frequencyResponse(0.0)), 1.0, 1e-12) << "cfg " << cfg;
    // A low-pass: |H| decreases from DC to Nyquist.
    double previous = 2.0;
    for (int k = 0; k <= 100; ++k) {
      const double g = std::abs(filter.frequencyResponse(0.005 * k * filter.setting().internal_rate_hz));
      EXPECT_LE(g, previous + 1e-15) << "cfg " << cfg << " k " << k;
      previous = g;
    }
  }
}

TEST(DigitalLowPassFilter, ConstantInputPassesWithUnitGain) {
  DigitalLowPassFilter filter(6);
  double y = 0.0;
  for (int i = 0; i < 5000; ++i) y = filter.update(-2.5);
  EXPECT_NEAR(y, -2.5, 1e-12);
}

TEST(DigitalLowPassFilter, ResetIsSteadyState) {
  for (int cfg = 0; cfg <= 6; ++cfg) {
    DigitalLowPassFilter filter(cfg);
    filter.reset(17.25);
    for (int i = 0; i < 100; ++i) ASSERT_NEAR(filter.update(17.25), 17.25, 1e-12) << "cfg " << cfg;
    filter.reset();
    EXPECT_EQ(filter.update(0.0), 0.0);
  }
}

TEST(DigitalLowPassFilter, ImpulseResponseIsTheInverseTransformOfH) {
  // h[n] = (1/N)·Σ_k H(k·fs/N)·e^{j2πkn/N} for N large (the response decays well within N).
  const int cfg = 4;
  DigitalLowPassFilter filter(cfg);
  const double fs = filter.setting().internal_rate_hz;
  const int n_fft = 4096;
  for (int n = 0; n < 40; ++n) {
    const double h_n = filter.update(n == 0 ? 1.0 : 0.0);
    std::complex<double> sum = 0.0;
    for (int k = 0; k < n_fft; ++k)
      sum += filter.frequencyResponse(k * fs / n_fft) * std::polar(1.0, 2.0 * kPiSensor * k * n / n_fft);
    EXPECT_NEAR(h_n, sum.real() / n_fft, 1e-12) << "n " << n;
  }
}

TEST(DigitalLowPassFilter, GroupDelayAtDcIsMinusPhaseSlope) {
  for (int cfg = 0; cfg <= 6; ++cfg) {
    const DigitalLowPassFilter filter(cfg);
    const double df = 1e-3;  // Hz
    const double slope = std::arg(filter.frequencyResponse(df)) / (2.0 * kPiSensor * df);
    EXPECT_NEAR(filter.groupDelayAtDc(), -slope, 1e-9) << "cfg " << cfg;
  }
}

TEST(GyroSensitivity, MatchesRegisterMap) {
  EXPECT_EQ(gyroSensitivityLsbPerDps(0), 131.0);
  EXPECT_EQ(gyroSensitivityLsbPerDps(1), 65.5);
  EXPECT_EQ(gyroSensitivityLsbPerDps(2), 32.8);
  EXPECT_EQ(gyroSensitivityLsbPerDps(3), 16.4);
  EXPECT_THROW(gyroSensitivityLsbPerDps(-1), std::invalid_argument);
  EXPECT_THROW(gyroSensitivityLsbPerDps(4), std::invalid_argument);
}

TEST(QuantizeToInt16, RoundsToNearestLsb) {
  const double lsb = 131.0;
  EXPECT_EQ(quantizeToInt16(0.0, lsb), 0);
  EXPECT_EQ(quantizeToInt16(1.0 / lsb, lsb), 1);
  EXPECT_EQ(quantizeToInt16(0.49 / lsb, lsb), 0);
  EXPECT_EQ(quantizeToInt16(0.51 / lsb, lsb), 1);
  EXPECT_EQ(quantizeToInt16(-0.51 / lsb, lsb), -1);
  EXPECT_EQ(quantizeToInt16(0.5, 2.0), 1);  // exactly half an LSB: away from zero
  EXPECT_EQ(quantizeToInt16(-0.5, 2.0), -1);
  EXPECT_EQ(quantizeToInt16(100.0, lsb), 13100);
  EXPECT_EQ(quantizeToInt16(-1.5, 1.0), -2);
}

TEST(QuantizeToInt16, SaturatesAtBothEnds) {
  EXPECT_EQ(quantizeToInt16(32767.0, 1.0), 32767);
  EXPECT_EQ(quantizeToInt16(32767.4, 1.0), 32767);
  EXPECT_EQ(quantizeToInt16(32767.5, 1.0), 32767);  // would round to 32768
  EXPECT_EQ(quantizeToInt16(250.0, 131.0), 32750);
  EXPECT_EQ(quantizeToInt16(251.0, 131.0), 32767);  // beyond ±250 °/s at FS_SEL 0
  EXPECT_EQ(quantizeToInt16(1e300, 1.0), 32767);
  EXPECT_EQ(quantizeToInt16(std::numeric_limits<double>::infinity(), 1.0), 32767);
  EXPECT_EQ(quantizeToInt16(-32768.0, 1.0), -32768);
  EXPECT_EQ(quantizeToInt16(-32767.6, 1.0), -32768);
  EXPECT_EQ(quantizeToInt16(-32768.5, 1.0), -32768);  // would round to −32769
  EXPECT_EQ(quantizeToInt16(-251.0, 131.0), -32768);
  EXPECT_EQ(quantizeToInt16(-std::numeric_limits<double>::infinity(), 1.0), -32768);
}

TEST(QuantizeToInt16, NanIsZeroAndBadScaleThrows) {
  EXPECT_EQ(quantizeToInt16(std::numeric_limits<double>::quiet_NaN(), 131.0), 0);
  EXPECT_THROW(quantizeToInt16(1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(quantizeToInt16(1.0, -131.0), std::invalid_argument);
  EXPECT_THROW(quantizeToInt16(1.0, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(quantizeToInt16(1.0, std::numeric_limits<double>::infinity()), std::invalid_argument);
}
