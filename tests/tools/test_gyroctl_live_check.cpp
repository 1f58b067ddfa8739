// gyroctl live-check (docs/live-check.md) on recordings written here from a seeded simulated
// board at rest, 2 h at 50 Hz: a 12.5 Hz line of 0.1 × the white noise's per-sample σ
// (amplitude) starting at t = 3600 s on gy is named as a line on y within 10 min of data time,
// its centre within 1 %, in the text and in the JSON lines; the still column's moving samples
// are left out (a swing there names nothing); bad options and a recording without gz are one
// line and exit 64 and 65.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "processing/simulation/noise_simulator.hpp"
#include "tools/run_command.hpp"

using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

constexpr double kLiveCsvRate = 50.0;

// t,gx,gy,gz[,still] of a simulated board at rest (FS_SEL 0, ARW 0.3 °/√h, bias instability
// 10 °/h, rate random walk 5 °/h/√h), with `add` called on each sample's three rates.
template <typename Add>
std::filesystem::path writeBoard(const std::filesystem::path& dir, double duration_s, std::uint64_t seed, Add add,
                                 bool still_column = false) {
  gyrod::processing::SimulationModel m;
  m.rate_hz = kLiveCsvRate;
  m.fs_sel = 0;
  for (auto& a : m.axes) {
    a.terms.arw_deg_per_sqrt_h = 0.3;
    a.terms.bias_instability_deg_per_h = 10.0;
    a.terms.rrw_deg_per_h_sqrt_h = 5.0;
  }
  gyrod::processing::NoiseSimulator sim(m, duration_s, seed);
  const auto path = dir / "board.csv";
  std::FILE* f = std::fopen(path.c_str(), "w");
  std::fprintf(f, still_column ? "t,gx,gy,gz,still\n" : "t,gx,gy,gz\n");
  const auto n = static_cast<std::size_t>(duration_s * kLiveCsvRate);
  for (std::size_t i = 0; i < n; ++i) {
    const auto s = sim.next();
    std::array<double, 3> r = s.rate_dps;
    const double t = static_cast<double>(i) / kLiveCsvRate;
    const bool still = add(t, r);
    std::fprintf(f, "%.6f,%.9g,%.9g,%.9g", t, r[0], r[1], r[2]);
    if (still_column) std::fprintf(f, ",%d", still ? 1 : 0);
    std::fprintf(f, "\n");
  }
  std::fclose(f);
  return path;
}

// The white noise's per-sample σ of this model at 50 Hz: ARW 0.3 °/√h is N = 0.005 °/s/√Hz,
// and white rate noise has σ²(τ₀) = N²/τ₀ (IEEE 952).
const double kLiveCsvSigma = 0.3 / 60.0 * std::sqrt(kLiveCsvRate);

}  // namespace

TEST(GyroctlLiveCheck, ALineFromAnHourInIsNamedOnItsAxisWithin10Minutes) {
  ScratchDir d;
  const double amp = 0.1 * kLiveCsvSigma;
  const auto csv = writeBoard(d.path(), 7200.0, 61, [amp](double t, std::array<double, 3>& r) {
    if (t >= 3600.0) r[1] += amp * std::sin(2.0 * std::numbers::pi * 12.5 * t);
    return true;
  });
  auto r = runGyroctl("live-check " + csv.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("new   line on y: 12.5"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("24 intervals of 300 s examined at 50 Hz (6 the baseline)"), std::string::npos) << r.out;
  r = runGyroctl("live-check --json " + csv.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::istringstream lines(r.out);
  std::vector<nlohmann::json> effects;
  nlohmann::json summary;
  for (std::string line; std::getline(lines, line);) {
    const auto j = nlohmann::json::parse(line);
    if (j.at("class") == "EFFECT")
      effects.push_back(j);
    else
      summary = j;
  }
  ASSERT_EQ(effects.size(), 1u) << r.out;
  const auto& e = effects[0];
  EXPECT_EQ(e.at("state"), "new");
  EXPECT_EQ(e.at("effect"), "line");
  EXPECT_EQ(e.at("axis"), "y");
  EXPECT_NEAR(e.at("params").at("centre_hz").get<double>(), 12.5, 0.125) << e;
  EXPECT_GT(e.at("t").get<double>(), 3600.0) << e;
  EXPECT_LE(e.at("t").get<double>(), 3600.0 + 600.0) << e;
  EXPECT_LE(e.at("onset_t_95").at(0).get<double>(), 3600.0) << e;
  EXPECT_GE(e.at("onset_t_95").at(1).get<double>(), 3600.0) << e;
  EXPECT_EQ(summary.at("class"), "SUMMARY");
  EXPECT_EQ(summary.at("intervals"), 24);
  EXPECT_EQ(summary.at("current").size(), 1u);
}

// 10 min of swinging (1 °/s at 2 Hz on gx) marked moving in the still column: left out, so
// nothing is named, and the summary counts at least those samples.
TEST(GyroctlLiveCheck, MovingSamplesAreLeftOut) {
  ScratchDir d;
  const auto csv = writeBoard(
      d.path(), 3600.0, 62,
      [](double t, std::array<double, 3>& r) {
        const bool moving = t >= 2400.0 && t < 3000.0;
        if (moving) r[0] += std::sin(2.0 * std::numbers::pi * 2.0 * t);
        return !moving;
      },
      true);
  const auto r = runGyroctl("live-check --json " + csv.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto summary = nlohmann::json::parse(r.out.substr(r.out.rfind('{')));
  EXPECT_EQ(r.out.find("EFFECT"), std::string::npos) << r.out;
  EXPECT_GE(summary.at("samples_left_out").get<double>(), 600.0 * kLiveCsvRate) << r.out;
  EXPECT_EQ(summary.at("intervals"), 10);  // 3600 s less the 600 s moving, in 300 s intervals
}

TEST(GyroctlLiveCheck, BadOptionsAndAFileWithoutGzAreOneLine) {
  ScratchDir d;
  const auto csv = writeBoard(d.path(), 100.0, 63, [](double, std::array<double, 3>&) { return true; });
  auto r = runGyroctl("live-check --interval 5 " + csv.string(), d.path());
  EXPECT_EQ(r.exit_status, 64) << r.err;
  EXPECT_NE(r.err.find("--interval must hold at least 512 samples"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  r = runGyroctl("live-check --baseline 60 " + csv.string(), d.path());
  EXPECT_EQ(r.exit_status, 64) << r.err;
  EXPECT_NE(r.err.find("--baseline"), std::string::npos) << r.err;
  const auto no_gz = d.path() / "no-gz.csv";
  std::FILE* f = std::fopen(no_gz.c_str(), "w");
  std::fprintf(f, "t,gx,gy\n0,0.1,0.2\n0.02,0.1,0.2\n0.04,0.1,0.2\n");
  std::fclose(f);
  r = runGyroctl("live-check " + no_gz.string(), d.path());
  EXPECT_EQ(r.exit_status, 65) << r.err;
  EXPECT_NE(r.err.find("'gz' is missing"), std::string::npos) << r.err;
}
