// gyroctl attitude: a simulated board (gyroctl simulate --accel) that rests, turns once about z
// and rests again: with and without a model file the heading change is the true turn and roll
// and pitch stay level, and the motion errors it learned are named; the columns and the error
// statuses.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "run_command.hpp"

using namespace gyrod::test;

namespace {

// The columns of a CSV with a header line, by name.
struct AttitudeCsv {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;
  const std::vector<double>& column(const std::string& name) const {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == name) return columns[i];
    throw std::runtime_error("no column " + name);
  }
};

AttitudeCsv readAttitudeCsv(const std::string& text) {
  AttitudeCsv csv;
  std::istringstream in(text);
  std::string line, field;
  std::getline(in, line);
  std::istringstream header(line);
  while (std::getline(header, field, ',')) csv.names.push_back(field);
  csv.columns.resize(csv.names.size());
  while (std::getline(in, line)) {
    std::istringstream row(line);
    for (std::size_t i = 0; i < csv.names.size() && std::getline(row, field, ','); ++i)
      csv.columns[i].push_back(std::stod(field));
  }
  return csv;
}

}  // namespace

TEST(GyroctlAttitude, AOneTurnAboutZReadsAsItsTrueHeadingChangeWithAndWithoutAModel) {
  ScratchDir d;
  // 10 s still, 12 s at 30 °/s about z (a full turn), 8 s still, at 100 Hz; the gyro biased.
  const auto motion = d.write("motion.csv", "t,wx,wy,wz\n0,0,0,0\n10,0,0,0\n10.01,0,0,30\n22,0,0,30\n22.01,0,0,0\n");
  const auto still = d.path() / "still.csv";
  const auto model = d.path() / "model.toml";
  const auto rec = d.path() / "turn.csv";
  const std::string sensor = " --arw 0.5 --bias-instability 10 --rate 100 --accel";
  ASSERT_EQ(runGyroctl("simulate" + sensor + " --duration 600 --seed 3 -o " + still.string(), d.path()).exit_status, 0);
  const auto a = runGyroctl("analyze " + still.string() + " --write-model " + model.string(), d.path());
  ASSERT_EQ(a.exit_status, 0) << a.err;
  const auto s = runGyroctl(
      "simulate" + sensor + " --duration 30 --seed 4 --motion " + motion.string() + " -o " + rec.string(), d.path());
  ASSERT_EQ(s.exit_status, 0) << s.err;
  for (const std::string& with : {std::string(), " --model " + model.string()}) {
    const auto out = d.path() / "attitude.csv";
    const auto r = runGyroctl("attitude " + rec.string() + " -o " + out.string() + with, d.path());
    ASSERT_EQ(r.exit_status, 0) << r.err;
    // What motion taught it, named on stderr: each of the learned motion errors.
    for (const char* term :
         {"learned in motion: gyro sensitivity error x ", "; cross-axis xy ", "; accel lever arm ", "; accel delay "})
      EXPECT_NE(r.err.find(term), std::string::npos) << term << " in " << r.err;
    const AttitudeCsv csv = readAttitudeCsv(readWholeFile(out));
    // The recording's columns first, then the estimator's.
    ASSERT_GE(csv.names.size(), 16u);
    EXPECT_EQ(csv.names[0], "t");
    EXPECT_EQ(csv.names[1], "gx");
    const std::vector<std::string> tail(csv.names.end() - 9, csv.names.end());
    EXPECT_EQ(tail, (std::vector<std::string>{"qw", "qx", "qy", "qz", "roll", "pitch", "heading", "inclination_std",
                                              "heading_std"}));
    const auto& heading = csv.column("heading");
    ASSERT_EQ(heading.size(), 3000u);
    EXPECT_NEAR(heading[0], 0.0, 1e-12);
    // Over the turn the heading goes once round: its unwrapped change is the true +360°.
    double unwrapped = 0.0;
    for (std::size_t i = 1000; i < heading.size(); ++i) unwrapped += std::remainder(heading[i] - heading[i - 1], 360.0);
    EXPECT_NEAR(unwrapped, 360.0, 0.5) << "model:" << with;
    for (std::size_t i = 0; i < heading.size(); ++i) {
      EXPECT_NEAR(csv.column("roll")[i], 0.0, 0.5) << i;
      EXPECT_NEAR(csv.column("pitch")[i], 0.0, 0.5) << i;
    }
  }
}

TEST(GyroctlAttitude, ARecordingWithoutTheAccelColumnsIsADataError) {
  ScratchDir d;
  const auto in = d.write("gyro.csv", "t,gx,gy,gz\n0,0,0,0\n0.01,0,0,0\n0.02,0,0,0\n");
  const auto r = runGyroctl("attitude " + in.string() + " -o " + (d.path() / "out.csv").string(), d.path());
  EXPECT_EQ(r.exit_status, 65);
  EXPECT_NE(r.err.find("gyro.csv: attitude needs the columns gx,gy,gz and ax,ay,az; 'ax' is missing"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(runGyroctl("attitude " + in.string(), d.path()).exit_status, 64);
  EXPECT_EQ(runGyroctl("attitude " + (d.path() / "missing.csv").string() + " -o x.csv", d.path()).exit_status, 66);
}
