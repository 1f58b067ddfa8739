// What gyroctl does with a recording's accelerometer columns (ax, ay, az; docs/motion.md):
// `filter --model` gives them to the still detector (the paper's columns do not change),
// `model-check` says on stderr that it does not check them, and a file with accel but no gyro
// column is refused with exit 65 naming the file and the missing columns.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "run_command.hpp"

using namespace gyrod::test;

namespace {

constexpr int kDataError = 65;  // tools/gyroctl/exit_codes.hpp

// A still chip at 50 Hz (white gyro noise at the model's ARW, 0.95 °/√h → 0.11 °/s per sample),
// with accel columns when `accel` is "steady" (gravity on z plus 3 mg noise) or "tilting"
// (ax ramping by 1 mg a sample, far above what the accel still test passes).
std::string recording(std::size_t n, const std::string& accel) {
  std::mt19937_64 rng(12);
  std::normal_distribution<double> gyro(0.0, 0.112), acc(0.0, 0.003);
  std::ostringstream s;
  s.precision(17);
  s << "t,gx,gy,gz" << (accel.empty() ? "" : ",ax,ay,az") << "\n";
  for (std::size_t i = 0; i < n; ++i) {
    s << static_cast<double>(i) / 50.0 << ',' << gyro(rng) << ',' << gyro(rng) << ',' << gyro(rng);
    const double ax = acc(rng), ay = acc(rng), az = 1.0 + acc(rng);  // drawn either way: same gyro values
    if (accel == "steady") s << ',' << ax << ',' << ay << ',' << az;
    if (accel == "tilting") s << ',' << ax + 0.001 * static_cast<double>(i) << ',' << ay << ',' << az;
    s << '\n';
  }
  return s.str();
}

std::string sensorModel() {
  std::ostringstream m;
  m << "rate_hz = 50\n";
  for (const char* axis : {"x", "y", "z"})
    m << "[" << axis << "]\nquantization_urad = 0.1663\narw_deg_per_sqrt_h = 0.95164\n"
      << "bias_instability_deg_per_h = 0.60565\nrrw_deg_per_h_sqrt_h = 0.07759\nbias_dps = 0\n"
      << "[" << axis << ".calibration]\nbias_std_dps = 0.02\ntemperature_reference_c = 25.0\n";
  return m.str();
}

struct FilterOutput {
  std::vector<std::string> paper;  // t and gx,gx_mean,gx_kalman per axis, as text (pinned)
  std::size_t still = 0;
  std::string err;
};

FilterOutput filterWithModel(const ScratchDir& d, const std::string& name, const std::string& csv) {
  const auto in = d.write(name + ".csv", csv);
  const auto model = d.write("model.toml", sensorModel());
  const auto out = d.path() / (name + "-filtered.csv");
  const auto r = runGyroctl("filter " + in.string() + " -o " + out.string() + " --model " + model.string() +
                                " --bias=0,0,0 --ar-phi 0.9 --kalman-q 0.0001 --kalman-r 0.01",
                            d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  FilterOutput f;
  f.err = r.err;
  std::ifstream file(out);
  std::string line;
  std::getline(file, line);
  EXPECT_EQ(line,
            "t,gx,gx_mean,gx_kalman,gy,gy_mean,gy_kalman,gz,gz_mean,gz_kalman,gx_rate,gx_bias,gy_rate,gy_bias,"
            "gz_rate,gz_bias,still");
  while (std::getline(file, line)) {
    std::size_t cut = 0;
    for (int commas = 0; commas < 10; ++commas) cut = line.find(',', cut) + 1;
    f.paper.push_back(line.substr(0, cut));
    f.still += line.back() == '1' ? 1 : 0;
  }
  return f;
}

}  // namespace

TEST(GyroctlAccelColumns, FilterGivesTheAccelToTheStillDetectorAndLeavesThePaperColumnsAlone) {
  ScratchDir d;
  const std::size_t n = 3000;  // 60 s
  const FilterOutput gyro_only = filterWithModel(d, "gyro", recording(n, ""));
  const FilterOutput steady = filterWithModel(d, "steady", recording(n, "steady"));
  const FilterOutput tilting = filterWithModel(d, "tilting", recording(n, "tilting"));
  ASSERT_EQ(gyro_only.paper.size(), n);
  EXPECT_EQ(steady.paper, gyro_only.paper);
  EXPECT_EQ(tilting.paper, gyro_only.paper);
  EXPECT_GT(gyro_only.still, n / 2) << gyro_only.err;
  EXPECT_GT(steady.still, n / 2) << steady.err;
  EXPECT_EQ(tilting.still, 0u) << "the gyro cannot see this tilt, the accel can: " << tilting.err;
  EXPECT_NE(gyro_only.err.find("no ax, ay, az columns: the still detector judged by the gyro alone"), std::string::npos)
      << gyro_only.err;
  EXPECT_NE(steady.err.find("the still detector used the ax, ay, az columns"), std::string::npos) << steady.err;
}

TEST(GyroctlAccelColumns, ModelCheckSaysItDoesNotCheckTheAccelColumns) {
  ScratchDir d;
  const auto with_accel = d.write("with-accel.csv", recording(100, "steady"));
  const auto r = runGyroctl("model-check " + with_accel.string(), d.path());
  // 100 samples are too few to check: the note comes first, on reading the file.
  EXPECT_EQ(r.exit_status, kDataError) << r.err;
  EXPECT_NE(r.err.find(with_accel.string() + ": the accelerometer columns (ax, ay, az) are not checked"),
            std::string::npos)
      << r.err;
  const auto without = d.write("without-accel.csv", recording(100, ""));
  const auto r2 = runGyroctl("model-check " + without.string(), d.path());
  EXPECT_EQ(r2.err.find("accelerometer"), std::string::npos) << r2.err;
}

TEST(GyroctlAccelColumns, AFileWithAccelButNoGyroColumnIsRefusedNamingFileAndColumns) {
  ScratchDir d;
  std::string csv = "t,ax,ay,az\n";
  for (int i = 0; i < 200; ++i) csv += std::to_string(i / 50.0) + ",0.001,-0.002,1.0\n";
  const auto file = d.write("accel-only.csv", csv);
  for (const std::string& command : {"filter " + file.string() + " -o " + (d.path() / "out.csv").string(),
                                     "model-check " + file.string(), "analyze " + file.string()}) {
    const auto r = runGyroctl(command, d.path());
    EXPECT_EQ(r.exit_status, kDataError) << command << "\n" << r.err;
    EXPECT_NE(r.err.find(file.string() + ":1"), std::string::npos) << command << "\n" << r.err;
    EXPECT_NE(r.err.find("no gyro column"), std::string::npos) << command << "\n" << r.err;
    EXPECT_NE(r.err.find("gx,gy,gz"), std::string::npos) << command << "\n" << r.err;
  }
}
