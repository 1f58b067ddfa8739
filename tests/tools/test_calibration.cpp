// The one sensor model file as a calibration (docs/calibration.md): its tables read and
// written back to the same numbers, old files read as before, and the workflow end to end on
// simulated records from seeds: a cold-start still record → `gyroctl analyze --write-model`
// recovers the hidden temperature coefficient and bias within 3 of its stated standard errors,
// and `gyroctl filter --model` on a motion record gives `<axis>_rate` columns that are
// processing::RateEstimator's output bit for bit and turn the hidden turns to within 0.5 %.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "formats/calibration.hpp"
#include "formats/model_toml.hpp"
#include "processing/motion/rate_estimator.hpp"
#include "processing/simulation/motion_profile.hpp"
#include "processing/simulation/noise_simulator.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::recording;
using namespace gyrod::processing;
using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

constexpr std::array<double, 3> kCoefficient = {0.03, -0.02, 0.015};  // °/s per °C, at 25 °C
constexpr std::array<double, 3> kBias = {1.367, -0.4, 0.25};          // °/s at 25 °C

// The paper's X axis on every axis, DLPF 4, ±250 °/s, a temperature coupling per axis.
SimulationModel sensor(double start_c, double final_c, double time_constant_s) {
  SimulationModel m;
  m.rate_hz = 50.0;
  m.dlpf_cfg = 4;
  m.fs_sel = 0;
  for (std::size_t a = 0; a < 3; ++a) {
    m.axes[a].terms = {0.1663, 0.95164, 0.60565, 0.07759, 0.43223};
    m.axes[a].bias_dps = kBias[a];
    m.axes[a].extra.temperature_coefficient_dps_per_c = kCoefficient[a];
    m.axes[a].extra.temperature_reference_c = 25.0;
  }
  m.temperature = {start_c, final_c, time_constant_s, 0.02};
  return m;
}

void appendNumber(std::string& out, double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  out += buf;
}

// The record as gyrod writes it (t,gx,gy,gz,temp; 17 digits, so it reads back bit for bit).
std::string csvOf(const std::vector<SimulatedSample>& samples) {
  std::string out = "t,gx,gy,gz,temp\n";
  for (const SimulatedSample& s : samples) {
    appendNumber(out, s.t_s);
    for (double r : s.rate_dps) out += ',', appendNumber(out, r);
    out += ',';
    appendNumber(out, s.temperature_c);
    out += '\n';
  }
  return out;
}

std::vector<SimulatedSample> simulate(const SimulationModel& m, double seconds, std::uint64_t seed,
                                      MotionProfile motion = {}) {
  NoiseSimulator sim(m, seconds, seed, std::move(motion));
  std::vector<SimulatedSample> out;
  for (std::size_t i = 0; i < sim.sampleCount(); ++i) out.push_back(sim.next());
  return out;
}

std::vector<std::vector<std::string>> csvFields(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::stringstream ss(text);
  std::string line;
  while (std::getline(ss, line)) {
    std::vector<std::string> row;
    std::stringstream ls(line);
    std::string field;
    while (std::getline(ls, field, ',')) row.push_back(field);
    rows.push_back(row);
  }
  return rows;
}

SensorModel everyTable() {
  SensorModel m;
  m.simulation = sensor(24.0, 38.5, 900.0);
  m.simulation.axes[0].ar = {{-0.2855}, 1e-4};
  m.calibration[0] = AxisCalibration{4.2e-4, 0.0312, 1.3e-4, 31.25, 0.051, 0.004, 240.5};
  m.calibration[2] = AxisCalibration{5e-4, -0.011, 2e-4, 30.0, 0.0, 0.0, 0.0};
  m.kalman[1] = ScalarKalmanParameters{0.95, 1.2e-3, 1.8e-2, 0.0, {}};
  m.filter = FilterModel{};
  m.filter->mean_window = 30;
  m.filter->mean_threshold_dps = 0.25;
  m.filter->still = {50, 3.5, 1e-4};
  m.filter->bias_instability_horizon_s = 200.0;
  m.filter->temperature_smoothing_s = 0.0;
  m.filter->low_pass_hz = 5.0;
  return m;
}

std::string errorOf(const std::string& text) {
  try {
    parseSensorModelToml(text, "model.toml");
  } catch (const RecordingError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SensorModelToml, WrittenAndReadBackToTheSameNumbers) {
  const SensorModel m = everyTable();
  const std::string text = sensorModelToToml(m);
  const SensorModel back = parseSensorModelToml(text, "model.toml");
  EXPECT_EQ(sensorModelToToml(back), text);
  for (std::size_t a = 0; a < 3; ++a) {
    ASSERT_EQ(back.calibration[a].has_value(), m.calibration[a].has_value()) << a;
    ASSERT_EQ(back.kalman[a].has_value(), m.kalman[a].has_value()) << a;
    EXPECT_EQ(back.simulation.axes[a].bias_dps, m.simulation.axes[a].bias_dps);
    EXPECT_EQ(back.simulation.axes[a].extra.temperature_coefficient_dps_per_c,
              m.simulation.axes[a].extra.temperature_coefficient_dps_per_c);
  }
  const AxisCalibration& c = *back.calibration[0];
  EXPECT_EQ(c.bias_std_dps, 4.2e-4);
  EXPECT_EQ(c.temperature_coefficient_dps_per_c, 0.0312);
  EXPECT_EQ(c.temperature_coefficient_std_dps_per_c, 1.3e-4);
  EXPECT_EQ(c.temperature_reference_c, 31.25);
  EXPECT_EQ(c.warm_up_amplitude_dps, 0.051);
  EXPECT_EQ(c.warm_up_amplitude_std_dps, 0.004);
  EXPECT_EQ(c.warm_up_time_constant_s, 240.5);
  EXPECT_EQ(back.calibration[2]->temperature_coefficient_dps_per_c, -0.011);
  EXPECT_EQ(back.kalman[1]->a, 0.95);
  EXPECT_EQ(back.kalman[1]->q, 1.2e-3);
  EXPECT_EQ(back.kalman[1]->r, 1.8e-2);
  ASSERT_TRUE(back.filter);
  EXPECT_EQ(back.filter->mean_window, 30u);
  EXPECT_EQ(back.filter->mean_threshold_dps, 0.25);
  EXPECT_EQ(back.filter->still.window_samples, 50u);
  EXPECT_EQ(back.filter->still.mean_threshold_sigmas, 3.5);
  EXPECT_EQ(back.filter->still.difference_false_alarm, 1e-4);
  EXPECT_EQ(back.filter->bias_instability_horizon_s, 200.0);
  EXPECT_EQ(back.filter->temperature_smoothing_s, 0.0);
  EXPECT_EQ(back.filter->low_pass_hz, 5.0);
}

TEST(SensorModelToml, AFileWithoutCalibrationIsWrittenAndReadExactlyAsBefore) {
  const SimulationModel sim = everyTable().simulation;
  SensorModel plain;
  plain.simulation = sim;
  EXPECT_EQ(sensorModelToToml(plain), modelToToml(sim));
  const SensorModel back = parseSensorModelToml(modelToToml(sim), "old.toml");
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_FALSE(back.calibration[a]);
    EXPECT_FALSE(back.kalman[a]);
  }
  EXPECT_FALSE(back.filter);
  EXPECT_EQ(modelToToml(back.simulation), modelToToml(sim));
  // And the simulator's reader takes a calibrated file, ignoring the calibration.
  EXPECT_EQ(modelToToml(parseModelToml(sensorModelToToml(everyTable()), "new.toml")), modelToToml(sim));
}

TEST(SensorModelToml, BadCalibrationKeysAreErrorsAtTheirLine) {
  EXPECT_EQ(
      errorOf("[x.calibration]\nbias_std = 1\n").rfind("model.toml:2: unknown key 'bias_std' in [x.calibration]", 0),
      0u);
  EXPECT_EQ(
      errorOf("[x.calibration]\nbias_std_dps = -1\n").rfind("model.toml:2: x.calibration.bias_std_dps must be >= 0", 0),
      0u);
  EXPECT_EQ(errorOf("[y.calibration]\nwarm_up_amplitude_dps = 0.1\n")
                .rfind("model.toml:2: y.calibration.warm_up_amplitude_dps needs warm_up_time_constant_s", 0),
            0u);
  EXPECT_EQ(errorOf("[z.kalman]\na = 2\n").rfind("model.toml:2: z.kalman.a must be in [-1, 1]", 0), 0u);
  EXPECT_EQ(errorOf("[filter]\nwindow = 3\n").rfind("model.toml:2: unknown key 'window' in [filter]", 0), 0u);
  EXPECT_EQ(errorOf("[filter]\nstill_window_samples = 2\n").rfind("model.toml:2: still_window_samples must be 3..", 0),
            0u);
  EXPECT_EQ(errorOf("[filter]\nstill_difference_false_alarm = 1\n")
                .rfind("model.toml:2: filter.still_difference_false_alarm must be < 1", 0),
            0u);
}

TEST(SensorModelToml, RateEstimatorParametersComeFromTheTables) {
  const SensorModel m = everyTable();
  const RateEstimatorParameters p = rateEstimatorParameters(m);
  EXPECT_EQ(p.rate_hz, 50.0);
  EXPECT_EQ(p.axes[0].bias_dps, kBias[0]);
  EXPECT_EQ(p.axes[0].temperature_coefficient_dps_per_c, 0.0312);
  EXPECT_EQ(p.axes[0].temperature_reference_c, 31.25);
  EXPECT_EQ(p.axes[0].warm_up_amplitude_dps, 0.051);
  EXPECT_EQ(p.axes[0].warm_up_time_constant_s, 240.5);
  EXPECT_EQ(p.axes[0].bias_std_dps, 4.2e-4);
  EXPECT_EQ(p.axes[0].terms.arw_deg_per_sqrt_h, 0.95164);
  // No [y.calibration]: no temperature term, and the bias taken as exact.
  EXPECT_EQ(p.axes[1].temperature_coefficient_dps_per_c, 0.0);
  EXPECT_EQ(p.axes[1].bias_std_dps, 0.0);
  EXPECT_EQ(p.still.window_samples, 50u);
  EXPECT_EQ(p.bias_instability_horizon_s, 200.0);
  EXPECT_EQ(p.low_pass_hz, 5.0);
}

TEST(Calibration, AnalyzeRecoversTheCoefficientAndFilterTurnsTheHiddenTurns) {
  ScratchDir d;
  // 1. The calibration record: 20 min still from a cold start, 25 → 40 °C (τ = 5 min).
  const auto still = d.write("still.csv", csvOf(simulate(sensor(25.0, 40.0, 300.0), 1200.0, 21)));
  const auto model_path = d.path() / "sensor.toml";
  auto r = runGyroctl("analyze " + still.string() + " --write-model " + model_path.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const SensorModel model = readSensorModelToml(model_path.string());
  for (std::size_t a = 0; a < 3; ++a) {
    ASSERT_TRUE(model.calibration[a]) << readWholeFile(model_path);
    const AxisCalibration& c = *model.calibration[a];
    ASSERT_GT(c.temperature_coefficient_std_dps_per_c, 0.0);
    EXPECT_NEAR(c.temperature_coefficient_dps_per_c, kCoefficient[a], 3.0 * c.temperature_coefficient_std_dps_per_c)
        << "axis " << a;
    // The bias at the file's reference temperature, as the simulator makes it.
    const double true_bias = kBias[a] + kCoefficient[a] * (c.temperature_reference_c - 25.0);
    EXPECT_NEAR(model.simulation.axes[a].bias_dps, true_bias, 3.0 * c.bias_std_dps) << "axis " << a;
    EXPECT_EQ(c.warm_up_amplitude_dps, 0.0) << "no shape beyond the temperature was hidden";
    EXPECT_TRUE(model.kalman[a]);
  }
  ASSERT_TRUE(model.filter);

  // 2. A motion record of the same sensor (another seed), warming up 25 → 40 °C: 10 turns at
  // 20 °/s about x with 3 s still before each, from t = 60 s.
  constexpr double kTurnRate = 20.0, kStill = 3.0, kStart = 60.0;
  const MotionProfile motion = MotionProfile::turns(0, 10.0, kTurnRate, kStill, kStart);
  const std::vector<SimulatedSample> moving = simulate(sensor(25.0, 40.0, 300.0), 600.0, 22, motion);
  const auto rec = d.write("moving.csv", csvOf(moving));
  const auto plain_out = d.path() / "plain.csv", rate_out = d.path() / "rate.csv";
  r = runGyroctl("filter " + rec.string() + " -o " + plain_out.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  r = runGyroctl("filter " + rec.string() + " -o " + rate_out.string() + " --model " + model_path.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto plain = csvFields(readWholeFile(plain_out));
  const auto rows = csvFields(readWholeFile(rate_out));
  ASSERT_EQ(rows.size(), moving.size() + 1);
  ASSERT_EQ(plain.size(), rows.size());
  const std::vector<std::string> added = {"gx_rate", "gx_bias", "gy_rate", "gy_bias", "gz_rate", "gz_bias", "still"};
  ASSERT_EQ(rows[0].size(), plain[0].size() + added.size());
  for (std::size_t c = 0; c < added.size(); ++c) EXPECT_EQ(rows[0][plain[0].size() + c], added[c]);
  // The existing columns: the same text, in the same place.
  for (std::size_t i = 0; i < rows.size(); ++i)
    ASSERT_TRUE(std::equal(plain[i].begin(), plain[i].end(), rows[i].begin())) << "line " << i + 1;

  // The rate columns are RateEstimator's output, bit for bit (same parameters, same inputs).
  RateEstimatorParameters params = rateEstimatorParameters(model);
  params.rate_hz = sampleRateFromTimes(readRecordingCsv(rec.string()));  // gyroctl's: the recording's, from t
  RateEstimator estimator(params);
  const std::size_t base = plain[0].size();
  double angle = 0.0, true_angle = 0.0, dt = 1.0 / 50.0;
  std::size_t still_rows = 0;
  for (std::size_t i = 0; i < moving.size(); ++i) {
    const SimulatedSample& s = moving[i];
    const RateSample e = estimator.update(s.t_s, s.rate_dps, s.temperature_c);
    const auto& row = rows[i + 1];
    for (std::size_t a = 0; a < 3; ++a) {
      ASSERT_EQ(std::stod(row[base + 2 * a]), e.rate_dps[a]) << "line " << i + 2 << " axis " << a;
      ASSERT_EQ(std::stod(row[base + 2 * a + 1]), e.bias_dps[a]) << "line " << i + 2 << " axis " << a;
    }
    ASSERT_EQ(row[base + 6], e.still ? "1" : "0") << "line " << i + 2;
    still_rows += e.still;
    angle += std::stod(row[base]) * dt;
    true_angle += s.true_rate_dps[0] * dt;
  }
  EXPECT_NEAR(true_angle, 3600.0, 1.0);
  std::printf("x: turned %.2f deg by the rate column, %.2f deg in truth (%.3f %%); %zu of %zu samples still\n", angle,
              true_angle, 100.0 * (angle - true_angle) / true_angle, still_rows, moving.size());
  EXPECT_LE(std::fabs(angle - true_angle), 0.005 * std::fabs(true_angle));
}

TEST(Calibration, FilterWithoutATempColumnTakesTheReferenceAndSaysSo) {
  ScratchDir d;
  SensorModel m = everyTable();
  const auto model = d.write("m.toml", sensorModelToToml(m));
  std::string csv = "t,gx,gy,gz\n";
  for (int i = 0; i < 200; ++i) {
    const double w = 0.001 * ((i * 37) % 11 - 5);
    csv += std::to_string(i * 0.02) + "," + std::to_string(1.4 + w) + "," + std::to_string(-0.4 + w) + "," +
           std::to_string(0.25 + w) + "\n";
  }
  const auto in = d.write("in.csv", csv);
  const auto out = d.path() / "out.csv";
  const auto r = runGyroctl("filter " + in.string() + " -o " + out.string() + " --model " + model.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.err.find("has no temp column: the rate stream takes the model's reference temperature, 31.25 C"),
            std::string::npos)
      << r.err;
  // Without gz, the still detector cannot run: an error naming the column.
  const auto two = d.write("two.csv", "t,gx,gy\n0,1,2\n0.02,1,2\n0.04,1,2\n");
  const auto e = runGyroctl("filter " + two.string() + " -o " + out.string() + " --model " + model.string(), d.path());
  EXPECT_EQ(e.exit_status, 65) << e.err;  // EX_DATAERR
  EXPECT_NE(e.err.find("'gz' is missing"), std::string::npos) << e.err;
}

TEST(Calibration, ModelCheckWritesTheSameCalibrationBesideItsEffects) {
  ScratchDir d;
  const auto hidden = d.write("hidden.toml",
                              "rate_hz = 50\n[temperature]\nstart_c = 24\nfinal_c = 34\ntime_constant_s = 120\n"
                              "noise_std_c = 0.02\n[x]\narw_deg_per_sqrt_h = 0.5\nbias_dps = 0.3\n"
                              "[x.extra]\ntemperature_coefficient_dps_per_c = 0.02\ntemperature_reference_c = 25\n"
                              "[y]\narw_deg_per_sqrt_h = 0.5\n[z]\narw_deg_per_sqrt_h = 0.5\n");
  const auto rec = d.path() / "rec.csv";
  auto r = runGyroctl("simulate --model " + hidden.string() + " --duration 300 --seed 9 -o " + rec.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto checked = d.path() / "checked.toml", analysed = d.path() / "analysed.toml";
  r = runGyroctl("model-check " + rec.string() + " --replicas 8 --threads 2 --write-model " + checked.string(),
                 d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  r = runGyroctl("analyze " + rec.string() + " --write-model " + analysed.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const SensorModel c = readSensorModelToml(checked.string()), a = readSensorModelToml(analysed.string());
  for (std::size_t axis = 0; axis < 3; ++axis) {
    ASSERT_TRUE(c.calibration[axis]) << readWholeFile(checked);
    // The same fit of the same record: the same calibration table.
    EXPECT_EQ(c.calibration[axis]->temperature_coefficient_dps_per_c,
              a.calibration[axis]->temperature_coefficient_dps_per_c);
    EXPECT_EQ(c.calibration[axis]->bias_std_dps, a.calibration[axis]->bias_std_dps);
  }
  const AxisCalibration& x = *c.calibration[0];
  EXPECT_NEAR(x.temperature_coefficient_dps_per_c, 0.02, 3.0 * x.temperature_coefficient_std_dps_per_c);
  EXPECT_NE(c.simulation.axes[0].extra.temperature_coefficient_dps_per_c, 0.0) << readWholeFile(checked);
  EXPECT_NO_THROW(rateEstimatorParameters(c));
}
