// gyroctl filter on a record that is mostly motion: the Kalman it identifies describes the
// motion, and filter says so (once, on stderr) and points to --model; a still record gets no
// such warning. The output columns are the same either way.
#include <gtest/gtest.h>

#include <string>

#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

TEST(GyroctlFilterMoving, AMostlyMovingRecordIsWarnedAboutAndAStillOneIsNot) {
  ScratchDir d;
  const auto moving = d.path() / "moving.csv";
  const auto still = d.path() / "still.csv";
  ASSERT_EQ(runGyroctl(
                "simulate --arw 0.95 --duration 60 --seed 3 --motion 'sine:axis=x,freq=1,amp=20' -o " + moving.string(),
                d.path())
                .exit_status,
            0);
  ASSERT_EQ(
      runGyroctl("simulate --arw 0.95 --bias-instability 0.6 --duration 60 --seed 4 -o " + still.string(), d.path())
          .exit_status,
      0);
  const auto out = d.path() / "out.csv";
  const auto m = runGyroctl("filter " + moving.string() + " -o " + out.string(), d.path());
  ASSERT_EQ(m.exit_status, 0) << m.err;
  EXPECT_NE(
      m.err.find("gyroctl filter: warning: " + moving.string() + ": the still detector finds the record moving in"),
      std::string::npos)
      << m.err;
  EXPECT_NE(m.err.find("--model sensor.toml"), std::string::npos) << m.err;
  const std::string header = readWholeFile(out).substr(0, readWholeFile(out).find('\n'));
  EXPECT_EQ(header, "t,gx,gx_mean,gx_kalman,gy,gy_mean,gy_kalman,gz,gz_mean,gz_kalman");
  const auto s = runGyroctl("filter " + still.string() + " -o " + out.string(), d.path());
  ASSERT_EQ(s.exit_status, 0) << s.err;
  EXPECT_EQ(s.err.find("warning"), std::string::npos) << s.err;
  // With A, Q and R all given nothing is identified, so there is nothing to warn about.
  const auto given = runGyroctl(
      "filter " + moving.string() + " -o " + out.string() + " --ar-phi 0.5 --kalman-q 1 --kalman-r 1", d.path());
  ASSERT_EQ(given.exit_status, 0) << given.err;
  EXPECT_EQ(given.err.find("warning"), std::string::npos) << given.err;
}
