// The streaming timing check: gaps, jitter and the nominal spacing, on generated time columns.
#include "processing/base/sample_timing.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include "processing/base/portable_random.hpp"

namespace gyrod::processing {
namespace {

// Uniform in [0, 1) from the project's PRNG, so the series are the same on every machine.
double uniform(SplitMix64& rng) { return static_cast<double>(rng.next() >> 11) * 0x1.0p-53; }

std::vector<double> regularTimes(std::size_t n, double dt) {
  std::vector<double> t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) * dt;
  return t;
}

SampleTimingReport check(const std::vector<double>& t, std::optional<double> nominal = std::nullopt) {
  SampleTimingCheck c(nominal);
  for (std::size_t i = 0; i < t.size(); ++i) c.add(t[i], i + 2);  // line 1 is the header
  return c.report();
}

TEST(SampleTiming, RegularSeriesIsRegular) {
  const auto r = check(regularTimes(5000, 0.02));
  EXPECT_EQ(r.samples, 5000u);
  EXPECT_NEAR(r.nominal_dt_s, 0.02, 1e-15);
  EXPECT_FALSE(r.nominal_given);
  EXPECT_TRUE(r.regular());
  EXPECT_EQ(r.gaps, 0u);
  EXPECT_EQ(r.irregular, 0u);
  EXPECT_LT(r.max_jitter_s, 1e-12);  // i·dt rounding only
  EXPECT_FALSE(r.largest_gap);
  EXPECT_FALSE(r.first_offending);
}

TEST(SampleTiming, FourSecondGapIsCountedWithItsStartAndLine) {
  std::vector<double> t = regularTimes(3000, 0.02);
  for (std::size_t i = 1000; i < t.size(); ++i) t[i] += 4.0;  // 4 s missing after sample 999
  const auto r = check(t);
  EXPECT_EQ(r.gaps, 1u);
  EXPECT_EQ(r.irregular, 0u);
  EXPECT_EQ(r.missing_samples, 200u);  // round(4.02 / 0.02) − 1
  ASSERT_TRUE(r.largest_gap);
  EXPECT_NEAR(r.largest_gap->dt_s, 4.02, 1e-9);
  EXPECT_NEAR(r.largest_gap->start_t_s, 999 * 0.02, 1e-9);
  EXPECT_EQ(r.largest_gap->index, 1000u);
  EXPECT_EQ(r.largest_gap->line, 1002u);
  ASSERT_TRUE(r.first_offending);
  EXPECT_EQ(r.first_offending->line, 1002u);
  EXPECT_FALSE(r.regular());
}

TEST(SampleTiming, LargestOfSeveralGapsAndTheFirstOffending) {
  std::vector<double> t = regularTimes(2000, 0.01);
  for (std::size_t i = 300; i < t.size(); ++i) t[i] += 0.05;  // 5 samples missing
  for (std::size_t i = 1200; i < t.size(); ++i) t[i] += 1.0;  // 100 missing
  const auto r = check(t);
  EXPECT_EQ(r.gaps, 2u);
  EXPECT_EQ(r.missing_samples, 105u);
  ASSERT_TRUE(r.largest_gap && r.first_offending);
  EXPECT_EQ(r.largest_gap->index, 1200u);
  EXPECT_EQ(r.first_offending->index, 300u);
}

// 5–50 ms of delay on each time stamp of a 10 Hz series: intervals off by up to ±45 ms.
TEST(SampleTiming, JitterFromDelayedTimeStamps) {
  SplitMix64 rng(16);
  std::vector<double> t(4000);
  double largest_expected = 0.0;
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = static_cast<double>(i) * 0.1 + 0.005 + 0.045 * uniform(rng);
  for (std::size_t i = 1; i < t.size(); ++i)
    largest_expected = std::max(largest_expected, std::abs(t[i] - t[i - 1] - 0.1));
  const auto r = check(t, 0.1);
  EXPECT_TRUE(r.nominal_given);
  EXPECT_EQ(r.gaps, 0u);  // ±45 ms never reaches 1.5 × 100 ms
  EXPECT_NEAR(r.max_jitter_s, largest_expected, 1e-12);
  EXPECT_GT(r.max_jitter_s, 0.04);
  EXPECT_LE(r.max_jitter_s, 0.045);
  // The difference of two uniform delays exceeds 10 ms with probability (1 − 10/45)² ≈ 0.605.
  const double share = static_cast<double>(r.irregular) / static_cast<double>(t.size() - 1);
  EXPECT_NEAR(share, 0.605, 0.05);
  // RMS of the difference of two independent U(0, 45 ms): 45 ms / √6.
  EXPECT_NEAR(r.rms_jitter_s, 0.045 / std::sqrt(6.0), 0.002);
  ASSERT_TRUE(r.first_offending);
  EXPECT_GT(std::abs(r.first_offending->dt_s - 0.1), 0.01);
}

TEST(SampleTiming, NominalIsTheMedianOfTheFirstIntervalsNotSkewedByAnEarlyGap) {
  std::vector<double> t = regularTimes(500, 0.005);
  for (std::size_t i = 3; i < t.size(); ++i) t[i] += 2.0;  // a gap among the first intervals
  const auto r = check(t);
  EXPECT_NEAR(r.nominal_dt_s, 0.005, 1e-12);
  EXPECT_EQ(r.gaps, 1u);
  ASSERT_TRUE(r.first_offending);
  EXPECT_EQ(r.first_offending->index, 3u);
}

TEST(SampleTiming, ShortSeriesReportsFromWhatItHas) {
  const auto r = check({0.0, 0.5, 1.0, 1.5, 5.0});
  EXPECT_DOUBLE_EQ(r.nominal_dt_s, 0.5);
  EXPECT_EQ(r.gaps, 1u);
  EXPECT_EQ(r.samples, 5u);
  EXPECT_EQ(check({}).nominal_dt_s, 0.0);
  EXPECT_TRUE(check({1.0}).regular());
}

TEST(SampleTiming, ReportMidwayEqualsReportAtTheEndOfTheSamePrefix) {
  const std::vector<double> t = {0.0, 0.1, 0.2, 0.45, 0.5, 0.6};
  SampleTimingCheck c;
  for (double v : t) c.add(v);
  const auto mid = c.report();  // before kNominalIntervals: settles a copy
  c.add(0.7);
  EXPECT_EQ(mid.samples, 6u);
  EXPECT_EQ(c.report().samples, 7u);
  EXPECT_EQ(mid.gaps, 1u);
  EXPECT_EQ(mid.irregular, 1u);  // 0.45 → 0.5 is half a sample early
}

TEST(SampleTiming, TimeGoingBackIsIrregular) {
  std::vector<double> t = regularTimes(200, 0.01);
  t[150] = t[149];
  const auto r = check(t);
  EXPECT_EQ(r.irregular, 1u);  // 0 s
  EXPECT_EQ(r.gaps, 1u);       // then 20 ms
  ASSERT_TRUE(r.first_offending);
  EXPECT_EQ(r.first_offending->index, 150u);
}

void expectSameInterval(const std::optional<TimingInterval>& a, const std::optional<TimingInterval>& b) {
  ASSERT_EQ(a.has_value(), b.has_value());
  if (!a) return;
  EXPECT_EQ(a->start_t_s, b->start_t_s);
  EXPECT_EQ(a->dt_s, b->dt_s);
  EXPECT_EQ(a->index, b->index);
  EXPECT_EQ(a->line, b->line);
}

// addTimes gives add()'s report to the bit, asking for few lines, on jittered series with gaps,
// repeated and backward times, whether τ0 is given or the median, fed in one piece or several.
TEST(SampleTiming, AddTimesIsAddSampleBySample) {
  SplitMix64 rng(20261125);
  for (int round = 0; round < 24; ++round) {
    const std::size_t n = round < 4 ? static_cast<std::size_t>(round) * 30 : 5000;
    std::vector<double> t(n);
    double now = 10.0 * uniform(rng);
    for (std::size_t i = 0; i < n; ++i) {
      const double u = uniform(rng);
      now += u < 0.002   ? 0.02 * (2.0 + 50.0 * uniform(rng))          // a gap
             : u < 0.004 ? -0.01 * uniform(rng)                        // back in time
             : u < 0.006 ? 0.0                                         // standing still
                         : 0.02 * (1.0 + 0.3 * (uniform(rng) - 0.5));  // jitter, some over 10 %
      t[i] = now;
    }
    const std::optional<double> nominal = round % 2 == 0 ? std::nullopt : std::optional<double>(0.02);
    SampleTimingCheck one(nominal), batch(nominal);
    for (std::size_t i = 0; i < n; ++i) one.add(t[i], 3 * i + 7);
    std::size_t asked = 0;
    const std::size_t cut = round % 3 == 0 ? n : n / 3;  // in two pieces, the second numbered from its start
    batch.addTimes(std::span<const double>(t).first(cut), [&](std::size_t i) {
      ++asked;
      return 3 * i + 7;
    });
    batch.addTimes(std::span<const double>(t).subspan(cut), [&](std::size_t i) {
      ++asked;
      return 3 * (i + cut) + 7;
    });
    const auto a = one.report(), b = batch.report();
    EXPECT_EQ(a.samples, b.samples);
    EXPECT_EQ(a.nominal_dt_s, b.nominal_dt_s);
    EXPECT_EQ(a.gaps, b.gaps);
    EXPECT_EQ(a.missing_samples, b.missing_samples);
    EXPECT_EQ(a.irregular, b.irregular);
    EXPECT_EQ(a.max_jitter_s, b.max_jitter_s);
    EXPECT_EQ(a.rms_jitter_s, b.rms_jitter_s);
    expectSameInterval(a.largest_gap, b.largest_gap);
    expectSameInterval(a.first_offending, b.first_offending);
    if (n == 5000) {
      EXPECT_GT(a.irregular, 10u);
      EXPECT_LT(a.irregular + a.gaps, n / 2);
      EXPECT_LE(asked, a.irregular + a.gaps + kNominalIntervals + 1);  // the offending intervals, and τ0's
    }
  }
}

TEST(SampleTiming, RefusesBadNominalAndLimits) {
  EXPECT_THROW(SampleTimingCheck(0.0), std::invalid_argument);
  EXPECT_THROW(SampleTimingCheck(std::nan("")), std::invalid_argument);
  EXPECT_THROW(SampleTimingCheck(std::nullopt, SampleTimingLimits{1.0, 0.1}), std::invalid_argument);
  EXPECT_THROW(SampleTimingCheck(std::nullopt, SampleTimingLimits{1.5, 0.6}), std::invalid_argument);
}

}  // namespace
}  // namespace gyrod::processing
