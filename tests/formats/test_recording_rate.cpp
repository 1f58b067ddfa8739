// sampleRateFromTimes: 1 / the median step of t, the same bits as a sort of every step would
// give, on clocks whose median step is common, rare, or away from the sampled steps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "formats/recording_csv.hpp"

using namespace gyrod::recording;

namespace {

// The rate by the definition: every step copied, the middle one found by a full sort.
double rateBySorting(const std::vector<double>& t) {
  std::vector<double> dt;
  for (std::size_t i = 1; i < t.size(); ++i) dt.push_back(t[i] - t[i - 1]);
  std::sort(dt.begin(), dt.end());
  return 1.0 / dt[dt.size() / 2];
}

Recording withTimes(std::vector<double> t) {
  Recording r;
  r.path = "rec.csv";
  r.t = std::move(t);
  return r;
}

// Deterministic uniform numbers in [0, 1) (a 64-bit LCG's top bits).
struct Lcg {
  std::uint64_t state;
  double next() {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  }
};

TEST(RecordingRate, MedianStepIsTheSortedMiddleToTheBit) {
  Lcg rng{20261125};
  std::vector<std::vector<double>> columns;
  for (std::size_t n : {2u, 3u, 4u, 5u, 100u, 1025u, 20'001u, 20'002u, 300'001u}) {  // the last on both cores
    std::vector<double> printed(n), jittered(n), two_steps(n);
    double now = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      printed[i] = 0.02 * static_cast<double>(i) + 1000.0;  // a regular clock: few distinct steps
      now += 0.01 * (1.0 + rng.next());                     // every step different
      jittered[i] = now;
      two_steps[i] = static_cast<double>(i) + (i % 2 == 0 ? 0.0 : 0.25);  // the median on a tie's edge
    }
    columns.push_back(printed);
    columns.push_back(jittered);
    columns.push_back(two_steps);
  }
  // Short steps just where the reader samples 1024 steps evenly, long ones elsewhere: a guess
  // from the sample misses the median.
  // On one core and on both (the search by bits counts each half apart).
  for (const std::size_t steps : {std::size_t{40'000}, std::size_t{300'000}}) {
    std::vector<bool> sampled(steps + 1, false);
    for (std::size_t j = 0; j < 1024; ++j) sampled[j * steps / 1024 + 1] = true;
    std::vector<double> misleading(steps + 1);
    for (std::size_t i = 1; i <= steps; ++i)
      misleading[i] = misleading[i - 1] + (sampled[i] ? 0.001 : 0.02 + 1e-9 * static_cast<double>(i % 97));
    columns.push_back(misleading);
  }
  // A 50 Hz clock from t = 60000 s on: a few distinct steps, in a pattern the even sample
  // aliases (its median lies outside the bracket it guesses).
  std::vector<double> aliased(300'001);
  for (std::size_t i = 0; i < aliased.size(); ++i) aliased[i] = 60000.0 + 0.02 * static_cast<double>(i);
  columns.push_back(aliased);
  for (const auto& t : columns) {
    const double expected = rateBySorting(t);
    EXPECT_EQ(sampleRateFromTimes(withTimes(t)), expected) << t.size() << " samples";
  }
}

// On one core or two (a long column is counted in halves), the first such step in the file.
TEST(RecordingRate, TheFirstStepThatIsNotPositiveIsNamed) {
  for (const std::size_t n : {std::size_t{5000}, std::size_t{400'000}}) {
    std::vector<double> t(n);
    for (std::size_t i = 0; i < t.size(); ++i) t[i] = 0.5 * static_cast<double>(i);
    t[3000] = t[2999];
    t[n - 1000] = 0.0;
    for (const bool both_halves : {true, false}) {
      if (!both_halves) t[3000] = 1500.0;  // only the later one left
      try {
        (void)sampleRateFromTimes(withTimes(t));
        FAIL() << "accepted t standing still";
      } catch (const RecordingError& e) {
        const std::string expected =
            both_halves
                ? "rec.csv:3001: column 't' is not strictly increasing (t = 1499.5 after 1499.5)"
                : "rec.csv:" + std::to_string(n - 999) + ": column 't' is not strictly increasing (t = 0 after " +
                      std::to_string(static_cast<int>(n - 1001) / 2) + (n % 2 == 0 ? ".5" : "") + ")";
        EXPECT_EQ(std::string(e.what()), expected);
      }
    }
  }
  EXPECT_THROW((void)sampleRateFromTimes(withTimes({1.0})), RecordingError);
}

}  // namespace
