// The start-up still window's motion check: noise at rest passes (white, and correlated as
// the chip's low-pass makes it), a turn, a sway or a step fails on the axis that moved, and a
// rotation constant over the whole window passes, as documented (it is a bias to the gyro).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <span>
#include <stdexcept>
#include <vector>

#include "processing/motion/still_period_check.hpp"
#include "processing/simulation/sensor_model.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kStillRateHz = 50.0;
constexpr std::size_t kSamples = 500;  // 10 s, bias.still_seconds' default
// The paper's angle random walk, 0.95 °/√h, as the standard deviation of a 50 Hz sample.
const double kSigmaDps = 0.95 / 60.0 * std::sqrt(kStillRateHz);

struct Window {
  std::array<std::vector<double>, 3> axes;
  std::array<std::span<const double>, 3> spans() const { return {axes[0], axes[1], axes[2]}; }
};

// Noise at rest around a bias, AR(1) with coefficient phi (0: white), from a seed.
Window atRest(unsigned seed, double phi = 0.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, kSigmaDps * std::sqrt(1.0 - phi * phi));
  Window w;
  const std::array<double, 3> bias = {-3.34, 1.09, -0.5};
  for (std::size_t a = 0; a < 3; ++a) {
    double x = 0.0;
    for (std::size_t k = 0; k < kSamples; ++k) {
      x = phi * x + noise(rng);
      w.axes[a].push_back(bias[a] + x);
    }
  }
  return w;
}

}  // namespace

TEST(StillPeriodCheck, NoiseAtRestPassesOverManySeeds) {
  int moved = 0;
  for (unsigned seed = 1; seed <= 200; ++seed) {
    moved += checkStillPeriod(atRest(seed).spans(), kStillRateHz).moved ? 1 : 0;
    moved += checkStillPeriod(atRest(1000 + seed, 0.5).spans(), kStillRateHz).moved ? 1 : 0;  // low-pass correlated
  }
  EXPECT_EQ(moved, 0);
}

TEST(StillPeriodCheck, ATurnOfOneDegreePerSecondForOneSecondIsMotionOnItsAxis) {
  Window w = atRest(7);
  for (std::size_t k = 250; k < 300; ++k) w.axes[2][k] += 1.0;  // 1 °/s about z from 5 s to 6 s
  const StillPeriodVerdict v = checkStillPeriod(w.spans(), kStillRateHz);
  EXPECT_TRUE(v.moved);
  EXPECT_EQ(v.axis, 2u);
  EXPECT_GT(v.adev_dps, 2.0 * v.allowed_dps);  // 2.7 times with this seed
}

TEST(StillPeriodCheck, ASwayAndAStepAreMotion) {
  Window sway = atRest(8);
  for (std::size_t k = 0; k < kSamples; ++k)
    sway.axes[0][k] += 0.5 * std::sin(2.0 * M_PI * 0.5 * static_cast<double>(k) / kStillRateHz);  // 0.5 Hz, 0.5 °/s
  EXPECT_TRUE(checkStillPeriod(sway.spans(), kStillRateHz).moved);
  EXPECT_EQ(checkStillPeriod(sway.spans(), kStillRateHz).axis, 0u);

  Window step = atRest(9);
  for (std::size_t k = 400; k < kSamples; ++k) step.axes[1][k] += 1.0;  // the board starts turning at 8 s
  EXPECT_TRUE(checkStillPeriod(step.spans(), kStillRateHz).moved);
  EXPECT_EQ(checkStillPeriod(step.spans(), kStillRateHz).axis, 1u);
}

TEST(StillPeriodCheck, ARotationConstantOverTheWholeWindowLooksLikeABias) {
  Window w = atRest(10);
  for (double& v : w.axes[2]) v += 30.0;
  EXPECT_FALSE(checkStillPeriod(w.spans(), kStillRateHz).moved);
}

TEST(StillPeriodCheck, RefusesBadInputAndSaysNothingOnTooFewSamples) {
  Window w = atRest(11);
  EXPECT_THROW(checkStillPeriod(w.spans(), 0.0), std::invalid_argument);
  std::array<std::span<const double>, 3> uneven = {w.axes[0], w.axes[1], std::span<const double>(w.axes[2]).first(10)};
  EXPECT_THROW(checkStillPeriod(uneven, kStillRateHz), std::invalid_argument);
  std::array<std::span<const double>, 3> few = {std::span<const double>(w.axes[0]).first(5),
                                                std::span<const double>(w.axes[1]).first(5),
                                                std::span<const double>(w.axes[2]).first(5)};
  EXPECT_FALSE(checkStillPeriod(few, kStillRateHz).moved);
}

namespace {

// A still (or turning) window as the chip makes it: white noise at the DLPF's internal rate,
// the DLPF (the simulator's model), decimated to `rate_hz`; 10 s. The paper's angle random
// walk; `turn_dps` for one second in the middle of the window on axis x.
Window throughTheChip(int cfg, double rate_hz, unsigned seed, double turn_dps = 0.0) {
  const DlpfSetting& dlpf = dlpfSetting(cfg);
  const auto divider = static_cast<std::size_t>(std::lround(dlpf.internal_rate_hz / rate_hz));
  const auto samples = static_cast<std::size_t>(10.0 * rate_hz);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.95 / 60.0 * std::sqrt(dlpf.internal_rate_hz));
  Window w;
  for (std::size_t a = 0; a < 3; ++a) {
    DigitalLowPassFilter filter(cfg);
    for (std::size_t k = 0; k < samples * divider; ++k) {
      const double t = static_cast<double>(k) / dlpf.internal_rate_hz;
      const double turn = (a == 0 && t >= 4.5 && t < 5.5) ? turn_dps : 0.0;
      const double y = filter.update(turn + noise(rng));
      if (k % divider == divider - 1) w.axes[a].push_back(y);
    }
  }
  return w;
}

}  // namespace

// Every DLPF setting at every rate from its internal rate down to 50 Hz: the chip's own noise at
// rest passes (the low-pass makes neighbouring samples alike, most at 8 kHz with DLPF 0 and at
// 1 kHz with DLPF 6), and a turn of 1 °/s for 1 s is still seen (3 °/s where the bandwidth is
// more than 4 times the rate).
TEST(StillPeriodCheck, TheChipAtRestPassesAtEveryRateAndDlpfAndATurnIsSeen) {
  for (int cfg = 0; cfg <= 6; ++cfg) {
    const double internal = dlpfSetting(cfg).internal_rate_hz;
    for (const double rate : {internal, 1000.0, 500.0, 200.0, 100.0, 50.0}) {
      if (rate > internal || (rate == 1000.0 && internal == 1000.0 && rate != internal)) continue;
      SCOPED_TRACE("DLPF_CFG " + std::to_string(cfg) + " at " + std::to_string(rate) + " Hz");
      StillPeriodCheckParameters p;
      p.low_pass_bandwidth_hz = dlpfSetting(cfg).bandwidth_hz;
      int moved = 0;
      for (unsigned seed = 0; seed < 8; ++seed)
        moved +=
            checkStillPeriod(throughTheChip(cfg, rate, 100 * static_cast<unsigned>(cfg) + seed).spans(), rate, p).moved
                ? 1
                : 0;
      EXPECT_EQ(moved, 0);
      // Where the bandwidth is far above the rate (256 Hz at 50 Hz), the chip's noise folds into
      // the samples' band: 5 times the noise of DLPF 3 at 50 Hz, and a larger turn is needed.
      const double turn_dps = dlpfSetting(cfg).bandwidth_hz > 4.0 * rate ? 3.0 : 1.0;
      const StillPeriodVerdict turn = checkStillPeriod(throughTheChip(cfg, rate, 7, turn_dps).spans(), rate, p);
      EXPECT_TRUE(turn.moved) << turn_dps << " deg/s";
      EXPECT_EQ(turn.axis, 0u);
    }
  }
}

TEST(StillPeriodCheck, LowPassCorrelationIsSixTimeConstantsOfEachSection) {
  EXPECT_EQ(lowPassCorrelationSeconds(0.0), 0.0);
  EXPECT_NEAR(lowPassCorrelationSeconds(256.0) * 8000.0, 19.2, 0.1);  // m_c = 20 at 8 kHz, DLPF 0
  EXPECT_NEAR(lowPassCorrelationSeconds(42.0) * 50.0, 0.73, 0.01);    // m_c = 1 at 50 Hz, DLPF 3
}
