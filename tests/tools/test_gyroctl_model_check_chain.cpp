// gyroctl model-check and the acquisition chain: taken from the recording's '# device' header
// (as gyrod writes it), from --dlpf/--fs-sel, or estimated; said in the text and the JSON; a
// rate the DLPF cannot make and a bad header value are errors naming them.
#include <gtest/gtest.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "formats/recording_header.hpp"
#include "processing/model_check/hidden_effect_generator.hpp"
#include "tools/run_command.hpp"

using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

std::string recordingCsv(const gyrod::processing::GeneratedRecording& g, const std::string& header) {
  std::string out = header + "t,gx,gy,gz,temp\n";
  char line[256];
  for (std::size_t i = 0; i < g.t.size(); ++i) {
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g,%.17g\n", g.t[i], g.axes[0][i], g.axes[1][i],
                  g.axes[2][i], g.temp[i]);
    out += line;
  }
  return out;
}

gyrod::processing::GeneratedRecording dlpf4Recording() {
  gyrod::processing::HiddenEffectGenerator gen(21);
  gen.dlpf_cfg = 4;
  return gen.generate(300.0, 50.0, {});
}

}  // namespace

TEST(GyroctlModelCheckChain, TheHeaderGivesTheChainAndCleanDataHasNoEffect) {
  ScratchDir d;
  const std::string header = "# gyrod recording, opened 2026-01-01T00:00:00Z\n# " +
                             gyrod::recording::acquisitionHeaderComment(4, 0, 50.0, 19) + "\n";
  const auto csv = d.write("rec.csv", recordingCsv(dlpf4Recording(), header));
  const auto r = runGyroctl("model-check " + csv.string() + " --json --seed 2 --threads 2", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto doc = nlohmann::json::parse(r.out);
  const auto& chain = doc.at("acquisition_chain");
  EXPECT_EQ(chain.at("dlpf_cfg"), 4);
  EXPECT_EQ(chain.at("fs_sel"), 0);
  EXPECT_NE(chain.at("dlpf_source").get<std::string>().find("rec.csv:2"), std::string::npos) << chain.dump();
  for (const char* axis : {"gx", "gy", "gz"}) {
    EXPECT_TRUE(doc.at("axes").at(axis).at("effects").empty()) << axis << ": " << doc.at("axes").at(axis).dump();
    EXPECT_FALSE(doc.at("axes").at(axis).at("extension").at("judged").get<bool>());
    EXPECT_TRUE(doc.at("axes").at(axis).at("gain").at("innovation_var_base_held_out").is_number());
  }
}

TEST(GyroctlModelCheckChain, WithoutAHeaderTheDlpfIsEstimatedAndSaidSo) {
  ScratchDir d;
  const auto csv = d.write("rec.csv", recordingCsv(dlpf4Recording(), ""));
  const auto r = runGyroctl("model-check " + csv.string() + " --replicas 8 --threads 2", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("acquisition chain: DLPF_CFG 4 (20 Hz) [estimated from the short-tau roll-off"),
            std::string::npos)
      << r.out;
  const auto given = runGyroctl("model-check " + csv.string() + " --replicas 8 --dlpf 6 --fs-sel 1", d.path());
  ASSERT_EQ(given.exit_status, 0) << given.err;
  EXPECT_NE(given.out.find("DLPF_CFG 6 (5 Hz) [--dlpf]; FS_SEL 1"), std::string::npos) << given.out;
}

TEST(GyroctlModelCheckChain, ImpossibleRatesAndBadHeadersAreErrors) {
  ScratchDir d;
  const auto g = dlpf4Recording();
  std::string no_t = "gx\n";
  for (double v : g.axes[0]) no_t += std::to_string(v) + "\n";
  const auto csv = d.write("rec.csv", no_t);
  auto r = runGyroctl("model-check " + csv.string() + " --rate 30 --dlpf 4", d.path());
  EXPECT_EQ(r.exit_status, 65);  // EX_DATAERR: no chain makes that rate
  EXPECT_NE(r.err.find("30 Hz cannot be made with DLPF_CFG 4"), std::string::npos) << r.err;
  const auto bad = d.write("bad.csv", recordingCsv(dlpf4Recording(), "# device dlpf_cfg=9\n"));
  r = runGyroctl("model-check " + bad.string(), d.path());
  EXPECT_EQ(r.exit_status, 65);  // EX_DATAERR
  EXPECT_NE(r.err.find("bad.csv:1: device header: dlpf_cfg='9'"), std::string::npos) << r.err;
  r = runGyroctl("model-check " + csv.string() + " --dlpf 7", d.path());
  EXPECT_EQ(r.exit_status, 64);  // EX_USAGE
}
