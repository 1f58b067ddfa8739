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
