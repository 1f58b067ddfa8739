// A spectral line that one fixed sinusoid cannot take out (its phase jumps part-way, as when
// a vibration source restarts or samples go missing) is one line, not two: the check names a
// single `sinusoid` whose amplitude is the line's rms amplitude, and says why it needed two
// components. The data are white noise from the simulator plus the line, from a seed.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "processing/model_check/model_check.hpp"
#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod::processing;

namespace {

std::vector<double> whiteNoise(std::size_t n, double rate_hz, double arw_deg_per_sqrt_h, std::uint64_t seed) {
  SimulationModel m;
  m.rate_hz = rate_hz;
  m.axes[0].terms.arw_deg_per_sqrt_h = arw_deg_per_sqrt_h;
  m.axes[0].terms.bias_instability_deg_per_h = 5.0;
  NoiseSimulator sim(m, static_cast<double>(n) / rate_hz, seed);
  std::vector<double> x(n);
  for (double& v : x) v = sim.next().rate_dps[0];
  return x;
}

TEST(ModelCheckLines, ALineWhosePhaseJumpsIsOneSinusoid) {
  const double rate = 50.0, freq = 7.31, amp = 0.03;
  const std::size_t n = 15000;  // 5 min at 50 Hz
  for (std::uint64_t seed : {3u, 4u}) {
    std::vector<double> x = whiteNoise(n, rate, 0.5, seed);  // white sd 0.059 deg/s
    for (std::size_t i = 0; i < n; ++i) {
      const double phase = i < 2 * n / 5 ? 0.3 : 0.3 + std::numbers::pi / 2.0;
      x[i] += amp * std::sin(2.0 * std::numbers::pi * freq * static_cast<double>(i) / rate + phase);
    }
    ModelCheckOptions o;
    o.replicas = 40;  // the product default: with 16 the thresholds are too noisy for a clean "nothing else" check
    o.seed = seed;
    const AxisModelCheck r = checkAxisModel({x, rate, {}, {}, {}}, o);
    std::size_t lines = 0;
    const DetectedEffect* line = nullptr;
    for (const DetectedEffect& e : r.effects)
      if (e.effect == ModelEffect::Sinusoid) {
        ++lines;
        line = &e;
      }
    ASSERT_EQ(lines, 1u) << "seed " << seed;
    EXPECT_NEAR(line->freq_hz, freq, 2.0 * rate / static_cast<double>(n)) << "seed " << seed;
    // The line's power is amp²/2 whatever its phase: the components' rms sum carries it
    // (within what the noise and the split between components leave: 15 %).
    EXPECT_NEAR(line->amp_dps, amp, 0.15 * amp) << "seed " << seed;
    EXPECT_FALSE(line->evidence.further_components.empty()) << "seed " << seed;  // "a second component"
  }
}

TEST(ModelCheckLines, AFixedSinusoidStaysOneComponent) {
  const double rate = 50.0, freq = 3.77, amp = 0.03;
  const std::size_t n = 15000;  // 5 min at 50 Hz
  std::vector<double> x = whiteNoise(n, rate, 0.5, 9);
  for (std::size_t i = 0; i < n; ++i)
    x[i] += amp * std::sin(2.0 * std::numbers::pi * freq * static_cast<double>(i) / rate + 1.0);
  ModelCheckOptions o;
  o.replicas = 40;  // the product default: with 16 the thresholds are too noisy for a clean "nothing else" check
  const AxisModelCheck r = checkAxisModel({x, rate, {}, {}, {}}, o);
  std::string all;
  for (const DetectedEffect& e : r.effects) all += std::string(modelEffectName(e.effect)) + "\n";
  ASSERT_EQ(r.effects.size(), 1u) << all;
  EXPECT_EQ(r.effects[0].effect, ModelEffect::Sinusoid);
  EXPECT_TRUE(r.effects[0].evidence.further_components.empty());  // no "second component"
  EXPECT_NEAR(r.effects[0].amp_dps, amp, 0.1 * amp);
}

}  // namespace
