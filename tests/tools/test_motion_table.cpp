// The table of docs/motion.md (bench/compare_streams, scripts/motion-table.sh), on shorter
// records: the calibration made by the workflow itself (gyroctl simulate --warm-up of the
// table's sensor, gyroctl analyze --write-model), then processing::compareStreams. The rate
// stream's figures must meet issue 11's goals, and the paper's Kalman stream must show what the
// table is about (a 1 Hz rotation shrunk to about a fifth, a warm-up's offset halved, not removed).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "formats/calibration.hpp"
#include "formats/model_toml.hpp"
#include "processing/motion/stream_comparison.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::processing;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

constexpr std::size_t kRaw = 0, kKalman = 2, kRate = 3;

StreamComparison tableFromTheWorkflow(const ScratchDir& d, std::uint64_t seed) {
  const auto sensor = d.write("true.toml", gyrod::recording::modelToToml(comparisonSensor()));
  const auto calibration = (d.path() / "calibration.csv").string();
  const auto model = (d.path() / "sensor.toml").string();
  auto r = runGyroctl("simulate --model " + sensor.string() + " --warm-up 15,300 --duration 1200 --seed " +
                          std::to_string(seed + 1000) + " -o " + calibration,
                      d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  r = runGyroctl("analyze " + calibration + " --write-model " + model, d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  StreamComparisonSetup setup;
  setup.sensor = comparisonSensor();
  setup.rate = gyrod::recording::rateEstimatorParameters(gyrod::recording::readSensorModelToml(model));
  setup.rate.rate_hz = setup.sensor.rate_hz;
  setup.seed = seed;
  setup.warm_up_minutes = 20;  // 25 → 39.7 °C with τ = 5 min
  setup.identification_still_s = 300.0;
  setup.rest_s = 120.0;
  return compareStreams(setup);
}

}  // namespace

TEST(MotionTable, RateRowMeetsTheIssuesGoalsAndTheKalmanRowShowsWhy) {
  ScratchDir d;
  const StreamComparison c = tableFromTheWorkflow(d, 2);
  const StreamFigures& rate = c.streams[kRate];
  EXPECT_EQ(kCompareStepSamples[2], 3u);
  EXPECT_NEAR(rate.step_value_dps[2], kCompareStepDps, 0.02 * kCompareStepDps);  // 3rd sample within 2 %
  EXPECT_EQ(kCompareFrequenciesHz[1], 1.0);
  EXPECT_NEAR(rate.gain[1], 1.0, 0.02);  // 1 Hz within 2 % and 5°
  EXPECT_LE(std::fabs(rate.phase_deg[1]), 5.0);
  EXPECT_LE(std::fabs(rate.turns_angle_error_percent), 0.5);
  EXPECT_LE(c.rate_bias_error_dps, 0.02);
  EXPECT_LE(10.0 * c.rate_bias_error_dps, c.startup_bias_error_dps);
  EXPECT_LE(std::fabs(rate.warm_up_offset_dps), 0.02);
  // raw (minus a start-up bias) follows the motion too but keeps the warm-up's offset.
  EXPECT_NEAR(c.streams[kRaw].gain[1], 1.0, 0.02);
  EXPECT_GE(std::fabs(c.streams[kRaw].warm_up_offset_dps), 0.2);
  // The paper's Kalman stream: a low-pass of DC gain ≈ 0.45 (docs/motion.md).
  EXPECT_LT(c.streams[kKalman].gain[1], 0.3);
  EXPECT_LT(c.streams[kKalman].turns_angle_error_percent, -40.0);
  EXPECT_FALSE(c.streams[kKalman].step_t90_s.has_value());
  EXPECT_LT(c.streams[kKalman].variance_ratio, 0.05);  // what the paper measures at rest
  EXPECT_DOUBLE_EQ(c.streams[kRaw].variance_ratio, 1.0);
}
