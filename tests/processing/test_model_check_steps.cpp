// Bias steps in a long record (issue 13, "steps are miscounted"): a one-hour record with five
// small steps came back with three. Seeded regressions of that case: every step found, none
// invented, each placed within a few seconds and sized within its standard error. Several
// steps per axis (issue 36): 3–7 steps of different sizes and signs at random times, close
// together, counted exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "processing/base/noise_terms.hpp"
#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"
#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kRate = 50.0;

NoiseTerms midTerms() {  // the middle of the hidden-effect generator's ranges
  NoiseTerms t;
  t.quantization_urad = 2.0;
  t.arw_deg_per_sqrt_h = 0.5;
  t.bias_instability_deg_per_h = 10.0;
  t.rrw_deg_per_h_sqrt_h = 3.0;
  return t;
}

double adevFloor(const NoiseTerms& terms) {  // as the generator sizes steps
  double f = 1e300;
  for (double tau = 2.0; tau <= 128.0; tau *= 2.0) f = std::min(f, std::sqrt(allanVarianceOfTerms(terms, tau)));
  return f;
}

std::vector<double> simulate(const std::vector<BiasStepEffect>& steps, double duration, std::uint64_t seed) {
  SimulationModel m;
  m.rate_hz = kRate;
  m.fs_sel = 0;
  m.axes[0].terms = midTerms();
  m.axes[0].bias_dps = 0.7;
  m.axes[0].extra.bias_steps = steps;
  NoiseSimulator sim(m, duration, seed);
  std::vector<double> x(static_cast<std::size_t>(duration * kRate));
  for (double& v : x) v = sim.next().rate_dps[0];
  return x;
}

AxisModelCheck check(const std::vector<double>& x, std::uint64_t seed) {
  ModelCheckOptions o;
  o.seed = seed;
  o.threads = 2;
  return checkAxisModel({x, kRate, {}, {}, {}}, o);
}

std::string describe(const AxisModelCheck& r) {
  std::string s;
  for (const DetectedEffect& e : r.effects) {
    s += std::string(modelEffectName(e.effect)) + " (statistic " + std::to_string(e.evidence.statistic) +
         ", threshold " + std::to_string(e.evidence.threshold) + ")";
    for (std::size_t j = 0; j < e.times_s.size(); ++j)
      s += " " + std::to_string(e.times_s[j]) + " s: " + std::to_string(e.sizes_dps[j]);
    s += "\n";
  }
  if (s.empty()) s = "(no effect)\n";
  for (const CheckStatistic& st : r.statistics)
    s += "  " + st.name + " " + std::to_string(st.value) + " (null median " + std::to_string(st.null_median) +
         ", threshold " + std::to_string(st.threshold) + ")\n";
  return s;
}

}  // namespace

// Five steps of 9–11 × the Allan floor in an hour, three seeds: 15 steps. Before the
// steps' share of the false-alarm budget, the 1 % threshold for further steps and the joint
// refit (model_check_steps.cpp), the check found 1 of the 5 of seed 31; the issue's
// case was 3 of 5.
TEST(ModelCheckSteps, FiveSmallStepsInOneHourAreFound) {
  const double floor_adev = adevFloor(midTerms());
  const std::vector<double> sizes = {10.0, -9.0, 11.0, 10.0, -10.0};
  const std::vector<double> times = {420.0, 1150.0, 1790.0, 2530.0, 3170.0};
  std::size_t found = 0;
  for (std::uint64_t seed : {31u, 32u, 33u}) {
    std::vector<BiasStepEffect> steps;
    for (std::size_t j = 0; j < times.size(); ++j) steps.push_back({times[j], sizes[j] * floor_adev});
    const AxisModelCheck r = check(simulate(steps, 3600.0, seed), seed);
    ASSERT_EQ(r.effects.size(), 1u) << "seed " << seed << ":\n" << describe(r);
    const DetectedEffect& e = r.effects[0];
    ASSERT_EQ(e.effect, ModelEffect::BiasSteps) << describe(r);
    EXPECT_GE(e.count, times.size() - 1) << "seed " << seed << ":\n" << describe(r);
    EXPECT_LE(e.count, times.size()) << "seed " << seed << ":\n" << describe(r);
    // Every step reported is a true one, placed within 10 s, its sign right.
    for (std::size_t k = 0; k < e.count; ++k) {
      std::size_t nearest = 0;
      for (std::size_t j = 1; j < times.size(); ++j)
        if (std::fabs(e.times_s[k] - times[j]) < std::fabs(e.times_s[k] - times[nearest])) nearest = j;
      EXPECT_NEAR(e.times_s[k], times[nearest], 10.0) << "seed " << seed << "\n" << describe(r);
      EXPECT_GT(e.sizes_dps[k] * sizes[nearest], 0.0) << "seed " << seed << "\n" << describe(r);
    }
    found += e.count;
  }
  EXPECT_GE(found, 14u);
}

// Several steps per axis (issue 36): the hidden-effect generator hides 3–7 steps on one axis of
// a 10-minute, 50 Hz record (times uniform over 0.1–0.9 of it, at least 30 s apart; signs at
// random), each 17–34 × the axis's ADEV floor: the smallest at 3 × the step floor, the 50 %
// size of the optimal blind scan of one step at the check's false-alarm rate (5.4–5.8 × the
// ADEV floor in 10 minutes; docs/model-check.md, "How far from the achievable"). The count must
// be exact in at least 18 of 20 seeds (90 %); in those, every step reported within 5 s of a
// hidden one with its sign, its size within 30 % and a 95 % interval stated for it. Seeds
// 901–920 were run once, after the changes they test.
TEST(ModelCheckSteps, ThreeToSevenStepsOfDifferentSizesAreCountedExactly) {
  std::size_t exact = 0, records = 0;
  std::string misses;
  for (std::uint64_t seed = 901; seed <= 920; ++seed) {
    HiddenEffectGenerator gen(seed);
    gen.step_size_lo = 17.0;
    gen.step_size_hi = 34.0;
    gen.step_count_lo = 3;
    gen.step_count_hi = 7;
    gen.step_min_gap = 0.05;
    const GeneratedRecording g = gen.generate(600.0, kRate, {ModelEffect::BiasSteps});
    const HiddenEffect& h = g.hidden[0];
    ModelCheckOptions o;
    o.seed = seed;
    o.threads = 2;
    const AxisModelCheck r = checkAxisModel({g.axes[h.axis], g.rate_hz, g.temp, g.t, {}}, o);
    ++records;
    const DetectedEffect* steps = nullptr;
    for (const DetectedEffect& e : r.effects)
      if (e.effect == ModelEffect::BiasSteps) steps = &e;
    if (!steps || steps->count != h.count) {
      misses += "seed " + std::to_string(seed) + ": " + std::to_string(h.count) + " hidden, " +
                std::to_string(steps ? steps->count : 0) + " found\n" + describe(r);
      continue;
    }
    ++exact;
    ASSERT_EQ(steps->times_s.size(), h.count);
    ASSERT_EQ(steps->sizes_dps.size(), h.count);
    EXPECT_EQ(steps->size_intervals.size(), h.count) << "seed " << seed;
    for (std::size_t k = 0; k < h.count; ++k) {
      // The steps are reported in time order, as the generator hides them.
      EXPECT_NEAR(steps->times_s[k], h.times_s[k], 5.0) << "seed " << seed << "\n" << describe(r);
      EXPECT_GT(steps->sizes_dps[k] * h.sizes_dps[k], 0.0) << "seed " << seed << "\n" << describe(r);
      EXPECT_NEAR(steps->sizes_dps[k], h.sizes_dps[k], 0.3 * std::fabs(h.sizes_dps[k])) << "seed " << seed << "\n"
                                                                                        << describe(r);
    }
  }
  std::printf("3-7 steps of 17-34 x the ADEV floor: count exact in %zu of %zu records\n", exact, records);
  EXPECT_GE(10 * exact, 9 * records) << exact << " of " << records << " exact\n" << misses;
}
