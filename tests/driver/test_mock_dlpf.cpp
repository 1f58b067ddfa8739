// The DLPF in the mock's signal path: a sinusoid comes out of the registers attenuated as
// the filter of the configured DLPF_CFG says, at the configured internal rate.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>

#include "driver/mock/mock_signal_source.hpp"
#include "processing/simulation/sensor_model.hpp"
#include "tests/driver/mock_rig.hpp"

namespace gyrod::driver::test {
namespace {

// Least-squares fit y ≈ c + a·sin(2πft) + b·cos(2πft); returns √(a² + b²).
double fittedAmplitude(const std::vector<double>& t_s, const std::vector<double>& y, double f_hz) {
  Eigen::MatrixXd X(static_cast<Eigen::Index>(y.size()), 3);
  Eigen::VectorXd v(static_cast<Eigen::Index>(y.size()));
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double w = 2.0 * std::numbers::pi * f_hz * t_s[i];
    X.row(static_cast<Eigen::Index>(i)) << 1.0, std::sin(w), std::cos(w);
    v(static_cast<Eigen::Index>(i)) = y[i];
  }
  const Eigen::Vector3d beta = X.colPivHouseholderQr().solve(v);
  return std::hypot(beta(1), beta(2));
}

// Gain of the mock's chain for a sinusoid of frequency f at DLPF_CFG cfg (SMPLRT_DIV 0,
// FS_SEL 0, amplitude 100 °/s = 13100 LSB; the first second is discarded as settling).
double measuredGain(int cfg, double f_hz) {
  const double amplitude_dps = 100.0;
  SinusoidSource source({SinusoidAxis{0.0, amplitude_dps, f_hz, 0.3}, SinusoidAxis{}, SinusoidAxis{}});
  Rig rig(source);
  std::vector<double> t_s, y;
  rig.mock.setSampleObserver([&](const SampleRecord& s) {
    const double t = static_cast<double>(s.time_ns - rig.mock.epochNs()) * 1e-9;
    if (t <= 1.0) return;
    t_s.push_back(t);
    y.push_back(s.gyro[0]);
  });
  rig.wake(cfg, 0);
  rig.advance(3 * kNsPerSecond);
  return fittedAmplitude(t_s, y, f_hz) / (amplitude_dps * 131.0);
}

class DlpfResponse : public ::testing::TestWithParam<int> {};

TEST_P(DlpfResponse, SinusoidIsAttenuatedAsTheConfiguredFilter) {
  const int cfg = GetParam();
  const processing::DlpfSetting& setting = processing::dlpfSetting(cfg);
  const processing::DigitalLowPassFilter filter(cfg);
  // Quantisation (±0.5 LSB on 13100) and the finite fit contribute < 1e-4 of gain.
  for (double f : {setting.bandwidth_hz / 10.0, setting.bandwidth_hz, 2.0 * setting.bandwidth_hz}) {
    const double gain = measuredGain(cfg, f);
    EXPECT_NEAR(gain, std::abs(filter.frequencyResponse(f)), 1e-3) << "DLPF_CFG " << cfg << " at " << f << " Hz";
  }
  // Independent of the implementation: the documented bandwidth is the −3 dB point, and
  // a tenth of it passes almost unchanged.
  EXPECT_NEAR(measuredGain(cfg, setting.bandwidth_hz), 1.0 / std::sqrt(2.0), 0.02) << "DLPF_CFG " << cfg;
  EXPECT_NEAR(measuredGain(cfg, setting.bandwidth_hz / 10.0), 1.0, 0.02) << "DLPF_CFG " << cfg;
}

INSTANTIATE_TEST_SUITE_P(Settings, DlpfResponse, ::testing::Values(0, 2, 3, 4, 5, 6));

TEST(MockMpu6050Dlpf, ReservedSettingSevenBypassesTheFilter) {
  // 2 kHz at 8 kHz ticks passes DLPF_CFG 7 at full amplitude; DLPF_CFG 0 (256 Hz) would
  // attenuate it strongly.
  const double gain = measuredGain(7, 2000.0);
  EXPECT_NEAR(gain, 1.0, 1e-3);
}

}  // namespace
}  // namespace gyrod::driver::test
