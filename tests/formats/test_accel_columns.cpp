// The accelerometer columns ax,ay,az [g] of a recording, as the reader and the ImuCalibration
// importer carry them.
#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>
#include <string>

#include "formats/imucal_recording.hpp"
#include "formats/recording_csv.hpp"

using namespace gyrod::recording;

namespace {

Recording parse(const std::string& text) {
  std::istringstream in(text);
  return parseRecordingCsv(in, "rec.csv");
}

std::string errorOf(const std::string& text) {
  try {
    parse(text);
  } catch (const RecordingError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(AccelColumns, AreReadIntoAccelGInAxisOrderWhateverTheirFileOrder) {
  const auto rec = parse("t,az,gx,ax,ay\n0,1.0,0.5,0.01,-0.02\n0.01,0.99,0.25,0.03,-0.04\n");
  EXPECT_EQ(rec.axis_names, (std::vector<std::string>{"gx"}));
  EXPECT_EQ(rec.accel_g[0], (std::vector<double>{0.01, 0.03}));
  EXPECT_EQ(rec.accel_g[1], (std::vector<double>{-0.02, -0.04}));
  EXPECT_EQ(rec.accel_g[2], (std::vector<double>{1.0, 0.99}));
  EXPECT_EQ(kAccelColumns[0], "ax");
}

TEST(AccelColumns, AreEmptyWhenAbsentAndASubsetIsFine) {
  const auto none = parse("t,gx\n0,1\n");
  for (const auto& a : none.accel_g) EXPECT_TRUE(a.empty());
  const auto some = parse("gx,az\n1,0.98\n");
  EXPECT_TRUE(some.accel_g[0].empty());
  EXPECT_EQ(some.accel_g[2], (std::vector<double>{0.98}));
}

TEST(AccelColumns, BadValuesNameFileLineAndColumn) {
  EXPECT_EQ(errorOf("t,gx,ax\n0,1,0.5\n0.01,1,abc\n"), "rec.csv:3: column 'ax': 'abc' is not a number");
  EXPECT_EQ(errorOf("t,gx,ay\n0,1,nan\n"), "rec.csv:2: column 'ay': non-finite value 'nan'");
  EXPECT_EQ(errorOf("t,gx,az,az\n0,1,1,1\n"), "rec.csv:1: column 'az' appears twice");
}

TEST(ImucalImport, CarriesTheAccelerometerInGAtTheChosenFullScale) {
  const std::string text = "Fs,100\nLogging Type,1\nax,ay,az,gx,gy,gz\n16384,-8192,4096,131,0,-262\n";
  std::istringstream in2g(text);
  const auto at2g = convertImucal(in2g, "raw.txt", 0, 0);
  EXPECT_EQ(at2g.csv, "t,gx,gy,gz,ax,ay,az\n0,1,0,-2,1,-0.5,0.25\n");
  EXPECT_EQ(at2g.accel_columns, 3u);
  EXPECT_EQ(at2g.lsb_per_g, 16384.0);
  std::istringstream in16g(text);
  EXPECT_EQ(convertImucal(in16g, "raw.txt", 0, 3).csv, "t,gx,gy,gz,ax,ay,az\n0,1,0,-2,8,-4,2\n");
  std::istringstream bad(text);
  EXPECT_THROW(convertImucal(bad, "raw.txt", 0, 4), std::invalid_argument);
}

TEST(ImucalImport, BadAccelCountsNameFileLineAndColumn) {
  const auto errorFor = [](const std::string& sample) {
    std::istringstream in("Fs,100\nax,ay,az,gx,gy,gz\n" + sample + "\n");
    try {
      convertImucal(in, "raw.txt", 0);
    } catch (const RecordingError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(errorFor("1,2.5,3,4,5,6"), "raw.txt:3: column 'ay': '2.5' is not an integer count");
  EXPECT_EQ(errorFor("40000,2,3,4,5,6"), "raw.txt:3: column 'ax': 40000 is outside the 16-bit range");
}

TEST(ImucalImport, AGyroOnlyLoggerFileStaysGyroOnly) {
  std::istringstream in("Fs,50\ngx,gy,gz\n131,262,0\n");
  const auto c = convertImucal(in, "raw.txt", 0);
  EXPECT_EQ(c.csv, "t,gx,gy,gz\n0,1,2,0\n");
  EXPECT_EQ(c.accel_columns, 0u);
}

// Found by fuzz_import_imucal: a header naming a sensor column twice was converted into a
// recording that the reader (rightly) refuses; the importer now refuses it, naming the line.
TEST(ImucalImport, ASensorColumnNamedTwiceIsRefused) {
  for (const std::string header : {"ax,ay,az,gx,gy,ay", "gx,gy,gx"}) {
    std::istringstream in("Fs,100\n" + header + "\n1,2,3,4,5,6\n");
    try {
      convertImucal(in, "raw.txt", 0);
      ADD_FAILURE() << header << ": accepted";
    } catch (const RecordingError& e) {
      const std::string name = header.substr(header.rfind(',') + 1);
      EXPECT_EQ(std::string(e.what()), "raw.txt:2: column '" + name + "' appears twice") << header;
    }
  }
}
