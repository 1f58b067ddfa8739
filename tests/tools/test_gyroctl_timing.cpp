// analyze, filter and model-check on recordings whose timing is not regular: a 4 s gap,
// 5–50 ms of jitter on the time stamps, "# GAP" and "# DROPPED" records. A warning on stderr
// with the figures, a "timing" object in --json, and --strict-timing makes it exit 2 naming
// FILE:LINE. The README's list of the object's fields is the code's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tools/run_command.hpp"

using gyrod::test::CommandResult;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;
using nlohmann::json;

namespace {

// t,gx,gy of white noise; `time` gives the time stamp of sample i, `extra` lines go before sample i.
template <class TimeOf>
std::string recording(std::size_t n, unsigned seed, TimeOf time,
                      const std::vector<std::pair<std::size_t, std::string>>& extra = {}) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::string s = "t,gx,gy\n";
  char buf[96];
  for (std::size_t i = 0; i < n; ++i) {
    for (const auto& [before, line] : extra)
      if (before == i) s += line + "\n";
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g\n", time(i), noise(rng), noise(rng));
    s += buf;
  }
  return s;
}

constexpr std::size_t kSamples = 3000;  // enough for model-check (2000)
constexpr double kRateHz = 50.0;

std::string withFourSecondGap() {
  // 4 s missing between sample 999 (t = 19.98 s, line 1001) and sample 1000 (line 1002).
  return recording(kSamples, 1,
                   [](std::size_t i) { return static_cast<double>(i) / kRateHz + (i >= 1000 ? 4.0 : 0.0); });
}

// Each stamp 5–50 ms late, at 10 Hz (so no interval reaches 1.5 × 100 ms).
std::string withJitter(std::vector<double>* times = nullptr) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> delay(0.005, 0.050);
  std::vector<double> t(kSamples);
  for (std::size_t i = 0; i < kSamples; ++i) t[i] = static_cast<double>(i) * 0.1 + delay(rng);
  if (times) *times = t;
  return recording(kSamples, 2, [&t](std::size_t i) { return t[i]; });
}

std::string withLostRecords() {
  return recording(
      kSamples, 3, [](std::size_t i) { return static_cast<double>(i) / kRateHz; },
      {{500, "# DROPPED count=7 reason=ring_full"}, {900, "# GAP seq=900 t=18 count=4 reason=fifo_overflow"}});
}

std::string regular() {
  return recording(kSamples, 4, [](std::size_t i) { return static_cast<double>(i) / kRateHz; });
}

json timingOf(const CommandResult& r) {
  EXPECT_EQ(r.exit_status, 0) << r.err;
  const json doc = json::parse(r.out);
  EXPECT_TRUE(doc.contains("timing")) << r.out.substr(0, 300);
  return doc.value("timing", json::object());
}

std::size_t countLines(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

}  // namespace

TEST(GyroctlTiming, RegularRecordingIsSilentAndSaysSoInJson) {
  ScratchDir d;
  const auto f = d.write("regular.csv", regular());
  const auto r = runGyroctl("analyze " + f.string() + " --json --strict-timing", d.path());
  const json t = timingOf(r);
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_TRUE(t["regular"].get<bool>());
  EXPECT_TRUE(t["t_column"].get<bool>());
  EXPECT_NEAR(t["nominal_dt_s"].get<double>(), 0.02, 1e-12);
  EXPECT_EQ(t["nominal_from"], "median");
  EXPECT_EQ(t["gaps"], 0);
  EXPECT_EQ(t["irregular_intervals"], 0);
  EXPECT_EQ(t["intervals"], kSamples - 1);
  EXPECT_TRUE(t["largest_gap"].is_null());
  EXPECT_TRUE(t["first_offending"].is_null());
  EXPECT_EQ(t["lost_records"], 0);
}

TEST(GyroctlTiming, FourSecondGapIsWarnedReportedAndStrictlyRefused) {
  ScratchDir d;
  const auto f = d.write("gap.csv", withFourSecondGap());
  const auto text = runGyroctl("analyze " + f.string(), d.path());
  ASSERT_EQ(text.exit_status, 0) << text.err;
  EXPECT_NE(text.err.find("gyroctl: warning: " + f.string() +
                          ": 1 gap in column 't' (intervals over 1.5 x the nominal 0.02 s): the largest 4.02 s after "
                          "t = 19.98 s (line 1002); about 200 samples missing"),
            std::string::npos)
      << text.err;
  EXPECT_NE(text.err.find("--strict-timing makes this an error"), std::string::npos) << text.err;
  EXPECT_NE(text.out.find("== gx =="), std::string::npos);  // the analysis still runs

  const json t = timingOf(runGyroctl("analyze " + f.string() + " --json", d.path()));
  EXPECT_FALSE(t["regular"].get<bool>());
  EXPECT_EQ(t["gaps"], 1);
  EXPECT_EQ(t["missing_samples"], 200);
  EXPECT_NEAR(t["largest_gap"]["dt_s"].get<double>(), 4.02, 1e-9);
  EXPECT_NEAR(t["largest_gap"]["start_t_s"].get<double>(), 19.98, 1e-9);
  EXPECT_EQ(t["largest_gap"]["line"], 1002);
  EXPECT_EQ(t["irregular_intervals"], 0);

  for (const std::string& command :
       std::vector<std::string>{"analyze", "model-check --replicas 8", "filter -o " + (d.path() / "o.csv").string()}) {
    const auto strict = runGyroctl(command + " " + f.string() + " --strict-timing", d.path());
    EXPECT_EQ(strict.exit_status, 65) << command << ": " << strict.err;
    EXPECT_EQ(strict.err,
              "gyroctl: " + f.string() +
                  ":1002: irregular timing (--strict-timing): a gap of 4.02 s after t = 19.98 s (over 1.5 x "
                  "the nominal spacing 0.02 s)\n")
        << command;
    EXPECT_TRUE(strict.out.empty()) << command << ": " << strict.out.substr(0, 200);
  }
  EXPECT_FALSE(std::filesystem::exists(d.path() / "o.csv"));
}

TEST(GyroctlTiming, JitterIsCountedWithItsLargestDeviation) {
  ScratchDir d;
  std::vector<double> times;
  const auto f = d.write("jitter.csv", withJitter(&times));
  double largest = 0.0;
  std::size_t beyond = 0, first_line = 0;
  for (std::size_t i = 1; i < times.size(); ++i) {
    const double off = std::abs(times[i] - times[i - 1] - 0.1);
    largest = std::max(largest, off);
    if (off > 0.01) {
      ++beyond;
      if (first_line == 0) first_line = i + 2;
    }
  }
  // --rate 10 fixes the nominal spacing at 0.1 s, so the expected figures follow from the times alone.
  const auto r = runGyroctl("analyze " + f.string() + " --rate 10 --json", d.path());
  const json t = timingOf(r);
  EXPECT_EQ(t["nominal_from"], "rate");
  EXPECT_EQ(t["gaps"], 0);
  EXPECT_EQ(t["irregular_intervals"], beyond);
  EXPECT_GT(beyond, kSamples / 2);  // (1 − 10/45)² ≈ 60 % of the intervals
  EXPECT_NEAR(t["max_jitter_s"].get<double>(), largest, 1e-12);
  EXPECT_GT(largest, 0.04);
  EXPECT_EQ(t["first_offending"]["line"], first_line);
  EXPECT_NE(r.err.find(std::to_string(beyond) + " of 2999 intervals in column 't' off the nominal 0.1 s (1 / --rate) "
                                                "by more than 10 %"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(countLines(r.err), 2u) << r.err;

  const auto strict = runGyroctl(
      "filter " + f.string() + " --rate 10 -o " + (d.path() / "o.csv").string() + " --strict-timing", d.path());
  EXPECT_EQ(strict.exit_status, 65) << strict.err;
  EXPECT_EQ(strict.err.rfind("gyroctl: " + f.string() + ":" + std::to_string(first_line) +
                                 ": irregular timing (--strict-timing): t = ",
                             0),
            0u)
      << strict.err;
  EXPECT_NE(strict.err.find("by more than 10 %"), std::string::npos) << strict.err;
  EXPECT_EQ(countLines(strict.err), 1u) << strict.err;
}

TEST(GyroctlTiming, GapAndDroppedRecordsAreReported) {
  ScratchDir d;
  const auto f = d.write("lost.csv", withLostRecords());
  const auto r = runGyroctl("model-check " + f.string() + " --replicas 8 --json", d.path());
  const json t = timingOf(r);
  EXPECT_EQ(t["gaps"], 0);  // the t column itself runs on: only the records tell
  EXPECT_EQ(t["lost_records"], 2);
  EXPECT_EQ(t["lost_samples"], 11);
  EXPECT_EQ(t["first_lost_record"]["kind"], "dropped");
  EXPECT_EQ(t["first_lost_record"]["count"], 7);
  EXPECT_EQ(t["first_lost_record"]["reason"], "ring_full");
  EXPECT_EQ(t["first_lost_record"]["line"], 502);
  EXPECT_NE(r.err.find("2 '# GAP'/'# DROPPED' records, 11 samples lost in all; the first at line 502"),
            std::string::npos)
      << r.err;

  const auto filtered = runGyroctl("filter " + f.string() + " -o " + (d.path() / "o.csv").string(), d.path());
  EXPECT_EQ(filtered.exit_status, 0) << filtered.err;
  EXPECT_NE(filtered.err.find("gyroctl: warning: " + f.string() + ": 2 '# GAP'/'# DROPPED' records"), std::string::npos)
      << filtered.err;

  const auto strict = runGyroctl("analyze " + f.string() + " --strict-timing", d.path());
  EXPECT_EQ(strict.exit_status, 65);
  EXPECT_EQ(strict.err,
            "gyroctl: " + f.string() +
                ":502: irregular timing (--strict-timing): a '# DROPPED' record: 7 samples lost (ring_full)\n");
}

// Without a t column the spacing cannot be judged: the JSON says so and nothing is warned.
TEST(GyroctlTiming, NoTimeColumn) {
  ScratchDir d;
  std::string bare;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.1);
  for (int i = 0; i < 500; ++i) bare += std::to_string(noise(rng)) + "\n";
  const auto f = d.write("bare.csv", bare);
  const auto r = runGyroctl("analyze " + f.string() + " --json --strict-timing", d.path());
  const json t = timingOf(r);
  EXPECT_FALSE(t["t_column"].get<bool>());
  EXPECT_TRUE(t["nominal_dt_s"].is_null());
  EXPECT_TRUE(t["regular"].get<bool>());
  EXPECT_TRUE(r.err.empty()) << r.err;
}

// README "Gaps and irregular timing" lists the fields of the "timing" object: the same set.
TEST(GyroctlTiming, ReadmeListsTheTimingFields) {
  std::ifstream in(std::string(GYROD_TEST_DATA_DIR) + "/../../README.md");
  ASSERT_TRUE(in) << "README.md not found";
  std::string line, fields_line;
  bool in_section = false;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) == 0) in_section = line.find("Gaps and irregular timing") != std::string::npos;
    if (in_section && line.find("`timing` object:") != std::string::npos) {
      fields_line = line;
      while (std::getline(in, line) && !line.empty()) fields_line += " " + line;
      break;
    }
  }
  ASSERT_FALSE(fields_line.empty()) << "no \"`timing` object:\" paragraph in the README's timing section";
  std::set<std::string> documented;
  const std::string after = fields_line.substr(fields_line.find("object:"));
  for (std::size_t at = after.find('`'); at != std::string::npos; at = after.find('`', at)) {
    const std::size_t end = after.find('`', at + 1);
    if (end == std::string::npos) break;
    documented.insert(after.substr(at + 1, end - at - 1));
    at = end + 1;
  }
  ScratchDir d;
  const auto f = d.write("lost.csv", withLostRecords());
  const json t = timingOf(runGyroctl("analyze " + f.string() + " --json", d.path()));
  std::set<std::string> produced;
  for (const auto& [key, value] : t.items()) produced.insert(key);
  for (const char* nested : {"dt_s", "start_t_s", "line", "kind", "count", "reason"}) produced.insert(nested);
  EXPECT_EQ(documented, produced);
}
