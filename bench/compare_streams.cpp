// compare_streams: the table of docs/motion.md — raw, mean, kalman and rate side by side on
// simulated records from one seed (processing/motion/stream_comparison.hpp says what each stream and
// each figure is). scripts/motion-table.sh runs the whole calibration workflow around it:
//   compare_streams --write-sensor true.toml            the simulated sensor, as a model file
//   gyroctl simulate --model true.toml --warm-up 15,300 --duration 1800 -o cal.csv
//   gyroctl analyze cal.csv --write-model sensor.toml   the calibration (docs/calibration.md)
//   compare_streams --model sensor.toml --seed N        prints the markdown table
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>

#include "formats/calibration.hpp"
#include "formats/model_toml.hpp"
#include "formats/output_file.hpp"
#include "processing/motion/stream_comparison.hpp"

namespace {

using namespace gyrod::processing;

int usage() {
  std::fputs(
      "usage: compare_streams --model SENSOR.toml [--seed N]   print the table (markdown)\n"
      "       compare_streams --write-sensor FILE               write the simulated sensor as a model file\n",
      stderr);
  return 2;
}

std::string cell(double v, const char* format) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

void row(const std::string& label, const StreamComparison& c, const auto& value) {
  std::string line = "| " + label;
  for (std::size_t s = 0; s < kComparedStreams; ++s) line += " | " + value(c.streams[s]);
  std::printf("%s |\n", line.c_str());
}

void printTable(const StreamComparison& c, const StreamComparisonSetup& setup) {
  std::printf("| measure | raw | mean | kalman | rate |\n|---|---|---|---|---|\n");
  for (std::size_t k = 0; k < kCompareStepSamples.size(); ++k)
    row("10 °/s step: value at sample " + std::to_string(kCompareStepSamples[k]) + " [°/s]", c,
        [k](const StreamFigures& f) { return cell(f.step_value_dps[k], "%.3f"); });
  row("10 °/s step: t90 [s]", c,
      [](const StreamFigures& f) { return f.step_t90_s ? cell(*f.step_t90_s, "%.3f") : std::string("never"); });
  row("10 °/s step: settled at [°/s]", c, [](const StreamFigures& f) { return cell(f.step_settled_dps, "%.3f"); });
  for (std::size_t k = 0; k < kCompareFrequenciesHz.size(); ++k)
    row(cell(kCompareFrequenciesHz[k], "%g") + " Hz, " + cell(kCompareAmplitudesDps[k], "%g") + " °/s: gain / phase", c,
        [k](const StreamFigures& f) { return cell(f.gain[k], "%.4f") + " / " + cell(f.phase_deg[k], "%+.1f°"); });
  row("mixed profile: RMS error [°/s]", c, [](const StreamFigures& f) { return cell(f.mixed_rms_error_dps, "%.3f"); });
  row("10 full turns: angle error", c,
      [](const StreamFigures& f) { return cell(f.turns_angle_error_percent, "%+.3f %%"); });
  row(cell(setup.warm_up_delta_c, "%g") + " °C warm-up: offset at rest after it [°/s]", c,
      [](const StreamFigures& f) { return cell(f.warm_up_offset_dps, "%+.4f"); });
  row("at rest: variance ratio (to raw)", c, [](const StreamFigures& f) { return cell(f.variance_ratio, "%.4f"); });
  row("at rest: peak ratio (to raw)", c, [](const StreamFigures& f) { return cell(f.peak_ratio, "%.4f"); });
  std::printf("\n");
  std::printf(
      "Seed %llu; %zu steps; raw's variance at rest %.4g (°/s)²;\nthe paper's chain ran with L = %zu, "
      "r = %g °/s, A = %.4f, Q = %.3g, R = %.3g (x axis).\n",
      static_cast<unsigned long long>(setup.seed), c.steps, c.raw_variance_dps2, c.paper[0].mean_window,
      c.paper[0].mean_threshold_dps, c.paper[0].kalman.a, c.paper[0].kalman.q, c.paper[0].kalman.r);
  std::printf(
      "Warm-up, worst axis: rate's bias estimate before the final still %.4f °/s from the truth;\n"
      "the start-up estimate's %.4f °/s.\n",
      c.rate_bias_error_dps, c.startup_bias_error_dps);
}

}  // namespace

int main(int argc, char** argv) {
  std::string model_path, sensor_path;
  std::uint64_t seed = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (i + 1 >= argc) return usage();
    if (arg == "--model")
      model_path = argv[++i];
    else if (arg == "--write-sensor")
      sensor_path = argv[++i];
    else if (arg == "--seed")
      seed = std::strtoull(argv[++i], nullptr, 10);
    else
      return usage();
  }
  try {
    if (!sensor_path.empty()) {
      gyrod::formats::writeFileAtomically(
          sensor_path,
          "# The simulated sensor of docs/motion.md's table (processing::comparisonSensor).\n" +
              gyrod::recording::modelToToml(comparisonSensor()),
          {});
      return 0;
    }
    if (model_path.empty()) return usage();
    StreamComparisonSetup setup;
    setup.sensor = comparisonSensor();
    setup.rate = gyrod::recording::rateEstimatorParameters(gyrod::recording::readSensorModelToml(model_path));
    setup.rate.rate_hz = setup.sensor.rate_hz;  // as gyrod does: the file's calibration at the device's rate
    setup.seed = seed;
    printTable(compareStreams(setup), setup);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "compare_streams: %s\n", e.what());
    return 1;
  }
  return 0;
}
