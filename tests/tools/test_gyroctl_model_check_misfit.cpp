// gyroctl model-check's verdict agrees with its own tests (docs/model-check.md, "Misfit"): a
// narrow line whose phase wanders (not in the catalogue) on one axis of a clean generated
// record is not "the base model holds" in the text, the JSON or the report, and the misfit
// names the band holding the line; a clean axis of the same record holds, its misfit null.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "processing/base/portable_random.hpp"
#include "processing/model_check/hidden_effect_generator.hpp"
#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

constexpr double kLineHz = 7.3;

// A clean record (seed 201) with, on gy, amp·sin(φ_i), φ_i = φ_{i−1} + 2πf/rate + δ_i,
// δ_i ~ N(0, π·0.3 Hz/rate): a Lorentzian line 0.3 Hz wide, amp = the axis's sd.
std::string recordingWithWanderingLine() {
  const auto g = gyrod::processing::HiddenEffectGenerator(201).generate(240.0, 50.0, {});
  std::vector<double> gy = g.axes[1];
  double mean = 0.0, ss = 0.0;
  for (double v : gy) mean += v;
  mean /= static_cast<double>(gy.size());
  for (double v : gy) ss += (v - mean) * (v - mean);
  const double amp = std::sqrt(ss / static_cast<double>(gy.size()));
  gyrod::processing::NormalGenerator normal(201);
  const double s = std::sqrt(std::numbers::pi * 0.3 / g.rate_hz);
  double phase = 0.0;
  for (double& v : gy) {
    phase += 2.0 * std::numbers::pi * kLineHz / g.rate_hz + s * normal.next();
    v += amp * std::sin(phase);
  }
  std::string out = "t,gx,gy,gz,temp\n";
  char line[256];
  for (std::size_t i = 0; i < g.t.size(); ++i) {
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g,%.17g\n", g.t[i], g.axes[0][i], gy[i], g.axes[2][i],
                  g.temp[i]);
    out += line;
  }
  return out;
}

}  // namespace

TEST(GyroctlModelCheckMisfit, AWanderingLineIsNotCalledAFitAndIsPlaced) {
  ScratchDir d;
  const auto csv = d.write("rec.csv", recordingWithWanderingLine());
  const auto report = d.path() / "report";
  auto r = runGyroctl("model-check " + csv.string() + " --axis gy --threads 2 --report " + report.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(r.out.find("holds"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("model does not fit: held-out innovations not white (Ljung-Box p "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" % of the Allan curve in the 90 % band (< 90 %); misfit at tau "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" x white)"), std::string::npos) << r.out;
  const std::string md = readWholeFile(report / "report.md");
  EXPECT_EQ(md.find("holds"), std::string::npos) << md;
  EXPECT_NE(md.find("model does not fit: held-out innovations not white"), std::string::npos) << md;

  r = runGyroctl("model-check " + csv.string() + " --json --threads 2", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto doc = nlohmann::json::parse(r.out);
  const auto& m = doc.at("axes").at("gy").at("misfit");
  EXPECT_TRUE(m.at("whiteness_fails").get<bool>()) << m.dump();
  EXPECT_TRUE(m.at("band_fails").get<bool>()) << m.dump();
  EXPECT_LT(m.at("ljung_box_p_held_out").get<double>(), 0.01) << m.dump();
  EXPECT_LT(m.at("in_band").get<double>(), 0.9) << m.dump();
  EXPECT_LE(m.at("tau_lo_s").get<double>(), m.at("tau_hi_s").get<double>()) << m.dump();
  EXPECT_TRUE(m.at("adev_ratio").is_number()) << m.dump();
  EXPECT_LE(m.at("freq_lo_hz").get<double>(), kLineHz) << m.dump();
  EXPECT_GE(m.at("freq_hi_hz").get<double>(), kLineHz) << m.dump();
  EXPECT_GT(m.at("power_ratio").get<double>(), 2.0) << m.dump();
  // A clean axis of the same record: both tests pass, nothing to place.
  const auto& clean = doc.at("axes").at("gx");
  EXPECT_TRUE(clean.at("effects").empty()) << clean.dump();
  const auto& c = clean.at("misfit");
  EXPECT_FALSE(c.at("whiteness_fails").get<bool>()) << c.dump();
  EXPECT_FALSE(c.at("band_fails").get<bool>()) << c.dump();
  for (const char* key : {"tau_lo_s", "tau_hi_s", "adev_ratio", "freq_lo_hz", "freq_hi_hz", "power_ratio"})
    EXPECT_TRUE(c.at(key).is_null()) << key << ": " << c.dump();
  r = runGyroctl("model-check " + csv.string() + " --axis gx --threads 2", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("the base model holds: no effect"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("does not fit"), std::string::npos) << r.out;
}
