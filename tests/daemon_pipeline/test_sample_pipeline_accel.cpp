// The pipeline hands each sample's accel to the still detector: a slow tilt that the gyro
// cannot tell from bias is "moving" with accel, and without accel (NaN, the default argument)
// the verdicts are those of the gyro alone.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "daemon/sample_pipeline.hpp"

using namespace gyrod::daemon;
using namespace gyrod::processing;

namespace {

PipelineSettings settingsWithModel() {
  PipelineSettings p;
  p.rate_hz = 50.0;
  p.allan_window_samples = 2048;
  RateEstimatorParameters m;
  m.rate_hz = 50.0;
  for (AxisBiasModel& axis : m.axes) {
    axis.terms.arw_deg_per_sqrt_h = 0.95;  // the paper's: 0.0224 °/s per 0.5 s window
    axis.terms.bias_instability_deg_per_h = 0.6;
    axis.bias_std_dps = 0.01;
  }
  p.rate_model = m;
  return p;
}

struct Counts {
  std::size_t with_accel = 0, without = 0, nan_accel = 0;
};

// 10 min at 50 Hz of white gyro noise with a tilt of `omega_dps` about x that the gyro shows
// as a constant offset; the accel sees gravity turn, with 2 mg of noise.
Counts stillSamples(double omega_dps) {
  const PipelineSettings p = settingsWithModel();
  SamplePipeline with_accel(p), without(p), nan_accel(p);
  std::mt19937_64 rng(17);
  std::normal_distribution<double> gyro_noise(0.0, 0.95 / 60.0 * std::sqrt(50.0));
  std::normal_distribution<double> accel_noise(0.0, 0.002);
  Counts c;
  for (std::uint64_t i = 0; i < 30000; ++i) {
    const double t = static_cast<double>(i) / 50.0;
    const Vec3 raw{omega_dps + gyro_noise(rng), gyro_noise(rng), gyro_noise(rng)};
    const double angle = omega_dps * t * std::numbers::pi / 180.0;
    const Vec3 accel{accel_noise(rng), std::sin(angle) + accel_noise(rng), std::cos(angle) + accel_noise(rng)};
    const bool a = with_accel.process(i, t, raw, 25.0, accel).still.value_or(false);
    const bool b = without.process(i, t, raw, 25.0).still.value_or(false);
    const bool n = nan_accel.process(i, t, raw, 25.0, kNoAccel).still.value_or(false);
    if (t < 10.0) continue;
    c.with_accel += a ? 1 : 0;
    c.without += b ? 1 : 0;
    c.nan_accel += n ? 1 : 0;
    EXPECT_EQ(n, b) << "sample " << i;
  }
  return c;
}

}  // namespace

TEST(SamplePipelineAccel, ASlowTiltIsNotStillWithAccelAndIsWithout) {
  const Counts tilt = stillSamples(0.04);
  std::printf("0.04 deg/s tilt: still samples without accel %zu, with accel %zu of 29500\n", tilt.without,
              tilt.with_accel);
  EXPECT_GT(tilt.without, 20000u);
  EXPECT_LT(tilt.with_accel, 300u);
  const Counts rest = stillSamples(0.0);
  std::printf("at rest: still samples without accel %zu, with accel %zu of 29500\n", rest.without, rest.with_accel);
  EXPECT_GT(rest.with_accel, 27000u);
}
