// gyroctl model-check: the JSON document, the report folder, and errors. The recording comes
// from the hidden-effect generator (a sinusoid on one axis), written as the CSV analyze reads.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "model_check/hidden_effect_generator.hpp"
#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_UNDEFINED__)
#define SKIP_WHEN_SANITIZED() GTEST_SKIP() << "model-check end to end: minutes under the sanitizers, runs in the optimised build"
#else
#define SKIP_WHEN_SANITIZED() (void)0
#endif

namespace {

std::string recordingCsv(const gyrod::test::GeneratedRecording& g) {
  std::string out = "t,gx,gy,gz,temp\n";
  char line[256];
  for (std::size_t i = 0; i < g.t.size(); ++i) {
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g,%.17g\n", g.t[i], g.axes[0][i], g.axes[1][i], g.axes[2][i],
                  g.temp[i]);
    out += line;
  }
  return out;
}

}  // namespace

TEST(GyroctlModelCheck, JsonNamesTheHiddenSinusoidOnItsAxisOnly) {
  SKIP_WHEN_SANITIZED();
  ScratchDir d;
  const auto g = gyrod::test::HiddenEffectGenerator(7).generate(300.0, 50.0, {gyrod::processing::ModelEffect::Sinusoid});
  const auto csv = d.write("rec.csv", recordingCsv(g));
  const auto r = runGyroctl("model-check " + csv.string() + " --json --replicas 16 --seed 3 --threads 2", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto doc = nlohmann::json::parse(r.out);
  const char* names[3] = {"gx", "gy", "gz"};
  for (std::size_t a = 0; a < 3; ++a) {
    const auto& axis = doc.at("axes").at(names[a]);
    for (const char* key : {"adev_log_error_base", "adev_log_error_extended", "innovation_var_base", "innovation_var_extended",
                            "ljung_box_p_base", "ljung_box_p_extended", "in_band_base", "in_band_extended"})
      EXPECT_TRUE(axis.at("gain").at(key).is_number()) << key;
    const auto& effects = axis.at("effects");
    ASSERT_TRUE(effects.is_array());
    if (a != g.hidden[0].axis) {
      EXPECT_TRUE(effects.empty()) << effects.dump();
      continue;
    }
    ASSERT_EQ(effects.size(), 1u) << effects.dump();
    EXPECT_EQ(effects[0].at("effect"), "sinusoid");
    EXPECT_NEAR(effects[0].at("params").at("freq_hz").get<double>(), g.hidden[0].freq_hz, 0.5 / 300.0);
    EXPECT_NEAR(effects[0].at("params").at("amp_dps").get<double>(), g.hidden[0].amp_dps, 0.1 * g.hidden[0].amp_dps);
    EXPECT_FALSE(effects[0].at("evidence").get<std::string>().empty());
  }
}

TEST(GyroctlModelCheck, ReportFolderHasMarkdownAndPlotScripts) {
  SKIP_WHEN_SANITIZED();
  ScratchDir d;
  const auto g = gyrod::test::HiddenEffectGenerator(5).generate(200.0, 50.0, {});
  const auto csv = d.write("rec.csv", recordingCsv(g));
  const auto dir = d.path() / "report";
  const auto r = runGyroctl("model-check " + csv.string() + " --axis gy --replicas 8 --report " + dir.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("checked in"), std::string::npos);
  const std::string md = readWholeFile(dir / "report.md");
  EXPECT_NE(md.find("## gy"), std::string::npos);
  EXPECT_EQ(md.find("## gx"), std::string::npos);
  for (const char* f : {"allan_gy.gp", "allan_gy.dat", "spectrum_gy.gp", "temperature_gy.gp"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    EXPECT_TRUE(std::filesystem::exists(dir / "allan_gy.png"));
  }
}

TEST(GyroctlModelCheck, TooShortOrMissingFilesAreUsageErrors) {
  ScratchDir d;
  const auto csv = d.write("short.csv", "t,gx\n0,0.1\n0.02,0.2\n0.04,0.1\n");
  auto r = runGyroctl("model-check " + csv.string(), d.path());
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("too few"), std::string::npos) << r.err;
  r = runGyroctl("model-check " + (d.path() / "missing.csv").string(), d.path());
  EXPECT_EQ(r.exit_status, 2);
  r = runGyroctl("model-check " + csv.string() + " --replicas 2", d.path());
  EXPECT_EQ(r.exit_status, 2);
}

// ---- the model file's optional [x.extra] tables ------------------------------------------

#include "tools/recording/model_toml.hpp"

TEST(ModelTomlExtra, ExtraEffectsReadBackIdentically) {
  gyrod::processing::SimulationModel m;
  auto& e = m.axes[1].extra;
  e.temperature_coefficient_dps_per_c = -0.0123;
  e.temperature_reference_c = 31.5;
  e.gauss_markov_tau_s = 17.25;
  e.gauss_markov_sigma_dps = 0.0021;
  e.outlier_count = 7;
  e.outlier_amplitude_dps = 1.5;
  e.sinusoids = {{1.08, 0.07, 0.3}, {12.5, 0.01, -2.0}};
  e.bias_steps = {{600.0, 0.02}};
  const auto back = gyrod::recording::parseModelToml(gyrod::recording::modelToToml(m), "m.toml");
  const auto& b = back.axes[1].extra;
  EXPECT_EQ(b.temperature_coefficient_dps_per_c, e.temperature_coefficient_dps_per_c);
  EXPECT_EQ(b.temperature_reference_c, e.temperature_reference_c);
  EXPECT_EQ(b.gauss_markov_tau_s, e.gauss_markov_tau_s);
  EXPECT_EQ(b.gauss_markov_sigma_dps, e.gauss_markov_sigma_dps);
  EXPECT_EQ(b.outlier_count, e.outlier_count);
  EXPECT_EQ(b.outlier_amplitude_dps, e.outlier_amplitude_dps);
  ASSERT_EQ(b.sinusoids.size(), 2u);
  EXPECT_EQ(b.sinusoids[1].freq_hz, 12.5);
  EXPECT_EQ(b.sinusoids[1].phase_rad, -2.0);
  ASSERT_EQ(b.bias_steps.size(), 1u);
  EXPECT_EQ(b.bias_steps[0].size_dps, 0.02);
  EXPECT_TRUE(back.axes[0].extra.empty());
  // A model without extras writes no [x.extra] table (files stay as they were).
  EXPECT_EQ(gyrod::recording::modelToToml(gyrod::processing::SimulationModel{}).find("extra"), std::string::npos);
}

TEST(ModelTomlExtra, BadExtraKeysNameTheLine) {
  try {
    gyrod::recording::parseModelToml("[x]\narw_deg_per_sqrt_h = 1.0\n[x.extra]\nsinusoid = []\n", "m.toml");
    FAIL();
  } catch (const gyrod::recording::RecordingError& err) {
    EXPECT_NE(std::string(err.what()).find("m.toml:4"), std::string::npos) << err.what();
  }
  EXPECT_THROW(gyrod::recording::parseModelToml("[z.extra]\nsinusoids = [{freq_hz = -1.0}]\n", "m.toml"),
               gyrod::recording::RecordingError);
}
