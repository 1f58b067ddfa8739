// gyroctl simulate --warm-up DELTA_C,TAU_S and --temperature-coefficient: the die temperature
// follows start + DELTA·(1 − e^{−t/TAU}), the bias follows it through the coupling k·(T − T_ref)
// on the noise-free curve, a warm-up without a coupling leaves the gyro columns bit for bit as
// they were, and bad values exit 2 naming them.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

std::vector<std::vector<double>> simulate(const ScratchDir& d, const std::string& options, const std::string& name) {
  const std::string out = (d.path() / name).string();
  const auto r = runGyroctl("simulate --duration 600 --seed 3 " + options + " -o " + out, d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  std::istringstream in(readWholeFile(out));
  std::string line;
  std::getline(in, line);
  std::vector<std::vector<double>> rows;
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

TEST(GyroctlSimulateWarmUp, TemperatureRisesAndTheBiasFollowsThroughTheCoupling) {
  ScratchDir d;
  // No noise terms, no DLPF, no quantisation: the gyro is the coupling alone.
  const auto rows = simulate(d, "--rate 10 --warm-up 15,120 --temperature-coefficient 0.03,-0.02,0.01", "w.csv");
  ASSERT_EQ(rows.size(), 6000u);
  const double k[3] = {0.03, -0.02, 0.01};
  for (const auto& row : rows) {
    const double t = row[0];
    const double temperature = 25.0 + 15.0 * (1.0 - std::exp(-t / 120.0));
    ASSERT_NEAR(row[4], temperature, 1e-9) << "t = " << t;
    for (int a = 0; a < 3; ++a) ASSERT_NEAR(row[1 + a], k[a] * (temperature - 25.0), 1e-12) << "t = " << t;
  }
  EXPECT_NEAR(rows.back()[1], 0.03 * 15.0, 0.03 * 15.0 * 0.01);  // 15 °C later: 15·k
}

TEST(GyroctlSimulateWarmUp, WithoutACouplingTheGyroColumnsAreBitForBitTheSame) {
  ScratchDir d;
  const std::string noise = "--arw 0.95 --bias-instability 0.6 --rrw 0.08 --dlpf 4 --rate 50 --fs-sel 0";
  const auto plain = simulate(d, noise, "plain.csv");
  const auto warm = simulate(d, noise + " --warm-up 15,300", "warm.csv");
  ASSERT_EQ(plain.size(), warm.size());
  for (std::size_t i = 0; i < plain.size(); ++i) {
    for (int c = 0; c < 4; ++c) ASSERT_EQ(plain[i][c], warm[i][c]) << "row " << i << " column " << c;
    ASSERT_EQ(plain[i][4], plain[0][4]);  // no warm-up: one temperature (25 °C on the 1/340 grid)
  }
  EXPECT_NEAR(warm.back()[4], 25.0 + 15.0 * (1.0 - std::exp(-599.98 / 300.0)), 0.01);
}

TEST(GyroctlSimulateWarmUp, BadValuesExitTwoNamingThem) {
  ScratchDir d;
  const std::string out = " -o " + (d.path() / "bad.csv").string();
  struct Case {
    std::string options, expected;
  };
  for (const Case& c : {Case{"--warm-up 15", "expected DELTA_C,TAU_S"}, Case{"--warm-up 15,0", "TAU_S must be > 0"},
                        Case{"--warm-up 15,abc", "'abc' is not a finite number"},
                        Case{"--temperature-coefficient 0.1,0.2", "--temperature-coefficient: expected one value"}}) {
    const auto r = runGyroctl("simulate --duration 10 " + c.options + out, d.path());
    EXPECT_EQ(r.exit_status, 64) << c.options;  // EX_USAGE
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.options << ": " << r.err;
  }
}
