// gyroctl simulate --model with a narrowband line in the file's [y.extra]: the CSV's gy
// spectrum shows the line at its centre and with its width, gx and gz do not; a --rate too low
// for the line is refused naming it.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "processing/simulation/narrowband_line.hpp"
#include "tools/run_command.hpp"
#include "welch_psd.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

constexpr double kSimulateLineRate = 100.0, kSimulateLineDuration = 1200.0;
constexpr double kSimulateLineCentre = 31.4, kSimulateLineWidth = 0.3, kSimulateLineRms = 0.05;

// The three rate columns of a `gyroctl simulate` CSV (t,gx,gy,gz,temp).
std::array<std::vector<double>, 3> simulateLineRateColumns(const std::string& text) {
  std::array<std::vector<double>, 3> columns;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    double t = 0.0, gx = 0.0, gy = 0.0, gz = 0.0;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf", &t, &gx, &gy, &gz) != 4) break;
    columns[0].push_back(gx);
    columns[1].push_back(gy);
    columns[2].push_back(gz);
  }
  return columns;
}

}  // namespace

TEST(GyroctlSimulateLines, ModelFileLineShowsInTheSpectrum) {
  ScratchDir d;
  char model[512];
  std::snprintf(model, sizeof model,
                "rate_hz = %g\nfs_sel = 0\n[x]\narw_deg_per_sqrt_h = 0.3\n[y]\narw_deg_per_sqrt_h = 0.3\n"
                "[y.extra]\nnarrowband_lines = [{centre_hz = %g, width_hz = %g, rms_dps = %g}]\n"
                "[z]\narw_deg_per_sqrt_h = 0.3\n",
                kSimulateLineRate, kSimulateLineCentre, kSimulateLineWidth, kSimulateLineRms);
  const auto model_path = d.write("line.toml", model);
  const auto csv = d.path() / "line.csv";
  const auto r = runGyroctl("simulate --model " + model_path.string() + " --duration " +
                                std::to_string(kSimulateLineDuration) + " --seed 31 -o " + csv.string(),
                            d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto columns = simulateLineRateColumns(readWholeFile(csv));
  ASSERT_EQ(columns[1].size(), static_cast<std::size_t>(kSimulateLineRate * kSimulateLineDuration));

  // 4096-sample segments (0.024 Hz bins), 57 of them: a bin scatters by ~14 %, so the midpoint
  // of the half-power points by ~0.015 Hz and their distance by ~15 %.
  const auto gy = gyrod::test::welchPsd(columns[1], kSimulateLineRate, 4096);
  const auto peak = gyrod::test::spectralPeakNear(gy, kSimulateLineCentre, 2.0);
  EXPECT_NEAR(peak.centreHz(), kSimulateLineCentre, 0.05);
  EXPECT_GT(peak.widthHz(), kSimulateLineWidth / 1.5);
  EXPECT_LT(peak.widthHz(), kSimulateLineWidth * 1.5);
  // gx and gz at the same frequency: the white floor (0.3 °/√h: 2·(0.3/60)² = 5e-5 (°/s)²/Hz,
  // the quantisation's 1/131 °/s LSB adding 1e-7), far below the line's 2·rms²/(π·width) = 5e-3.
  for (const std::size_t axis : {std::size_t{0}, std::size_t{2}}) {
    const auto other = gyrod::test::welchPsd(columns[axis], kSimulateLineRate, 4096);
    const auto bin = static_cast<std::size_t>(kSimulateLineCentre / other.bin_hz + 0.5);
    EXPECT_LT(other.psd[bin] * 20.0, peak.level) << "axis " << axis;
  }
  // The line's power: the gy spectrum over ±3 widths less the white floor (the mean density
  // over 5–25 Hz) against the line's own density over that band (≈ 89 % of rms²; a Lorentzian
  // holds (2/π)·atan(6) of its power there). The band power scatters by ~3 % (the line's
  // sample variance over 1200 s, its ~1 s correlation time) and the floor adds little:
  // within 12 %, four of those.
  const gyrod::processing::NarrowbandLineRecursion recursion = gyrod::processing::narrowbandLineRecursion(
      {kSimulateLineCentre, kSimulateLineWidth, kSimulateLineRms}, kSimulateLineRate);
  double band = 0.0, expected_band = 0.0, floor_density = 0.0;
  std::size_t floor_bins = 0, band_bins = 0;
  for (std::size_t k = 0; k < gy.psd.size(); ++k) {
    const double f = static_cast<double>(k) * gy.bin_hz;
    if (std::fabs(f - kSimulateLineCentre) <= 3.0 * kSimulateLineWidth) {
      band += gy.psd[k] * gy.bin_hz;
      expected_band += gyrod::processing::narrowbandLinePsd(recursion, kSimulateLineRate, f) * gy.bin_hz;
      ++band_bins;
    }
    if (f > 5.0 && f < 25.0) {
      floor_density += gy.psd[k];
      ++floor_bins;
    }
  }
  floor_density /= static_cast<double>(floor_bins);
  const double line_power = band - floor_density * gy.bin_hz * static_cast<double>(band_bins);
  EXPECT_NEAR(line_power / expected_band, 1.0, 0.12);
  EXPECT_NEAR(expected_band / (kSimulateLineRms * kSimulateLineRms), 0.89, 0.02);
  RecordProperty("line_power_over_expected", std::to_string(line_power / expected_band));
  RecordProperty("line_centre_hz", std::to_string(peak.centreHz()));
  RecordProperty("line_width_hz", std::to_string(peak.widthHz()));
}

TEST(GyroctlSimulateLines, RateBelowTwiceALinesCentreIsRefusedNamingTheLine) {
  // The file's rate admits the line; a --rate that puts it above the Nyquist frequency is a
  // usage error naming the line, and nothing is written.
  ScratchDir d;
  const auto model_path =
      d.write("line.toml", "rate_hz = 100\n[z.extra]\nnarrowband_lines = [{centre_hz = 31.4, width_hz = 0.3}]\n");
  const auto csv = d.path() / "line.csv";
  const auto r =
      runGyroctl("simulate --model " + model_path.string() + " --rate 50 --duration 1 -o " + csv.string(), d.path());
  EXPECT_EQ(r.exit_status, 64) << r.err;  // EX_USAGE, as every model the command line makes impossible
  EXPECT_NE(r.err.find("axis z: extra.narrowband_line[0].centre_hz must be in (0, rate/2 = 25), got 31.4"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(csv));
}
