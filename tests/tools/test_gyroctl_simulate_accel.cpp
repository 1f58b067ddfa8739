// gyroctl simulate --accel: the ax,ay,az columns (after temp, before any truth), gravity tilted
// by the motion, the gyro columns the same text with or without --accel, and the errors.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  for (std::string f; std::getline(in, f, ',');) out.push_back(f);
  return out;
}

}  // namespace

TEST(GyroctlSimulateAccel, AddsAxAyAzAndLeavesTheGyroColumnsAsTheyWere) {
  ScratchDir d;
  const std::string plain = (d.path() / "plain.csv").string(), accel = (d.path() / "accel.csv").string();
  const std::string common = "simulate --duration 20 --rate 50 --dlpf 4 --fs-sel 0 --arw 0.9 --bias-instability 8 ";
  ASSERT_EQ(runGyroctl(common + "-o " + plain, d.path()).exit_status, 0);
  const auto r = runGyroctl(common + "--accel --accel-bias 0.01,0,-0.02 -o " + accel, d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto a = lines(readWholeFile(plain)), b = lines(readWholeFile(accel));
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a[0], "t,gx,gy,gz,temp");
  EXPECT_EQ(b[0], "t,gx,gy,gz,temp,ax,ay,az");
  for (std::size_t i = 1; i < a.size(); ++i) {
    const auto x = fields(a[i]), y = fields(b[i]);
    ASSERT_EQ(y.size(), 8u);
    for (std::size_t c = 0; c < 5; ++c) ASSERT_EQ(x[c], y[c]) << "line " << i;
    // Level, at ±2 g (16384 LSB per g): whole LSBs near (0.01, 0, 0.98) g.
    EXPECT_NEAR(std::stod(y[5]), 0.01, 0.03);
    EXPECT_NEAR(std::stod(y[7]), 0.98, 0.03);
    const double counts = std::stod(y[6]) * 16384.0;
    EXPECT_EQ(counts, static_cast<double>(static_cast<long long>(counts))) << y[6];
  }
}

TEST(GyroctlSimulateAccel, WithMotionGravityFollowsTheTurnAndTheTruthComesLast) {
  ScratchDir d;
  const std::string out = (d.path() / "turn.csv").string();
  const auto r = runGyroctl(
      "simulate --duration 14 --rate 50 --accel --motion constant:axis=x,rate=9,start=2,duration=10 -o " + out,
      d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto rows = lines(readWholeFile(out));
  EXPECT_EQ(rows[0], "t,gx,gy,gz,temp,ax,ay,az,wx,wy,wz");
  double ay_before = 0.0, ay_after = 0.0, az_after = 0.0;
  int n_before = 0, n_after = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const auto f = fields(rows[i]);
    ASSERT_EQ(f.size(), 11u);
    const double t = std::stod(f[0]);
    if (t < 2.0) {
      ay_before += std::stod(f[6]);
      ++n_before;
    } else if (t >= 12.5) {
      ay_after += std::stod(f[6]);
      az_after += std::stod(f[7]);
      ++n_after;
    }
  }
  // Default accel noise 400 µg/√Hz: 2.8 mg per sample, the means within 1 mg.
  EXPECT_NEAR(ay_before / n_before, 0.0, 2e-3);
  EXPECT_NEAR(ay_after / n_after, 1.0, 2e-3);
  EXPECT_NEAR(az_after / n_after, 0.0, 2e-3);
}

TEST(GyroctlSimulateAccel, BadAccelOptionsAreRefused) {
  ScratchDir d;
  const std::string out = (d.path() / "x.csv").string();
  const auto range = runGyroctl("simulate --duration 1 --accel --accel-range-g 3 -o " + out, d.path());
  EXPECT_NE(range.exit_status, 0);
  EXPECT_NE(range.err.find("--accel-range-g must be 2, 4, 8 or 16, got 3"), std::string::npos) << range.err;
  const auto without = runGyroctl("simulate --duration 1 --accel-noise-density 1e-3 -o " + out, d.path());
  EXPECT_NE(without.exit_status, 0);
  EXPECT_NE(without.err.find("--accel"), std::string::npos) << without.err;
}
