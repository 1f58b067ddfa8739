// gyroctl import --columns: a foreign recording mapped column by column onto gyrod's CSV,
// checked against the shipped real records and against hand-made files of known values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

// A CSV with a header line: each column's values by name.
std::map<std::string, std::vector<double>> importedColumnsByName(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(in, line)) {
    std::stringstream fields(line);
    std::size_t c = 0;
    for (std::string field; std::getline(fields, field, ',') && c < names.size(); ++c)
      columns[names[c]].push_back(std::stod(field));
  }
  return columns;
}

const std::string kImucalRecord = std::string(GYROD_TEST_DATA_DIR) + "/mpu6050-arduino-100hz/imu_static_test.csv";
const std::string kSensorFusionRecord =
    std::string(GYROD_TEST_DATA_DIR) + "/mpu6050-sensor-fusion-set1/unmoved-x-pointing-forward.csv";

}  // namespace

// The logger's raw counts, mapped by hand (its 4 preamble lines skipped by the header search),
// give the very numbers the imucal format reader gives.
TEST(GyroctlImportColumns, RawCountsOfTheRealImucalRecordMatchTheImucalReader) {
  ScratchDir d;
  const auto known = d.path() / "known.csv";
  const auto mapped = d.path() / "mapped.csv";
  ASSERT_EQ(runGyroctl("import " + kImucalRecord + " -o " + known.string(), d.path()).exit_status, 0);
  const auto r = runGyroctl("import " + kImucalRecord +
                                " --columns gx=gx,gy=gy,gz=gz,ax=ax,ay=ay,az=az --rate 100 --gyro-unit lsb"
                                " --accel-unit lsb -o " +
                                mapped.string(),
                            d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.err.find("imported 9986 samples at 100 Hz"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("header on line 5"), std::string::npos) << r.err;
  const auto a = importedColumnsByName(readWholeFile(known));
  const auto b = importedColumnsByName(readWholeFile(mapped));
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, values] : a) {
    ASSERT_EQ(b.count(name), 1u) << name;
    ASSERT_EQ(b.at(name).size(), values.size()) << name;
    for (std::size_t i = 0; i < values.size(); ++i) ASSERT_EQ(b.at(name)[i], values[i]) << name << " sample " << i;
  }
}

// The file: other names, a sample counter, host time stamps, ';' between fields and
// the gyro in rad/s. The import gives back the real record it was made from, and analyze reads it.
TEST(GyroctlImportColumns, AForeignLayoutOfARealRecordComesBackAsGyrodsCsv) {
  ScratchDir d;
  const auto original = importedColumnsByName(readWholeFile(kSensorFusionRecord));
  const auto& t = original.at("t");
  std::string foreign = "sample;t_host_s;gx_rads;gy_rads;gz_rads;ax_g;ay_g;az_g;temp_C\n";
  constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;
  char line[512];
  for (std::size_t i = 0; i < t.size(); ++i) {
    std::snprintf(line, sizeof line, "%zu;%.17g;%.17g;%.17g;%.17g;%.17g;%.17g;%.17g;%.17g\n", i, t[i],
                  original.at("gx")[i] * kRadPerDeg, original.at("gy")[i] * kRadPerDeg,
                  original.at("gz")[i] * kRadPerDeg, original.at("ax")[i], original.at("ay")[i], original.at("az")[i],
                  original.at("temp")[i]);
    foreign += line;
  }
  const auto in = d.write("foreign.csv", foreign);
  const auto out = d.path() / "out.csv";
  const auto r = runGyroctl("import " + in.string() +
                                " --columns gx=gx_rads,gy=gy_rads,gz=gz_rads,ax=ax_g,ay=ay_g,az=az_g,temp=temp_C"
                                " --time t_host_s --gyro-unit rad/s --delimiter ';' -o " +
                                out.string(),
                            d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string text = readWholeFile(out);
  EXPECT_EQ(text.substr(0, text.find('\n')), "t,gx,gy,gz,temp,ax,ay,az");
  const auto back = importedColumnsByName(text);
  for (const auto& [name, values] : original) {
    ASSERT_EQ(back.at(name).size(), values.size()) << name;
    for (std::size_t i = 0; i < values.size(); ++i)
      ASSERT_NEAR(back.at(name)[i], values[i], 1e-12 * (1.0 + std::abs(values[i]))) << name << " sample " << i;
  }
  const auto a = runGyroctl("analyze " + out.string() + " --axis gx", d.path());
  EXPECT_EQ(a.exit_status, 0) << a.err;
}

TEST(GyroctlImportColumns, UnitsAreConvertedToDegreesPerSecondAndG) {
  ScratchDir d;
  const auto in = d.write("u.tsv", "time\twx\tacc_z\n0\t1\t9.80665\n0.5\t-0.5\t19.6133\n");
  const auto out = d.path() / "u.csv";
  const auto r = runGyroctl("import " + in.string() +
                                " --columns gx=wx,az=acc_z --time time --gyro-unit rad/s --accel-unit m/s2"
                                " --delimiter tab -o " +
                                out.string(),
                            d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto c = importedColumnsByName(readWholeFile(out));
  EXPECT_NEAR(c.at("gx")[0], 57.29577951308232, 1e-12);
  EXPECT_NEAR(c.at("gx")[1], -28.64788975654116, 1e-12);
  EXPECT_NEAR(c.at("az")[0], 1.0, 1e-15);
  EXPECT_NEAR(c.at("az")[1], 2.0, 1e-15);
  EXPECT_NE(r.err.find("at 2 Hz"), std::string::npos) << r.err;
}

// Each mistake: one line naming the file, the line, the column and the value.
TEST(GyroctlImportColumns, MistakesAreOneLineNamingFileLineColumnAndValue) {
  ScratchDir d;
  const auto in = d.write("f.csv", "sample,t_host_s,gx_dps,gy_dps\n0,0,0.5,0.25\n1,0.01,abc,0.5\n");
  const auto out = (d.path() / "o.csv").string();
  const auto expectOneLine = [&](const std::string& args, const std::string& needle, int status) {
    const auto r = runGyroctl("import " + in.string() + " " + args + " -o " + out, d.path());
    EXPECT_EQ(r.exit_status, status) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
    EXPECT_EQ(r.err.find("gyroctl: "), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  };
  expectOneLine("--columns gx=gx_dps,gy=gy_dps --time t_host_s",
                in.string() + ":3: column 'gx_dps': 'abc' is not a number", 65);
  expectOneLine("--columns gx=gx_dsp --rate 100",
                in.string() +
                    ":1: no column 'gx_dsp' in the header; did you mean 'gx_dps'? (the header has "
                    "'sample,t_host_s,gx_dps,gy_dps')",
                65);
  expectOneLine("--columns gq=gx_dps --rate 100", "--columns: 'gq' is not a gyrod column; did you mean 'gx'?", 64);
  expectOneLine("--columns gx:gx_dps --rate 100", "--columns: 'gx:gx_dps' is not TARGET=COLUMN", 64);
  expectOneLine("--columns ax=gy_dps --rate 100", "no gyro column mapped", 64);
  expectOneLine("--columns gx=gx_dps", "give the time column (--time COLUMN) or the sample rate (--rate HZ)", 64);
  expectOneLine("--columns gx=gx_dps --rate 100 --gyro-unit dps", "--gyro-unit 'dps': known units are", 64);
  expectOneLine("--columns gx=gx_dps --rate 100 --format imucal", "--format imucal and --columns", 64);
  expectOneLine("--rate 100", "--rate applies to --columns only", 64);
  EXPECT_FALSE(std::ifstream(out).good());
}

// A header is the file's text: echoed quoted and escaped, so that it cannot act on a terminal.
TEST(GyroctlImportColumns, AHostileHeaderIsEchoedEscaped) {
  ScratchDir d;
  const auto in = d.write("h.csv", "gx\x1b,b\n1,2\n");
  const auto r = runGyroctl("import " + in.string() + " --columns gx=gx --rate 10 -o o.csv", d.path());
  EXPECT_EQ(r.exit_status, 65) << r.err;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("did you mean 'gx\\x1B'? (the header has 'gx\\x1B,b')"), std::string::npos) << r.err;
}
