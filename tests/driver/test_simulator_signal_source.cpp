// The noise simulator as the mock chip's input: what comes out of the chip's output
// registers carries the model's bias and angle random walk (with the DLPF's aliasing
// factor the simulator documents), quantised at FS_SEL 0.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include "driver/mock/simulator_signal_source.hpp"
#include "mock_rig.hpp"
#include "processing/allan/allan.hpp"
#include "processing/simulation/sensor_model.hpp"
#include "welch_psd.hpp"

using namespace gyrod::driver;
using namespace gyrod::driver::test;
using gyrod::processing::SimulationModel;

TEST(SimulatorSignalSource, ChipOutputCarriesTheModelsBiasAndArw) {
  SimulationModel model;
  model.axes[0].terms.arw_deg_per_sqrt_h = 0.9;
  model.axes[0].bias_dps = 1.25;
  model.axes[1].bias_dps = -0.5;
  SimulatorSignalSource source(model, 4, 42, 3600.0);
  EXPECT_DOUBLE_EQ(source.expectedTickRateHz(), 1000.0);
  Rig rig(source);
  std::vector<double> x, y;
  rig.mock.setSampleObserver([&](const SampleRecord& s) {
    x.push_back(s.gyro[0] / 131.0);
    y.push_back(s.gyro[1] / 131.0);
  });
  rig.wake(4, 19);  // DLPF_CFG 4, 1 kHz / 20 = 50 Hz
  rig.advance(600 * kNsPerSecond);
  ASSERT_NEAR(static_cast<double>(x.size()), 30000.0, 2.0);
  EXPECT_EQ(rig.mock.counters().source_rate_mismatch_ticks, 0u);

  double mean_x = 0.0, mean_y = 0.0;
  for (double v : x) mean_x += v;
  for (double v : y) mean_y += v;
  mean_x /= static_cast<double>(x.size());
  mean_y /= static_cast<double>(y.size());
  // N = 0.9 °/√h → 0.015 °/√s; σ of a 600 s mean = N/√600 ≈ 6e-4 °/s.
  EXPECT_NEAR(mean_x, 1.25, 5 * 0.015 / std::sqrt(600.0));
  EXPECT_NEAR(mean_y, -0.5, 1.0 / 131.0);  // y has no noise: the bias, quantised

  // ARW at τ = 1 s: σ(τ) = F·N/√τ with F the decimation aliasing factor (docs/simulator.md).
  const double factor = gyrod::processing::aliasedWhiteNoiseFactor(4, 50.0);
  const double expected = factor * 0.015;
  const double measured = std::sqrt(gyrod::processing::overlappingAllanVariance(x, 50));
  // ~600 independent 1 s intervals: the relative standard error of σ is about 1/√(2·600/1.5).
  EXPECT_NEAR(measured, expected, 5 * expected / std::sqrt(800.0));
}

TEST(SimulatorSignalSource, AWarmUpMovesTheBiasThroughTheTemperatureCoupling) {
  // No noise: the chip's output is the bias, the coupling k·(T(t) − 25 °C) and the quantisation.
  SimulationModel model;
  model.axes[0].bias_dps = 1.0;
  model.axes[0].extra.temperature_coefficient_dps_per_c = 0.03;
  model.temperature = gyrod::processing::withWarmUp(model.temperature, {15.0, 60.0});  // 25 → 40 °C
  SimulatorSignalSource source(model, 4, 42, 3600.0);
  Rig rig(source);
  std::vector<double> x, y, temperature;
  rig.mock.setSampleObserver([&](const SampleRecord& s) {
    x.push_back(s.gyro[0] / 131.0);
    y.push_back(s.gyro[1] / 131.0);
    temperature.push_back(s.temperature / 340.0 + 36.53);
  });
  rig.wake(4, 19);
  rig.advance(300 * kNsPerSecond);
  ASSERT_GT(x.size(), 14000u);
  for (std::size_t i = 0; i < x.size(); i += 10) {
    // The bias follows the temperature the chip reports: half an LSB of each quantisation, and
    // the DLPF's 10 ms lag on a rise of at most 0.0075 °/s per s.
    ASSERT_NEAR(x[i], 1.0 + 0.03 * (temperature[i] - 25.0), 0.5 / 131.0 + 0.03 * 0.5 / 340.0 + 1e-4) << "sample " << i;
    ASSERT_EQ(y[i], 0.0);  // an axis without a coupling stays at its bias
  }
  EXPECT_NEAR(temperature.front(), 25.0, 0.5);
  EXPECT_NEAR(temperature.back(), 25.0 + 15.0 * (1.0 - std::exp(-5.0)), 0.05);
  EXPECT_NEAR(x.back(), 1.0 + 0.03 * 15.0 * (1.0 - std::exp(-5.0)), 1.0 / 131.0);
}

TEST(SimulatorSignalSource, ANarrowbandLineOfTheModelPlaysThroughTheChip) {
  // A model with a line on y: the chip's gy spectrum peaks at the line's centre (DLPF_CFG 3,
  // 44 Hz bandwidth, passes 12 Hz nearly whole), and gx is the very stream of the model
  // without the line (the line's random numbers are the extras' own).
  constexpr double kMockLineCentre = 12.0, kMockLineWidth = 0.3, kMockLineRms = 0.1;
  SimulationModel model;
  for (auto& axis : model.axes) axis.terms.arw_deg_per_sqrt_h = 0.3;
  SimulationModel with_line = model;
  with_line.axes[1].extra.narrowband_lines = {{kMockLineCentre, kMockLineWidth, kMockLineRms}};
  const auto chipOutput = [](const SimulationModel& m, std::vector<double>& x, std::vector<double>& y) {
    SimulatorSignalSource source(m, 3, 17, 1200.0);
    Rig rig(source);
    rig.mock.setSampleObserver([&](const SampleRecord& s) {
      x.push_back(s.gyro[0] / 131.0);
      y.push_back(s.gyro[1] / 131.0);
    });
    rig.wake(3, 9);  // 1 kHz / 10 = 100 Hz
    rig.advance(600 * kNsPerSecond);
  };
  std::vector<double> x_line, y_line, x_plain, y_plain;
  chipOutput(with_line, x_line, y_line);
  chipOutput(model, x_plain, y_plain);
  ASSERT_NEAR(static_cast<double>(y_line.size()), 60000.0, 2.0);
  EXPECT_EQ(x_line, x_plain);

  // 2048-sample segments (0.049 Hz bins), 57 of them: the midpoint of the half-power points
  // scatters by ~0.015 Hz.
  const auto spectrum = gyrod::test::welchPsd(y_line, 100.0, 2048);
  const auto peak = gyrod::test::spectralPeakNear(spectrum, kMockLineCentre, 2.0);
  EXPECT_NEAR(peak.centreHz(), kMockLineCentre, 0.05);
  const auto plain = gyrod::test::welchPsd(y_plain, 100.0, 2048);
  const auto bin = static_cast<std::size_t>(kMockLineCentre / plain.bin_hz + 0.5);
  EXPECT_GT(peak.level, 20.0 * plain.psd[bin]);
  // Its power: the variance added to gy against rms²·|H(12 Hz)|² of the DLPF (the line is
  // narrow against the filter), within 4 sd of the sample variance (~4 %: 600 s of a line whose
  // correlation time is ~1 s).
  const double gain = std::norm(gyrod::processing::DigitalLowPassFilter(3).frequencyResponse(kMockLineCentre));
  const auto variance = [](const std::vector<double>& v) {
    double mean = 0.0, sum = 0.0;
    for (double e : v) mean += e;
    mean /= static_cast<double>(v.size());
    for (double e : v) sum += (e - mean) * (e - mean);
    return sum / static_cast<double>(v.size());
  };
  const double added = variance(y_line) - variance(y_plain);
  EXPECT_NEAR(added / (kMockLineRms * kMockLineRms * gain), 1.0, 0.17);
  RecordProperty("line_centre_hz", std::to_string(peak.centreHz()));
  RecordProperty("line_power_over_expected", std::to_string(added / (kMockLineRms * kMockLineRms * gain)));
}
