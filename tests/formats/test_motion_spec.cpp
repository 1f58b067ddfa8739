// Motion specs (formats/motion_spec.hpp): each built-in profile written as text against its
// factory, the sum, the CSV of true rates, and the errors naming the bad key, value or line.
#include "formats/motion_spec.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include "formats/recording_csv.hpp"

using gyrod::processing::AngularRate;
using gyrod::processing::MotionProfile;
using namespace gyrod::recording;

namespace {

std::string textError(const std::string& text) {
  try {
    parseMotionProfileText(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

void expectSameProfile(const MotionProfile& a, const MotionProfile& b) {
  for (double t = -1.0; t < 30.0; t += 0.0173) EXPECT_EQ(a.rateAt(t), b.rateAt(t)) << "t = " << t;
}

class MotionCsv : public ::testing::Test {
 protected:
  MotionCsv() {
    std::random_device rd;
    dir_ = std::filesystem::temp_directory_path() / ("gyrod-motion-" + std::to_string(rd()));
    std::filesystem::create_directories(dir_);
  }
  ~MotionCsv() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string write(const std::string& text) const {
    const auto p = (dir_ / "motion.csv").string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  std::string fileError(const std::string& text) const {
    const std::string path = write(text);
    try {
      readMotionCsv(path);
    } catch (const RecordingError& e) {
      return e.what();
    }
    return "(no error)";
  }

 private:
  std::filesystem::path dir_;
};

}  // namespace

TEST(MotionSpecText, EachProfileIsItsFactory) {
  expectSameProfile(parseMotionProfileText("step:axis=z,at=5,rate=10"), MotionProfile::step(2, 5.0, 10.0));
  expectSameProfile(parseMotionProfileText("sine:axis=x,freq=1,amp=20"), MotionProfile::sine(0, 1.0, 20.0));
  expectSameProfile(parseMotionProfileText("sine:axis=x,freq=0.5,amp=3,start=2,duration=4"),
                    MotionProfile::sine(0, 0.5, 3.0, 2.0, 4.0));
  expectSameProfile(parseMotionProfileText("constant:axis=y,rate=0.5"), MotionProfile::constant(1, 0.5));
  expectSameProfile(parseMotionProfileText("constant:axis=y,rate=-7,start=1,duration=2"),
                    MotionProfile::constant(1, -7.0, 1.0, 2.0));
  expectSameProfile(parseMotionProfileText("turns:axis=z,count=10,rate=90,still=2"),
                    MotionProfile::turns(2, 10.0, 90.0, 2.0));
  expectSameProfile(parseMotionProfileText("turns:axis=z,count=2,rate=-45,still=1,start=3"),
                    MotionProfile::turns(2, 2.0, -45.0, 1.0, 3.0));
}

TEST(MotionSpecText, SumWithPlusAndBlanks) {
  const MotionProfile mix = parseMotionProfileText(" step:axis=z, at=5, rate=10 + sine:axis=x,freq=1,amp=20 ");
  expectSameProfile(mix, MotionProfile::sum({MotionProfile::step(2, 5.0, 10.0), MotionProfile::sine(0, 1.0, 20.0)}));
  // A '+' inside a number is not a new profile.
  expectSameProfile(parseMotionProfileText("constant:axis=x,rate=+1e+1"), MotionProfile::constant(0, 10.0));
}

TEST(MotionSpecText, TellsProfilesFromPaths) {
  EXPECT_TRUE(isMotionProfileText("step:axis=z,at=1,rate=2"));
  EXPECT_TRUE(isMotionProfileText("stpe:axis=z"));  // a typo is reported as one, not as a missing file
  EXPECT_FALSE(isMotionProfileText("motion.csv"));
  EXPECT_FALSE(isMotionProfileText("/tmp/a:b.csv"));
  EXPECT_FALSE(isMotionProfileText("./step:1.csv"));
}

TEST(MotionSpecText, ErrorsEscapeAndBoundWhatTheyEcho) {
  // A value from a hostile config or command line reaches the terminal escaped and cut.
  EXPECT_EQ(textError("step:axis=z,at=5,rate=\x1b[2J"), "motion: step: rate must be a finite number, got '\\x1B[2J'");
  const std::string long_value(5000, '7');
  const std::string e = textError("step:axis=z,at=5,rate=" + long_value + "x");
  EXPECT_LT(e.size(), 200u) << e;
  EXPECT_NE(e.find("(5001 bytes)"), std::string::npos) << e;
}

TEST(MotionSpecText, ErrorsNameTheProfileKeyAndValue) {
  EXPECT_EQ(textError("stpe:axis=z,at=5,rate=10"),
            "motion: unknown profile 'stpe' (profiles: step, sine, constant, turns)");
  EXPECT_EQ(textError("step:axis=z,at=5,rat=10"), "motion: step: unknown key 'rat' (keys: axis, at, rate)");
  EXPECT_EQ(textError("step:axis=z,at=5"), "motion: step: missing key 'rate' (keys: axis, at, rate)");
  EXPECT_EQ(textError("step:axis=w,at=5,rate=1"), "motion: step: axis must be x, y or z, got 'w'");
  EXPECT_EQ(textError("step:axis=z,at=5,rate=ten"), "motion: step: rate must be a finite number, got 'ten'");
  EXPECT_EQ(textError("step:axis=z,at=5,rate=1,rate=2"), "motion: step: key 'rate' given twice");
  EXPECT_EQ(textError("step:axis=z,at,rate=1"), "motion: step: 'at' is not key=value (keys: axis, at, rate)");
  EXPECT_EQ(textError("sine:axis=x,freq=0,amp=1"), "motion: sine: freq must be finite and > 0, got 0");
  EXPECT_EQ(textError("sine:axis=x,freq=1,amp=-2"), "motion: sine: amp must be finite and >= 0, got -2");
  EXPECT_EQ(textError("turns:axis=z,count=1,rate=0"), "motion: turns: rate must be finite and not 0, got 0");
  EXPECT_EQ(textError("constant:axis=y,rate=1,duration=0"),
            "motion: constant: duration must be > 0 (or forever), got 0");
  EXPECT_NE(textError("").find("motion: empty spec"), std::string::npos);
  EXPECT_NE(textError("constant:axis=y,rate=1 + step:axis=q,at=1,rate=1").find("axis must be x, y or z, got 'q'"),
            std::string::npos);
}

TEST_F(MotionCsv, InterpolatesBetweenRowsAndMissingAxesAreZero) {
  const MotionProfile p = readMotionCsv(write("# a turn on z\n t , wz,wx\n0,0,1\n\n2,20,1\n4,20,-1\n"));
  EXPECT_EQ(p.rateAt(1.0), (AngularRate{1.0, 0.0, 10.0}));
  EXPECT_EQ(p.rateAt(3.0), (AngularRate{0.0, 0.0, 20.0}));
  EXPECT_EQ(p.rateAt(9.0), (AngularRate{-1.0, 0.0, 20.0}));
  EXPECT_EQ(motionFromSpec(write("t,wy\n0,3\n")).rateAt(5.0), (AngularRate{0.0, 3.0, 0.0}));
}

TEST_F(MotionCsv, ErrorsNameFileAndLine) {
  const std::string path = write("");
  EXPECT_EQ(fileError("t,wx,gz\n"), path + ":1: unknown column 'gz' (expected t and any of wx,wy,wz)");
  EXPECT_EQ(fileError("wx,wy\n0,1\n"), path + ":1: no column 't': the header needs t and any of wx,wy,wz");
  EXPECT_EQ(fileError("t\n0\n"), path + ":1: no rate column: the header needs t and any of wx,wy,wz");
  EXPECT_EQ(fileError("t,wx,wx\n"), path + ":1: column 'wx' appears twice");
  EXPECT_EQ(fileError("t,wx\n0,1\n# note\n1,abc\n"), path + ":4: column 'wx': 'abc' is not a number");
  EXPECT_EQ(fileError("t,wx\n0,1\n1,nan\n"), path + ":3: column 'wx': non-finite value 'nan'");
  EXPECT_EQ(fileError("t,wx\n0,1\n1,2,3\n"), path + ":3: expected 2 fields, found 3");
  EXPECT_EQ(fileError("t,wx\n0,1\n1,2\n1,3\n"), path + ":4: column 't' is not strictly increasing (t = 1 after 1)");
  EXPECT_EQ(fileError("# only a comment\n"), path + ": empty file: no header t,wx,wy,wz and no rows");
  EXPECT_EQ(fileError("\nt,wz\n"), path + ":2: no rows after the header");
  EXPECT_NE(fileError("t,wz\n").find(path + ":1: no rows"), std::string::npos);
}

TEST(MotionSpecFile, MissingFileIsNamed) {
  try {
    motionFromSpec("/nonexistent/motion.csv");
    FAIL() << "no error";
  } catch (const RecordingError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/motion.csv: cannot open", 0), 0u) << e.what();
  }
}

TEST_F(MotionCsv, RecordingReaderKeepsTheTruthColumnsApart) {
  const Recording rec = readRecordingCsv(write("t,gx,gy,gz,temp,wx,wy,wz\n0,1,2,3,25,4,5,6\n0.02,1,2,3,25,7,8,9\n"));
  EXPECT_EQ(rec.axis_names, (std::vector<std::string>{"gx", "gy", "gz"}));
  EXPECT_EQ(rec.true_rate[0], (std::vector<double>{4.0, 7.0}));
  EXPECT_EQ(rec.true_rate[2], (std::vector<double>{6.0, 9.0}));
  EXPECT_TRUE(readRecordingCsv(write("t,gz\n0,1\n")).true_rate[0].empty());
  EXPECT_THROW(readRecordingCsv(write("t,wx\n0,1\n")), RecordingError);  // the truth alone is no recording
}
