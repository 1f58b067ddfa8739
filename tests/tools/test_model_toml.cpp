// Simulation model files: every key read into the right field, the writer's output read
// back to the same model, and every kind of bad input reported as FILE:LINE naming the key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "formats/model_toml.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::recording;
using gyrod::processing::SimulationModel;

namespace {

// The message of the RecordingError thrown for `text`, or "" if none.
std::string errorOf(const std::string& text) {
  try {
    parseModelToml(text, "model.toml");
  } catch (const RecordingError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ModelToml, ReadsEveryKey) {
  const SimulationModel m = parseModelToml(R"(
rate_hz = 100
dlpf = 3
fs_sel = 1
[temperature]
start_c = 24.5
final_c = 38
time_constant_s = 900.0
noise_std_c = 0.02
[x]
quantization_urad = 0.1663
arw_deg_per_sqrt_h = 0.95164
bias_instability_deg_per_h = 0.60565
rrw_deg_per_h_sqrt_h = 0.07759
rate_ramp_deg_per_h2 = 0.43223
bias_dps = -1.367
[x.ar]
phi = [-0.2796, -0.0802, -0.1428]
noise_var = 0.0564
[z]
arw_deg_per_sqrt_h = 2
)",
                                           "model.toml");
  EXPECT_EQ(m.rate_hz, 100.0);
  EXPECT_EQ(m.dlpf_cfg, 3);
  EXPECT_EQ(m.fs_sel, 1);
  EXPECT_EQ(m.temperature.start_c, 24.5);
  EXPECT_EQ(m.temperature.final_c, 38.0);
  EXPECT_EQ(m.temperature.time_constant_s, 900.0);
  EXPECT_EQ(m.temperature.noise_std_c, 0.02);
  EXPECT_EQ(m.axes[0].terms.quantization_urad, 0.1663);
  EXPECT_EQ(m.axes[0].terms.arw_deg_per_sqrt_h, 0.95164);
  EXPECT_EQ(m.axes[0].terms.bias_instability_deg_per_h, 0.60565);
  EXPECT_EQ(m.axes[0].terms.rrw_deg_per_h_sqrt_h, 0.07759);
  EXPECT_EQ(m.axes[0].terms.rate_ramp_deg_per_h2, 0.43223);
  EXPECT_EQ(m.axes[0].bias_dps, -1.367);
  ASSERT_EQ(m.axes[0].ar.phi.size(), 3u);
  EXPECT_EQ(m.axes[0].ar.phi[2], -0.1428);
  EXPECT_EQ(m.axes[0].ar.noise_var, 0.0564);
  EXPECT_EQ(m.axes[1].terms.arw_deg_per_sqrt_h, 0.0);  // absent axis: all zero
  EXPECT_EQ(m.axes[2].terms.arw_deg_per_sqrt_h, 2.0);
}

TEST(ModelToml, EmptyFileIsThePureDefaultModel) {
  const SimulationModel m = parseModelToml("", "model.toml");
  EXPECT_EQ(m.rate_hz, 50.0);
  EXPECT_FALSE(m.dlpf_cfg);
  EXPECT_FALSE(m.fs_sel);
}

TEST(ModelToml, WrittenModelReadsBackIdentically) {
  SimulationModel m;
  m.rate_hz = 1000.0 / 3.0;
  m.dlpf_cfg = 2;
  m.fs_sel = 3;
  m.temperature = {21.123456789012345, 40.0, 1234.5, 0.1 / 3.0};
  for (std::size_t a = 0; a < 3; ++a) {
    m.axes[a].terms.arw_deg_per_sqrt_h = 0.1 * (a + 1) / 7.0;
    m.axes[a].terms.bias_instability_deg_per_h = 1e-3 * (a + 2);
    m.axes[a].bias_dps = -0.3 * a;
  }
  m.axes[1].ar = {{0.2, -0.1}, 1.0 / 3.0};
  const SimulationModel r = parseModelToml(modelToToml(m), "written.toml");
  EXPECT_EQ(r.rate_hz, m.rate_hz);
  EXPECT_EQ(r.dlpf_cfg, m.dlpf_cfg);
  EXPECT_EQ(r.fs_sel, m.fs_sel);
  EXPECT_EQ(r.temperature.start_c, m.temperature.start_c);
  EXPECT_EQ(r.temperature.noise_std_c, m.temperature.noise_std_c);
  for (std::size_t a = 0; a < 3; ++a) {
    for (auto t : gyrod::processing::kAllNoiseTerms) EXPECT_EQ(r.axes[a].terms.get(t), m.axes[a].terms.get(t));
    EXPECT_EQ(r.axes[a].bias_dps, m.axes[a].bias_dps);
    EXPECT_EQ(r.axes[a].ar.phi, m.axes[a].ar.phi);
    EXPECT_EQ(r.axes[a].ar.noise_var, m.axes[a].ar.noise_var);
  }
}

TEST(ModelToml, UnknownKeysNameFileLineAndKey) {
  EXPECT_EQ(errorOf("rate_hz = 50\nsample_rate = 3\n").rfind("model.toml:2: unknown key 'sample_rate'", 0), 0u)
      << errorOf("rate_hz = 50\nsample_rate = 3\n");
  EXPECT_EQ(errorOf("[x]\narw = 1\n").rfind("model.toml:2: unknown key 'arw' in [x]", 0), 0u);
  EXPECT_EQ(errorOf("[temperature]\nstart = 1\n").rfind("model.toml:2: unknown key 'start' in [temperature]", 0), 0u);
  EXPECT_EQ(errorOf("[y.ar]\nphi = [0.1]\nsigma2 = 1\n").rfind("model.toml:3: unknown key 'sigma2' in [y.ar]", 0), 0u);
  EXPECT_EQ(errorOf("[w]\n").rfind("model.toml:1: unknown key 'w'", 0), 0u);
}

TEST(ModelToml, WrongTypesNameTheKey) {
  EXPECT_EQ(errorOf("rate_hz = \"fast\"\n"), "model.toml:1: rate_hz must be a number, got a string");
  EXPECT_EQ(errorOf("dlpf = 4.0\n"), "model.toml:1: dlpf must be an integer, got a float");
  EXPECT_EQ(errorOf("\n\n[x]\nbias_dps = true\n"), "model.toml:4: x.bias_dps must be a number, got a boolean");
  EXPECT_EQ(errorOf("x = 3\n"), "model.toml:1: x must be a table ([x]), got an integer");
  EXPECT_EQ(errorOf("[x.ar]\nphi = 0.5\n"), "model.toml:2: x.ar.phi must be an array of numbers, got a float");
  EXPECT_EQ(errorOf("[x.ar]\nphi = [0.5, \"a\"]\n"),
            "model.toml:2: x.ar.phi must contain numbers only, found a string");
}

TEST(ModelToml, BadValuesNameTheKey) {
  EXPECT_EQ(errorOf("rate_hz = 0\n"), "model.toml:1: rate_hz must be > 0, got 0");
  EXPECT_EQ(errorOf("dlpf = 7\n"), "model.toml:1: dlpf must be 0..6, got 7");
  EXPECT_EQ(errorOf("fs_sel = -1\n"), "model.toml:1: fs_sel must be 0..3, got -1");
  EXPECT_EQ(errorOf("[z]\nrrw_deg_per_h_sqrt_h = -0.1\n"),
            "model.toml:2: z.rrw_deg_per_h_sqrt_h must be >= 0, got -0.1");
  EXPECT_EQ(errorOf("[z]\nbias_dps = nan\n"), "model.toml:2: z.bias_dps must be finite, got nan");
  EXPECT_EQ(errorOf("[temperature]\ntime_constant_s = 0\n"),
            "model.toml:2: temperature.time_constant_s must be > 0, got 0");
  // Cross-key checks point at the key that has to change.
  const std::string rate = errorOf("dlpf = 3\n\nrate_hz = 300\n");
  EXPECT_EQ(rate.rfind("model.toml:3: rate_hz 300 is not possible with DLPF_CFG 3", 0), 0u) << rate;
  const std::string ar = errorOf("[x.ar]\nnoise_var = 1\nphi = [0.5, 0.6]\n");
  EXPECT_EQ(ar.rfind("model.toml:3: x.ar.phi is not stationary", 0), 0u) << ar;
}

TEST(ModelToml, SyntaxErrorsAndMissingFiles) {
  const std::string e = errorOf("rate_hz = 50\n[x\n");
  EXPECT_EQ(e.rfind("model.toml:2: ", 0), 0u) << e;
  gyrod::test::ScratchDir d;
  const std::string missing = (d.path() / "none.toml").string();
  try {
    readModelToml(missing);
    FAIL() << "no error for a missing file";
  } catch (const RecordingError& err) {
    EXPECT_EQ(std::string(err.what()), missing + ": cannot open: No such file or directory");
  }
  const std::string path = (d.path() / "m.toml").string();
  std::ofstream(path) << "rate_hz = 25\n";
  EXPECT_EQ(readModelToml(path).rate_hz, 25.0);
}
