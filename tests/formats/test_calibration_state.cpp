// gyrod's calibration state file (formats/calibration_state.hpp): written and read back to the
// same numbers, atomically replaced, and every way a file can be wrong refused in one line that
// names the file, the line and the key.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "formats/calibration_state.hpp"

using namespace gyrod::formats;

namespace {

CalibrationState sampleState() {
  CalibrationState s;
  s.model = fnv1a64Hex("1.367 0.03 25 0 0\n");
  s.rate_hz = 50.0;
  s.saved_unix_s = 1795000000.25;
  s.data_time_s = 7200.0;
  s.residual.temperature_origin_c = 28.013;
  s.residual.temperature_c = 42.87;
  s.residual.still_temperature_min_c = 28.02;
  s.residual.still_temperature_max_c = 42.9;
  s.residual.still_samples = 351234;
  s.residual.axes[0] = {0.2031, -0.01493, 1.7e-6, -8.1e-8, 6.3e-9};
  s.residual.axes[1] = {-0.19, 0.0102, 2.2e-6, 1.0e-8, 7.0e-9};
  s.residual.axes[2] = {1.0 / 3.0, 0.0, 3.0e-6, 0.0, 0.0};
  return s;
}

std::string stateErrorOf(const std::string& text) {
  try {
    parseCalibrationStateToml(text, "state.toml");
  } catch (const CalibrationStateError& e) {
    return e.what();
  }
  return "";
}

std::string stateTextReplaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

}  // namespace

TEST(CalibrationState, ReadsBackTheSameNumbers) {
  const CalibrationState s = sampleState();
  const CalibrationState back = parseCalibrationStateToml(calibrationStateToToml(s), "state.toml");
  EXPECT_EQ(back.model, s.model);
  EXPECT_EQ(back.rate_hz, s.rate_hz);
  EXPECT_EQ(back.saved_unix_s, s.saved_unix_s);
  EXPECT_EQ(back.data_time_s, s.data_time_s);
  EXPECT_EQ(back.residual.temperature_origin_c, s.residual.temperature_origin_c);
  EXPECT_EQ(back.residual.temperature_c, s.residual.temperature_c);
  EXPECT_EQ(back.residual.still_temperature_min_c, s.residual.still_temperature_min_c);
  EXPECT_EQ(back.residual.still_temperature_max_c, s.residual.still_temperature_max_c);
  EXPECT_EQ(back.residual.still_samples, s.residual.still_samples);
  for (std::size_t a = 0; a < 3; ++a) EXPECT_EQ(back.residual.axes[a], s.residual.axes[a]) << a;
}

TEST(CalibrationState, NoStillSampleYetLeavesTheRangeOut) {
  CalibrationState s = sampleState();
  s.residual.still_temperature_min_c = s.residual.still_temperature_max_c = std::nan("");
  s.residual.still_samples = 0;
  const std::string text = calibrationStateToToml(s);
  EXPECT_EQ(text.find("still_temperature_min_c"), std::string::npos);
  const CalibrationState back = parseCalibrationStateToml(text, "state.toml");
  EXPECT_TRUE(std::isnan(back.residual.still_temperature_min_c));
  EXPECT_TRUE(std::isnan(back.residual.still_temperature_max_c));
}

TEST(CalibrationState, TheFingerprintCoversTheBiasModelAndNothingElse) {
  EXPECT_EQ(fnv1a64Hex(""), "cbf29ce484222325");   // FNV-1a 64's offset basis: nothing hashed
  EXPECT_EQ(fnv1a64Hex("a"), "af63dc4c8601ec8c");  // the published test vector
  gyrod::processing::RateEstimatorParameters p;
  p.axes[0].bias_dps = 1.367;
  const std::string base = biasModelFingerprint(p);
  auto changed = [&](auto edit) {
    gyrod::processing::RateEstimatorParameters q = p;
    edit(q);
    return biasModelFingerprint(q) != base;
  };
  EXPECT_TRUE(changed([](auto& q) { q.axes[0].bias_dps = 1.368; }));
  EXPECT_TRUE(changed([](auto& q) { q.axes[2].temperature_coefficient_dps_per_c = 0.01; }));
  EXPECT_TRUE(changed([](auto& q) { q.axes[1].temperature_reference_c = 30.0; }));
  EXPECT_TRUE(changed([](auto& q) { q.axes[1].warm_up_amplitude_dps = 0.1; }));
  EXPECT_FALSE(changed([](auto& q) { q.axes[0].terms.arw_deg_per_sqrt_h = 2.0; }));
  EXPECT_FALSE(changed([](auto& q) { q.rate_hz = 100.0; }));
  EXPECT_FALSE(changed([](auto& q) { q.low_pass_hz = 5.0; }));
}

TEST(CalibrationState, EachBadFileIsOneLineNamingFileLineAndKey) {
  const std::string good = calibrationStateToToml(sampleState());
  // Another file altogether: a gyrod configuration.
  EXPECT_EQ(stateErrorOf("[device]\nrate_hz = 50\n"),
            "state.toml:1: unknown key 'device' at the top level (valid keys: format, version, model, rate_hz, "
            "saved_unix_s, data_time_s, temperature_c, temperature_origin_c, still_temperature_min_c, "
            "still_temperature_max_c, still_samples, x, y, z)");
  EXPECT_EQ(stateErrorOf("rate_hz = 50\n"), "state.toml: not a gyrod calibration state file: key 'format' is missing");
  const std::string other_format =
      stateErrorOf(stateTextReplaced(good, "\"gyrod-calibration-state\"", "\"gyrod-model\""));
  EXPECT_NE(other_format.find("state.toml:4: key 'format': must be \"gyrod-calibration-state\" (got \"gyrod-model\")"),
            std::string::npos)
      << other_format;
  const std::string newer = stateErrorOf(stateTextReplaced(good, "version = 1", "version = 2"));
  EXPECT_NE(newer.find("state.toml:5: key 'version': this gyrod reads version 1 (got 2)"), std::string::npos) << newer;
  const std::string text_for_number = stateErrorOf(stateTextReplaced(good, "rate_hz = 50.0", "rate_hz = \"fifty\""));
  EXPECT_NE(text_for_number.find("state.toml:7: key 'rate_hz'"), std::string::npos) << text_for_number;
  const std::string missing_axis = stateErrorOf(good.substr(0, good.find("\n[z]")));
  EXPECT_EQ(missing_axis, "state.toml: table [z] is missing");
  const std::string missing_key = stateErrorOf(stateTextReplaced(good, "var_slope = 7e-09\n", ""));
  EXPECT_EQ(missing_key, "state.toml: key 'y.var_slope' is missing");
  const std::string negative = stateErrorOf(stateTextReplaced(good, "var_offset = 3e-06", "var_offset = -3e-06"));
  EXPECT_NE(negative.find("state.toml: axis z: var_offset must be finite and >= 0"), std::string::npos) << negative;
  const std::string syntax = stateErrorOf(stateTextReplaced(good, "still_samples = ", "still_samples == "));
  EXPECT_EQ(syntax.rfind("state.toml:", 0), 0u) << syntax;
  EXPECT_EQ(syntax.find('\n'), std::string::npos) << syntax;
}

TEST(CalibrationState, TheFileIsReplacedWholeAndReadOnlyAsARegularFile) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("gyrod-state-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "calibration.toml").string();
  CalibrationState s = sampleState();
  replaceStateFile(path, calibrationStateToToml(s));
  s.residual.axes[0].offset_dps = 0.25;
  replaceStateFile(path, calibrationStateToToml(s));
  EXPECT_EQ(readCalibrationStateToml(path).residual.axes[0].offset_dps, 0.25);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  // A directory where the state should be, and a FIFO: refused by name, never opened or written.
  const std::string fifo = (dir / "fifo.toml").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THROW(readCalibrationStateToml(fifo), InputFileError);
  EXPECT_THROW(readCalibrationStateToml(dir.string()), InputFileError);
  EXPECT_THROW(replaceStateFile((dir / "no-such-dir" / "calibration.toml").string(), "x"), std::system_error);
  // Too large for a state file.
  {
    std::ofstream big(dir / "big.toml");
    big << std::string(kCalibrationStateInput.max_bytes + 1, '#');
  }
  EXPECT_THROW(readCalibrationStateToml((dir / "big.toml").string()), InputFileError);
  std::filesystem::remove_all(dir);
}
