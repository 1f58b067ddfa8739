// A recording as gyrod's recorder writes it (every column, GAP and DROPPED lines, page padding)
// reads cleanly with numpy's genfromtxt(names=True, comments='#'), pandas' read_csv(comment='#')
// and allantools: tests/python/check_recording_readers.py checks the names and every value with
// Debian's /usr/bin/python3, against the values pushed here.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "daemon/recorder.hpp"
#include "formats/recording_format.hpp"

using namespace gyrod::daemon;
using gyrod::recording::SampleValues;
namespace fs = std::filesystem;

namespace {

const fs::path kSourceDir = fs::path(GYROD_TEST_DATA_DIR).parent_path().parent_path();

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A value as the expected file holds it: every digit, "nan" for an empty field.
std::string exact(double v) {
  if (std::isnan(v)) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The `time` value a reader gets: the file's µs text, parsed.
double recordedTime(std::int64_t wall_ns) {
  char buf[64];
  const auto end =
      std::to_chars(buf, buf + sizeof buf, static_cast<double>(wall_ns) * 1e-9, std::chars_format::fixed, 6).ptr;
  return std::strtod(std::string(buf, end).c_str(), nullptr);
}

}  // namespace

TEST(RecordingReaders, NumpyAndPandasReadARecordingGyrodWrote) {
  const fs::path python = "/usr/bin/python3";
  if (!fs::exists(python)) GTEST_SKIP() << "no " << python;
  char tmpl[] = "/tmp/gyrod-readers-test-XXXXXX";
  const fs::path dir = ::mkdtemp(tmpl);

  RecorderOptions o;
  o.path = (dir / "gyro.csv").string();
  o.flush_interval_s = 3600.0;  // only flush() and stop() write
  o.ring_capacity = 256;        // small: pushing more between flushes drops (DROPPED lines)
  o.header_comments = {"device mock, rate_hz 50"};
  o.columns.time = true;
  o.columns.rate = true;
  std::ostringstream expected;
  expected << "t,gx,gy,gz,temp,time,ax,ay,az,gx_rate,gy_rate,gz_rate,gx_bias,gy_bias,gz_bias,still\n";
  std::mt19937_64 rng(12);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::string file;
  {
    Recorder rec(o);
    file = rec.currentFile();
    for (int i = 0; i < 3000; ++i) {
      if (i == 1000) rec.pushGap(i, i * 0.02, 7, "fifo_overflow");
      SampleValues v;
      v.t_s = i * 0.02;
      v.gx_dps = noise(rng) * 0.05;
      v.gy_dps = noise(rng) * 1e-7;
      v.gz_dps = noise(rng) * 250.0;
      v.temp_c = 25.0 + noise(rng);
      v.wall_ns = 1'795'000'000'000'000'000 + std::int64_t{20'000'000} * i + 1234;
      v.accel_g = {noise(rng) * 0.01, noise(rng) * 0.01, 1.0 + noise(rng) * 0.01};
      if (i >= 100) {  // before: the start-up bias estimation, no rate yet
        v.bias_dps = {-3.34, 1.09, -0.5};
        for (int a = 0; a < 3; ++a) v.rate_dps[a] = (a == 0 ? v.gx_dps : a == 1 ? v.gy_dps : v.gz_dps) - v.bias_dps[a];
        v.still = static_cast<std::int8_t>(i % 3 == 0);
      }
      if (rec.pushSample(v)) {
        expected << exact(v.t_s) << ',' << exact(v.gx_dps) << ',' << exact(v.gy_dps) << ',' << exact(v.gz_dps) << ','
                 << exact(v.temp_c) << ',' << exact(recordedTime(v.wall_ns));
        for (double x : v.accel_g) expected << ',' << exact(x);
        for (double x : v.rate_dps) expected << ',' << exact(x);
        for (double x : v.bias_dps) expected << ',' << exact(x);
        expected << ',' << (v.still < 0 ? "nan" : v.still ? "1" : "0") << '\n';
      }
      if (i % 400 == 399) rec.flush();  // 400 pushed between flushes, 256 fit: the rest dropped
    }
    rec.stop();
    ASSERT_GT(rec.stats().dropped, 0u);
  }
  const std::string text = readText(file);
  ASSERT_NE(text.find("\n# GAP seq=1000 "), std::string::npos);
  ASSERT_NE(text.find("\n# DROPPED count="), std::string::npos);
  ASSERT_NE(text.find("\n#        "), std::string::npos) << "no padding line: the test would not test it";
  const fs::path expected_path = dir / "expected.csv";
  std::ofstream(expected_path) << expected.str();

  const fs::path out = dir / "python.out";
  const std::string cmd = python.string() + " -B -s '" +
                          (kSourceDir / "tests/python/check_recording_readers.py").string() + "' '" + file + "' '" +
                          expected_path.string() + "' >'" + out.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  const std::string output = readText(out);
  fs::remove_all(dir);
  ASSERT_TRUE(WIFEXITED(status)) << output;
  if (WEXITSTATUS(status) == 77) GTEST_SKIP() << output;
  EXPECT_EQ(WEXITSTATUS(status), 0) << output;
  std::cout << output;  // which readers ran, and which were skipped and why
}
