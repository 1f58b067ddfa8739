// One JSON shape for Allan tables (protocol/allan_table.hpp): what offline analyze writes and
// what the ALLAN reply carries read back to the same points, and a point says only what is
// known (no interval before the noise type is identified, no non-overlapping estimator live).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "processing/allan/allan.hpp"
#include "protocol/allan_table.hpp"
#include "protocol/protocol.hpp"

using namespace gyrod;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// An offline table, as analyze computes it, of white noise from a seed.
std::vector<processing::AllanPoint> offlineTable() {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<double> x(4000);
  for (double& v : x) v = noise(rng);
  return processing::allanDeviationTable(x, 0.02, processing::octaveClusterSizes(x.size()));
}

void expectSamePoint(const processing::AllanPoint& got, const processing::AllanPoint& want) {
  EXPECT_EQ(got.tau_s, want.tau_s);
  EXPECT_EQ(got.m, want.m);
  EXPECT_EQ(got.oadev, want.oadev);
  EXPECT_EQ(got.oadev_terms, want.oadev_terms);
  EXPECT_EQ(got.noise_alpha, want.noise_alpha);
  EXPECT_EQ(got.edf, want.edf);
  EXPECT_EQ(got.oadev_lo, want.oadev_lo);
  EXPECT_EQ(got.oadev_hi, want.oadev_hi);
  if (std::isfinite(want.adev)) {
    EXPECT_EQ(got.adev, want.adev);
    EXPECT_EQ(got.adev_terms, want.adev_terms);
  } else {
    EXPECT_TRUE(std::isnan(got.adev));
  }
}

}  // namespace

TEST(AllanTable, AnOfflineTableReadsBackExactly) {
  const auto table = offlineTable();
  ASSERT_GE(table.size(), 8u);
  const auto json = protocol::allanTableJson(table);
  ASSERT_EQ(json.size(), table.size());
  EXPECT_TRUE(json[0].contains("oadev_lo"));
  EXPECT_TRUE(json[0].contains("adev_n"));
  const auto back = protocol::allanTableFromJson(nlohmann::ordered_json::parse(json.dump()));
  ASSERT_EQ(back.size(), table.size());
  for (std::size_t i = 0; i < table.size(); ++i) expectSamePoint(back[i], table[i]);
}

TEST(AllanTable, APointSaysOnlyWhatIsKnown) {
  processing::AllanPoint live{0.02, 1, kNaN, 0, 0.05, 999, 0, kNaN, kNaN, kNaN};
  processing::AllanPoint empty{0.04, 2, kNaN, 0, kNaN, 0, 0, kNaN, kNaN, kNaN};
  const auto json = protocol::allanTableJson(std::vector<processing::AllanPoint>{live, empty});
  ASSERT_EQ(json.size(), 1u);  // no deviation, no point
  EXPECT_EQ(json[0].dump(), R"({"tau_s":0.02,"m":1,"oadev":0.05,"n":999})");
}

TEST(AllanTable, TheAllanReplyCarriesTheSameTablesWithSpanIntervalsAndUncertainties) {
  protocol::AllanReport r;
  r.window_s = 3600.0;
  r.samples = 4000;
  r.span_s = 80.0;
  r.tau0_s = 0.02;
  r.confidence = 0.683;
  const auto table = offlineTable();
  for (const auto& p : table) r.tau_s.push_back(p.tau_s);
  for (auto& axis : r.curves) {
    for (const auto& p : table) axis[0].adev_dps.push_back(p.oadev);
    axis[0].points = table;
  }
  processing::NoiseTerms terms{1.0, 0.5, 3.0, kNaN, kNaN}, sigma{0.1, 0.05, 0.3, 7.0, 7.0};
  r.curves[1][0].noise = terms;
  r.curves[1][0].noise_uncertainty = sigma;
  const std::string line = protocol::allanLine(r);
  const auto j = nlohmann::ordered_json::parse(line);
  EXPECT_EQ(j["table"]["y"]["raw"], protocol::allanTableJson(table));  // the very same shape
  // An uncertainty only beside its term.
  EXPECT_EQ(j["noise_uncertainty"]["y"]["raw"].size(), 3u);

  const auto parsed = std::get<protocol::AllanReport>(protocol::parseServerLine(line.substr(0, line.size() - 1)));
  EXPECT_EQ(parsed.samples, 4000u);
  EXPECT_EQ(parsed.span_s, 80.0);
  EXPECT_EQ(parsed.window_s, 3600.0);
  EXPECT_EQ(parsed.confidence, 0.683);
  ASSERT_EQ(parsed.curves[2][0].points.size(), table.size());
  for (std::size_t i = 0; i < table.size(); ++i) expectSamePoint(parsed.curves[2][0].points[i], table[i]);
  ASSERT_TRUE(parsed.curves[1][0].noise_uncertainty.has_value());
  EXPECT_EQ(parsed.curves[1][0].noise_uncertainty->arw_deg_per_sqrt_h, 0.05);
  EXPECT_TRUE(std::isnan(parsed.curves[1][0].noise_uncertainty->rrw_deg_per_h_sqrt_h));
  EXPECT_TRUE(parsed.curves[0][1].points.empty());
}
