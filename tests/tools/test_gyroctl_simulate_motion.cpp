// gyroctl simulate --motion: the truth columns, each profile kind and the CSV form seen
// through the sensor, the chip's DLPF and full-scale saturation acting on the motion, the
// noise untouched by it, and the errors (exit 2, one line naming the problem).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

struct Table {
  std::string header;
  std::vector<std::vector<double>> rows;
};

Table parseCsv(const std::string& text) {
  Table t;
  std::istringstream in(text);
  std::getline(in, t.header);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::istringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) row.push_back(std::stod(field));
    t.rows.push_back(row);
  }
  return t;
}

// Columns of a simulated file with motion.
enum Column { T = 0, GX, GY, GZ, TEMP, WX, WY, WZ };

// No noise, no DLPF, no quantisation: every gyro column is exactly its truth.
Table simulatePure(const ScratchDir& d, const std::string& motion, double duration_s, double rate_hz = 100.0) {
  const std::string out = (d.path() / "pure.csv").string();
  std::ostringstream args;
  args << "simulate --duration " << duration_s << " --rate " << rate_hz << " --motion '" << motion << "' -o " << out;
  const auto r = runGyroctl(args.str(), d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  return parseCsv(readWholeFile(out));
}

void expectGyroIsTruth(const Table& t) {
  ASSERT_FALSE(t.rows.empty());
  for (const auto& row : t.rows) {
    ASSERT_EQ(row.size(), 8u);
    for (int a = 0; a < 3; ++a) ASSERT_EQ(row[GX + a], row[WX + a]) << "t = " << row[T];
  }
}

}  // namespace

TEST(GyroctlSimulateMotion, StepAddsTruthColumns) {
  ScratchDir d;
  const Table t = simulatePure(d, "step:axis=z,at=5,rate=10", 8);
  EXPECT_EQ(t.header, "t,gx,gy,gz,temp,wx,wy,wz");
  ASSERT_EQ(t.rows.size(), 800u);
  expectGyroIsTruth(t);
  for (const auto& row : t.rows) {
    EXPECT_EQ(row[WZ], row[T] < 5.0 ? 0.0 : 10.0) << row[T];
    EXPECT_EQ(row[WX], 0.0);
    EXPECT_EQ(row[WY], 0.0);
  }
}

TEST(GyroctlSimulateMotion, SineConstantAndTheirSum) {
  ScratchDir d;
  const Table t = simulatePure(d, "sine:axis=x,freq=1,amp=20 + constant:axis=y,rate=0.5,start=1", 3);
  expectGyroIsTruth(t);
  for (const auto& row : t.rows) {
    EXPECT_NEAR(row[WX], 20.0 * std::sin(2.0 * std::numbers::pi * row[T]), 1e-9) << row[T];
    EXPECT_EQ(row[WY], row[T] < 1.0 ? 0.0 : 0.5) << row[T];
  }
}

TEST(GyroctlSimulateMotion, TurnsTurnTheirAngle) {
  ScratchDir d;
  // still 1 s, turn 4 s, still 1 s, turn 4 s, still 1 s
  const Table t = simulatePure(d, "turns:axis=z,count=2,rate=90,still=1", 12);
  expectGyroIsTruth(t);
  double angle = 0.0;
  for (const auto& row : t.rows) angle += row[GZ] / 100.0;
  EXPECT_NEAR(angle, 720.0, 0.9);  // one sample's worth of rotation
  EXPECT_EQ(t.rows[50][WZ], 0.0);
  EXPECT_EQ(t.rows[300][WZ], 90.0);
  EXPECT_EQ(t.rows[550][WZ], 0.0);
}

TEST(GyroctlSimulateMotion, CsvOfTrueRatesIsInterpolated) {
  ScratchDir d;
  const auto csv = d.write("motion.csv", "# ramp up on y, then hold\nt,wy\n0,0\n2,20\n");
  const Table t = simulatePure(d, csv.string(), 4, 10);
  expectGyroIsTruth(t);
  ASSERT_EQ(t.rows.size(), 40u);
  EXPECT_NEAR(t.rows[5][WY], 5.0, 1e-12);
  EXPECT_NEAR(t.rows[15][WY], 15.0, 1e-12);
  EXPECT_EQ(t.rows[30][WY], 20.0);
}

TEST(GyroctlSimulateMotion, FullScaleSaturatesTheGyroNotTheTruth) {
  ScratchDir d;
  const std::string out = (d.path() / "sat.csv").string();
  const auto r = runGyroctl(
      "simulate --arw 0.5 --duration 2 --rate 50 --dlpf 4 --fs-sel 0 --motion constant:axis=z,rate=300 -o " + out,
      d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const Table t = parseCsv(readWholeFile(out));
  ASSERT_EQ(t.rows.size(), 100u);
  for (const auto& row : t.rows) {
    EXPECT_EQ(row[WZ], 300.0);
    EXPECT_NEAR(row[GZ], 32767.0 / 131.0, 1e-9);  // the ±250 °/s range's top code
    EXPECT_LT(std::abs(row[GX]), 5.0);            // the other axes only see their noise
  }
}

TEST(GyroctlSimulateMotion, DlpfDelaysAStep) {
  ScratchDir d;
  const std::string out = (d.path() / "dlpf.csv").string();
  const auto r =
      runGyroctl("simulate --duration 4 --rate 50 --dlpf 4 --motion step:axis=x,at=2,rate=10 -o " + out, d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const Table t = parseCsv(readWholeFile(out));
  ASSERT_EQ(t.rows.size(), 200u);
  EXPECT_EQ(t.rows[100][WX], 10.0);  // t = 2 s
  EXPECT_LT(t.rows[100][GX], 9.0);   // the 20 Hz DLPF has not caught up yet
  EXPECT_NEAR(t.rows[199][GX], 10.0, 0.01);
}

TEST(GyroctlSimulateMotion, NoiseIsTheSameWithOrWithoutMotion) {
  ScratchDir d;
  const std::string still = (d.path() / "still.csv").string(), moved = (d.path() / "moved.csv").string();
  const std::string args = "simulate --arw 1 --bias-instability 0.5 --duration 3 --rate 50 --dlpf 4 --fs-sel 0 ";
  ASSERT_EQ(runGyroctl(args + "-o " + still, d.path()).exit_status, 0);
  ASSERT_EQ(runGyroctl(args + "--motion constant:axis=x,rate=0 -o " + moved, d.path()).exit_status, 0);
  const Table a = parseCsv(readWholeFile(still)), b = parseCsv(readWholeFile(moved));
  EXPECT_EQ(a.header, "t,gx,gy,gz,temp");
  ASSERT_EQ(a.rows.size(), b.rows.size());
  for (std::size_t i = 0; i < a.rows.size(); ++i)
    for (int c = T; c <= TEMP; ++c) ASSERT_EQ(a.rows[i][c], b.rows[i][c]) << "row " << i << " column " << c;
}

TEST(GyroctlSimulateMotion, BadSpecsExitTwoNamingTheProblem) {
  ScratchDir d;
  const std::string out = (d.path() / "o.csv").string();
  const auto bad = d.write("bad.csv", "t,wz\n0,1\n0,2\n");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"stpe:axis=z,at=5,rate=10", "unknown profile 'stpe'"},
      {"step:axis=z,at=5,rat=10", "step: unknown key 'rat'"},
      {"sine:axis=x,freq=0,amp=20", "sine: freq must be finite and > 0, got 0"},
      {"turns:axis=z,count=10,still=2", "turns: missing key 'rate'"},
      {"constant:axis=q,rate=1", "axis must be x, y or z, got 'q'"},
      {bad.string(), bad.string() + ":3: column 't' is not strictly increasing"},
      {(d.path() / "none.csv").string(), "none.csv: cannot open"},
  };
  for (const auto& [spec, message] : cases) {
    const auto r = runGyroctl("simulate --arw 1 --duration 1 --motion '" + spec + "' -o " + out, d.path());
    // A spec that is not one is a bad option value (EX_USAGE); a motion file that cannot be
    // used is EX_DATAERR, one that is missing EX_NOINPUT.
    const int expected = spec.find(".csv") == std::string::npos       ? 64
                         : spec.find("none.csv") != std::string::npos ? 66
                                                                      : 65;
    EXPECT_EQ(r.exit_status, expected) << spec;
    EXPECT_NE(r.err.find(message), std::string::npos) << spec << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << spec;
  }
}

TEST(GyroctlSimulateMotion, OfflineToolsReadTheFileWithItsTruth) {
  ScratchDir d;
  const std::string sim = (d.path() / "sim.csv").string(), filtered = (d.path() / "f.csv").string();
  ASSERT_EQ(runGyroctl("simulate --arw 1 --duration 20 --rate 50 --dlpf 4 --fs-sel 0 "
                       "--motion 'sine:axis=x,freq=1,amp=20' -o " +
                           sim,
                       d.path())
                .exit_status,
            0);
  auto r = runGyroctl("filter " + sim + " -o " + filtered, d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const Table f = parseCsv(readWholeFile(filtered));
  EXPECT_EQ(f.header, "t,gx,gx_mean,gx_kalman,gy,gy_mean,gy_kalman,gz,gz_mean,gz_kalman");
  EXPECT_EQ(f.rows.size(), 1000u);
  r = runGyroctl("analyze " + sim, d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
}
