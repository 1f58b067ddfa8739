// The model file's narrowband lines ([x.extra] narrowband_lines): read into
// AxisExtraEffects::narrowband_lines, written back so that read → write → read gives the same
// values, and every bad value reported as FILE:LINE naming the key and the value.
#include <gtest/gtest.h>

#include <string>

#include "formats/model_toml.hpp"

using gyrod::processing::NarrowbandLine;
using gyrod::processing::SimulationModel;

namespace {

// The message of the RecordingError thrown for `text`, or "" if none.
std::string narrowbandLineFileError(const std::string& text) {
  try {
    gyrod::recording::parseModelToml(text, "lines.toml");
  } catch (const gyrod::recording::RecordingError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ModelTomlNarrowbandLines, ReadsEveryLine) {
  const SimulationModel m = gyrod::recording::parseModelToml(R"(
rate_hz = 100
[y.extra]
narrowband_lines = [{centre_hz = 31.4, width_hz = 0.3, rms_dps = 0.02},
                    {centre_hz = 16.2, width_hz = 0.15}]
)",
                                                             "lines.toml");
  ASSERT_EQ(m.axes[1].extra.narrowband_lines.size(), 2u);
  EXPECT_EQ(m.axes[1].extra.narrowband_lines[0], (NarrowbandLine{31.4, 0.3, 0.02}));
  EXPECT_EQ(m.axes[1].extra.narrowband_lines[1], (NarrowbandLine{16.2, 0.15, 0.0}));  // rms 0 by default
  EXPECT_TRUE(m.axes[0].extra.narrowband_lines.empty());
  EXPECT_FALSE(m.axes[1].extra.empty());
}

TEST(ModelTomlNarrowbandLines, WrittenLinesReadBackIdentically) {
  SimulationModel m;
  m.rate_hz = 1000.0 / 7.0;
  m.axes[0].extra.narrowband_lines = {{100.0 / 3.0, 0.1 / 3.0, 0.02 / 7.0}};
  m.axes[2].extra.narrowband_lines = {{31.4, 0.3, 0.02}, {20.000000000000004, 1e-3, 0.0}};
  m.axes[2].extra.sinusoids = {{1.08, 0.07, 0.3}};
  const std::string written = gyrod::recording::modelToToml(m);
  const SimulationModel back = gyrod::recording::parseModelToml(written, "written.toml");
  for (std::size_t a = 0; a < gyrod::processing::kSimulatedAxes; ++a)
    EXPECT_EQ(back.axes[a].extra.narrowband_lines, m.axes[a].extra.narrowband_lines) << "axis " << a;
  EXPECT_TRUE(back.axes[1].extra.empty());
  // And once more: the second file is the first.
  EXPECT_EQ(gyrod::recording::modelToToml(back), written);
  // Extras without lines write no narrowband_lines key (such files stay as they were).
  SimulationModel no_lines;
  no_lines.axes[0].extra.sinusoids = {{1.0, 0.1, 0.0}};
  EXPECT_EQ(gyrod::recording::modelToToml(no_lines).find("narrowband_lines"), std::string::npos);
}

TEST(ModelTomlNarrowbandLines, BadValuesNameFileLineKeyAndValue) {
  EXPECT_EQ(narrowbandLineFileError("[x.extra]\nnarrowband_lines = [{centre_hz = 3.1, width_hz = 0.3, q = 1}]\n")
                .rfind("lines.toml:2: unknown key 'q' in x.extra.narrowband_lines (expected centre_hz, width_hz, "
                       "rms_dps)",
                       0),
            0u);
  EXPECT_EQ(narrowbandLineFileError("rate_hz = 100\n[x]\n[x.extra]\n\nnarrowband_lines = [{centre_hz = 31.4, "
                                    "width_hz = 0, rms_dps = 0.02}]\n"),
            "lines.toml:5: x.extra.narrowband_lines.width_hz must be > 0, got 0");
  EXPECT_EQ(narrowbandLineFileError("[z.extra]\nnarrowband_lines = [{centre_hz = 3, width_hz = -0.3}]\n"),
            "lines.toml:2: z.extra.narrowband_lines.width_hz must be > 0, got -0.3");
  EXPECT_EQ(
      narrowbandLineFileError("[z.extra]\nnarrowband_lines = [{centre_hz = 3, width_hz = 0.3, rms_dps = -1e-3}]\n"),
      "lines.toml:2: z.extra.narrowband_lines.rms_dps must be >= 0, got -0.001");
  EXPECT_EQ(
      narrowbandLineFileError("[z.extra]\nnarrowband_lines = [{centre_hz = 3, width_hz = 0.3, rms_dps = \"a\"}]\n"),
      "lines.toml:2: z.extra.narrowband_lines.rms_dps must be a number, got a string");
  // The centre against the file's rate, wherever rate_hz stands, and against the default 50 Hz.
  EXPECT_EQ(narrowbandLineFileError("rate_hz = 40\n[y.extra]\nnarrowband_lines = [{centre_hz = 20, width_hz = 0.3}]\n"),
            "lines.toml:3: y.extra.narrowband_lines.centre_hz must be < rate_hz/2 = 20, got 20");
  EXPECT_EQ(narrowbandLineFileError("[y.extra]\nnarrowband_lines = [{centre_hz = 31.4, width_hz = 0.3}]\n"),
            "lines.toml:2: y.extra.narrowband_lines.centre_hz must be < rate_hz/2 = 25, got 31.4 (rate_hz not "
            "given: default 50)");
  EXPECT_EQ(
      narrowbandLineFileError("rate_hz = 100\n[y.extra]\nnarrowband_lines = [{centre_hz = 31.4, width_hz = 0.3}]\n"),
      "");
  EXPECT_EQ(narrowbandLineFileError("[y.extra]\nnarrowband_lines = [{centre_hz = 0, width_hz = 0.3}]\n"),
            "lines.toml:2: y.extra.narrowband_lines.centre_hz must be > 0, got 0");
  // Each line needs its centre and width; the array holds inline tables.
  EXPECT_EQ(narrowbandLineFileError("[y.extra]\n\nnarrowband_lines = [{centre_hz = 3, rms_dps = 0.1}]\n"),
            "lines.toml:3: y.extra.narrowband_lines: each line needs centre_hz and width_hz (width_hz is missing)");
  EXPECT_EQ(narrowbandLineFileError("[y.extra]\nnarrowband_lines = 31.4\n"),
            "lines.toml:2: y.extra.narrowband_lines must be an array of inline tables, got a float");
  EXPECT_EQ(narrowbandLineFileError("[y.extra]\nnarrowband_lines = [31.4]\n"),
            "lines.toml:2: y.extra.narrowband_lines must contain inline tables only, found a float");
  // The table's own list of keys names them.
  const std::string unknown = narrowbandLineFileError("[y.extra]\nnarrowband_line = []\n");
  EXPECT_EQ(unknown.rfind("lines.toml:2: unknown key 'narrowband_line' in [y.extra]", 0), 0u) << unknown;
  EXPECT_NE(unknown.find("narrowband_lines)"), std::string::npos) << unknown;
}
