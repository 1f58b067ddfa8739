// The model check's 95 % parameter intervals (processing/model_check_intervals.hpp;
// docs/model-check.md, "Intervals"): the generic pieces against known values, and a check of a
// hidden sinusoid whose interval must hold the truth. Their
// measured coverage over many seeds is bench/model_check_coverage.cpp's.
#include <gtest/gtest.h>

#include <vector>

#include "processing/hidden_effect_generator.hpp"
#include "processing/model_check.hpp"
#include "processing/model_check_intervals.hpp"
#include "processing/portable_random.hpp"

using namespace gyrod::processing;

TEST(ModelCheckIntervals, PoissonIntervalIsGarwoods) {
  // Garwood (1936) 95 % limits: 0 → [0, 3.689], 1 → [0.0253, 5.572], 10 → [4.795, 18.39].
  const ParameterInterval zero = poissonInterval(0), one = poissonInterval(1), ten = poissonInterval(10);
  EXPECT_EQ(zero.lo, 0.0);
  EXPECT_NEAR(zero.hi, 3.689, 1e-3);
  EXPECT_NEAR(one.lo, 0.0253, 1e-4);
  EXPECT_NEAR(one.hi, 5.572, 1e-3);
  EXPECT_NEAR(ten.lo, 4.795, 1e-3);
  EXPECT_NEAR(ten.hi, 18.39, 1e-2);
}

TEST(ModelCheckIntervals, BootstrapIntervalIsTheEstimatePlusMinusTheReplicasSpread) {
  NormalGenerator normal(11);
  std::vector<double> draws(4000);
  for (double& d : draws) d = 5.0 + 0.2 * normal.next();
  const ParameterInterval i = bootstrapInterval(7.0, draws);
  ASSERT_TRUE(i.stated);
  EXPECT_NEAR(i.lo, 7.0 - 1.96 * 0.2, 0.02);
  EXPECT_NEAR(i.hi, 7.0 + 1.96 * 0.2, 0.02);
  EXPECT_FALSE(bootstrapInterval(1.0, std::vector<double>(7, 1.0)).stated);  // too few replicas
  std::vector<double> logs(4000);
  for (double& d : logs) d = std::exp(0.1 * normal.next());
  const ParameterInterval l = logBootstrapInterval(2.0, logs);
  EXPECT_NEAR(l.lo, 2.0 * std::exp(-1.96 * 0.1), 0.01);
  EXPECT_NEAR(l.hi, 2.0 * std::exp(1.96 * 0.1), 0.01);
  EXPECT_FALSE(logBootstrapInterval(0.0, logs).stated);
}

// A hidden sinusoid: named, with an amplitude interval that holds the truth and is no narrower
// than the white-noise standard error alone would make it (the base noise is coloured).
TEST(ModelCheckIntervals, NamedEffectsStateIntervalsThatHoldTheTruth) {
  HiddenEffectGenerator gen(21);
  const GeneratedRecording g = gen.generate(600.0, 50.0, {ModelEffect::Sinusoid});
  const HiddenEffect& h = g.hidden.front();
  ModelCheckOptions o;
  o.seed = 5;
  o.threads = 2;
  const AxisModelCheck r = checkAxisModel({g.axes[h.axis], g.rate_hz, g.temp, g.t, {}}, o);
  const DetectedEffect* line = nullptr;
  for (const DetectedEffect& e : r.effects)
    if (e.effect == ModelEffect::Sinusoid) line = &e;
  ASSERT_NE(line, nullptr);
  ASSERT_TRUE(line->amp_interval.stated);
  EXPECT_TRUE(line->amp_interval.contains(h.amp_dps))
      << h.amp_dps << " not in [" << line->amp_interval.lo << ", " << line->amp_interval.hi << "]";
  const double white_sd = g.terms[h.axis].arw_deg_per_sqrt_h / 60.0 * std::sqrt(50.0);
  const double white_se = white_sd * std::sqrt(2.0 / 30000.0);
  EXPECT_GT(line->amp_interval.hi - line->amp_interval.lo, 0.8 * 2.0 * 1.96 * white_se);
  EXPECT_FALSE(line->k_interval.stated);  // only the effect's own parameters
}
