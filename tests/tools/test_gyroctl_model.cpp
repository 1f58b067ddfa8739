// gyroctl model (docs/calibration-state.md): a learned calibration state folded into a sensor
// model gives, at every temperature, the bias gyrod's rate stream subtracted with the model and
// the state; the command refuses a state of another bias model, and --write-model without a
// state.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "formats/calibration.hpp"
#include "formats/calibration_state.hpp"
#include "formats/model_toml.hpp"
#include "processing/motion/rate_estimator.hpp"
#include "tools/run_command.hpp"

using namespace gyrod;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

const char* const kModel =
    "rate_hz = 50\n"
    "[x]\narw_deg_per_sqrt_h = 0.95\nbias_dps = 1.2\n"
    "[x.calibration]\nbias_std_dps = 0.05\ntemperature_coefficient_dps_per_c = 0.01\n"
    "temperature_coefficient_std_dps_per_c = 0.02\ntemperature_reference_c = 30.0\n"
    "[y]\narw_deg_per_sqrt_h = 0.95\nbias_dps = -0.4\n"
    "[z]\narw_deg_per_sqrt_h = 0.95\nbias_dps = 0.25\n";

processing::LearnedResidual learnedResidual() {
  processing::LearnedResidual r;
  r.temperature_origin_c = 27.5;
  r.temperature_c = 41.0;
  r.still_temperature_min_c = 27.6;
  r.still_temperature_max_c = 41.2;
  r.still_samples = 12345;
  r.axes[0] = {0.03, 0.004, 4e-6, -1e-7, 9e-9};
  r.axes[1] = {-0.02, -0.011, 5e-6, 2e-7, 1.6e-8};
  r.axes[2] = {0.0, 0.0, 1e-6, 0.0, 1e-9};
  return r;
}

}  // namespace

TEST(GyroctlModel, TheFoldedModelHasTheBiasTheRateStreamSubtractedAtEveryTemperature) {
  const recording::SensorModel model = recording::parseSensorModelToml(kModel, "m.toml");
  const processing::LearnedResidual r = learnedResidual();
  const processing::RateEstimatorParameters before = recording::rateEstimatorParameters(model);
  const processing::RateEstimatorParameters after =
      recording::rateEstimatorParameters(recording::withLearnedResidual(model, r));
  for (std::size_t a = 0; a < 3; ++a)
    for (double t : {10.0, 25.0, 30.0, 41.0, 60.0}) {
      const auto& x = r.axes[a];
      const double residual = x.offset_dps + x.slope_dps_per_c * (t - r.temperature_origin_c);
      EXPECT_NEAR(after.axes[a].biasAt(t, 1e9), before.axes[a].biasAt(t, 1e9) + residual, 1e-12)
          << "axis " << a << " at " << t << " C";
    }
  // The uncertainty at the reference temperature is the residual's there; the coefficient's the slope's.
  const double d = 30.0 - 27.5;
  const auto& x = r.axes[0];
  EXPECT_NEAR(after.axes[0].bias_std_dps, std::sqrt(x.var_offset + 2 * d * x.cov_offset_slope + d * d * x.var_slope),
              1e-15);
  EXPECT_NEAR(after.axes[0].temperature_coefficient_std_dps_per_c, std::sqrt(x.var_slope), 1e-15);
  // An axis without [y.calibration] gets one, at the rate stream's default reference, 25 °C.
  EXPECT_EQ(after.axes[1].temperature_reference_c, 25.0);
  EXPECT_NEAR(after.axes[1].temperature_coefficient_dps_per_c, -0.011, 1e-15);
}

TEST(GyroctlModel, ShowsWritesAndRefusesWhatItCannotUse) {
  ScratchDir d;
  const auto model_path = d.write("model.toml", kModel);
  const recording::SensorModel model = recording::parseSensorModelToml(kModel, "m.toml");
  formats::CalibrationState state;
  state.model = formats::biasModelFingerprint(recording::rateEstimatorParameters(model));
  state.rate_hz = 50.0;
  state.saved_unix_s = 1795886338.0;
  state.data_time_s = 7200.0;
  state.residual = learnedResidual();
  const auto state_path = d.write("calibration.toml", formats::calibrationStateToToml(state));
  const auto out = d.path() / "combined.toml";

  const auto shown = runGyroctl("model " + model_path.string(), d.path());
  ASSERT_EQ(shown.exit_status, 0) << shown.err;
  EXPECT_NE(shown.out.find("x     1.2        +- 0.05"), std::string::npos) << shown.out;

  const auto written = runGyroctl(
      "model " + model_path.string() + " --state " + state_path.string() + " --write-model " + out.string(), d.path());
  ASSERT_EQ(written.exit_status, 0) << written.err;
  EXPECT_NE(written.out.find("12345 still samples at 27.6-41.2 C"), std::string::npos) << written.out;
  const recording::SensorModel back = recording::readSensorModelToml(out.string());
  const recording::SensorModel expected = recording::withLearnedResidual(model, state.residual);
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_EQ(back.simulation.axes[a].bias_dps, expected.simulation.axes[a].bias_dps) << a;
    EXPECT_EQ(back.calibration[a]->temperature_coefficient_dps_per_c,
              expected.calibration[a]->temperature_coefficient_dps_per_c)
        << a;
  }

  // The folded model is another bias model: the same state no longer belongs to it.
  const auto foreign = runGyroctl("model " + out.string() + " --state " + state_path.string(), d.path());
  EXPECT_EQ(foreign.exit_status, 65);
  EXPECT_NE(foreign.err.find("learned with another bias model"), std::string::npos) << foreign.err;
  const auto no_state = runGyroctl("model " + model_path.string() + " --write-model " + out.string(), d.path());
  EXPECT_EQ(no_state.exit_status, 64);
  EXPECT_NE(no_state.err.find("--write-model needs --state"), std::string::npos) << no_state.err;
  const auto broken = d.write("broken.toml", "format = \"gyrod-calibration-state\"\nversion = 7\n");
  const auto refused = runGyroctl("model " + model_path.string() + " --state " + broken.string(), d.path());
  EXPECT_EQ(refused.exit_status, 65);
  EXPECT_NE(refused.err.find(broken.string() + ":2: key 'version'"), std::string::npos) << refused.err;
}
