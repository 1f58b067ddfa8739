// gyroctl simulate: the CSV it writes, reproducibility from the seed, the model file and
// the errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {
std::vector<std::vector<double>> parseCsv(const std::string& text, std::string& header) {
  std::istringstream in(text);
  std::getline(in, header);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::istringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) row.push_back(std::stod(field));
    rows.push_back(row);
  }
  return rows;
}
}  // namespace

TEST(GyroctlSimulate, WritesTimeThreeAxesAndTemperature) {
  ScratchDir d;
  const std::string out = (d.path() / "sim.csv").string();
  const auto r = runGyroctl(
      "simulate --arw 0.95 --bias-instability 0.6 --duration 4 --rate 50 --dlpf 4 --fs-sel 0 -o " + out, d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::string header;
  const auto rows = parseCsv(readWholeFile(out), header);
  EXPECT_EQ(header, "t,gx,gy,gz,temp");
  ASSERT_EQ(rows.size(), 200u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 5u);
    EXPECT_EQ(rows[i][0], static_cast<double>(i) / 50.0);
    for (int k = 1; k <= 3; ++k) EXPECT_NEAR(rows[i][k] * 131.0, std::round(rows[i][k] * 131.0), 1e-9);
  }
}

TEST(GyroctlSimulate, SameSeedSameFileOtherSeedOtherFile) {
  ScratchDir d;
  const std::string a = (d.path() / "a.csv").string(), b = (d.path() / "b.csv").string(),
                    c = (d.path() / "c.csv").string();
  const std::string args = "simulate --arw 1 --rrw 0.1 --duration 10 --rate 100 ";
  ASSERT_EQ(runGyroctl(args + "--seed 7 -o " + a, d.path()).exit_status, 0);
  ASSERT_EQ(runGyroctl(args + "--seed 7 -o " + b, d.path()).exit_status, 0);
  ASSERT_EQ(runGyroctl(args + "--seed 8 -o " + c, d.path()).exit_status, 0);
  EXPECT_EQ(readWholeFile(a), readWholeFile(b));
  EXPECT_NE(readWholeFile(a), readWholeFile(c));
}

TEST(GyroctlSimulate, ModelFileWithCommandLineOverride) {
  ScratchDir d;
  const std::string model = (d.path() / "m.toml").string(), out = (d.path() / "o.csv").string();
  std::ofstream(model) << "rate_hz = 10\n[y]\nbias_dps = 2.5\n";
  auto r = runGyroctl("simulate --model " + model + " --duration 3 -o " + out, d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::string header;
  auto rows = parseCsv(readWholeFile(out), header);
  ASSERT_EQ(rows.size(), 30u);
  EXPECT_EQ(rows[5][2], 2.5);  // pure mode: the bias exactly
  r = runGyroctl("simulate --model " + model + " --duration 3 --rate 20 -o " + out, d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  rows = parseCsv(readWholeFile(out), header);
  EXPECT_EQ(rows.size(), 60u);
}

TEST(GyroctlSimulate, ErrorsAreOneLineAndLeaveNoOutput) {
  ScratchDir d;
  const std::string out = (d.path() / "o.csv").string(), model = (d.path() / "bad.toml").string();
  std::ofstream(model) << "rate_hz = 50\n[x]\narw = 1\n";
  auto r = runGyroctl("simulate --model " + model + " --duration 1 -o " + out, d.path());
  EXPECT_EQ(r.exit_status, 65);  // EX_DATAERR: a bad model file
  EXPECT_NE(r.err.find(model + ":3: unknown key 'arw' in [x]"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  r = runGyroctl("simulate --arw 1 --duration 1 --rate 300 --dlpf 3 -o " + out, d.path());
  EXPECT_EQ(r.exit_status, 64);  // EX_USAGE
  EXPECT_NE(r.err.find("rate_hz 300 is not possible with DLPF_CFG 3"), std::string::npos) << r.err;
  r = runGyroctl("simulate --arw -1 --duration 1 -o " + out, d.path());
  EXPECT_EQ(r.exit_status, 64);
  EXPECT_NE(r.err.find("arw_deg_per_sqrt_h must be finite and >= 0, got -1"), std::string::npos) << r.err;
  r = runGyroctl("simulate --model " + model + " --arw 1 --duration 1 -o " + out, d.path());
  EXPECT_EQ(r.exit_status, 64);  // --model excludes the term options
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out + ".tmp-gyroctl"));
}
