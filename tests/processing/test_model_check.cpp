// The model check, blind: data from processing/model_check/hidden_effect_generator.hpp (base-model
// noise, a moving temperature channel, hidden effects with random parameters on random
// axes, all from a seed); the check sees only the columns. Each test states its tolerance.
// Short recordings (10 min at 50 Hz) and few replicas keep them at about a second each in
// an optimised build; shorter ones would test a weaker check (the low-frequency effects need
// the record). All of them also run under ASan + UBSan: CI builds the sanitized suite
// optimised (.ci/run), where they take 0.5–17 s each (unoptimised they would take minutes).
// The detection and false-discovery rates over hundreds of seeds are measured by
// bench/model_check_rates.cpp (docs/model-check.md), not here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kDuration = 600.0;
constexpr double kRate = 50.0;

ModelCheckOptions testOptions(std::uint64_t seed) {
  ModelCheckOptions o;
  o.replicas = 40;  // the product's default: thresholds from fewer replicas are noisier
  o.seed = seed;
  o.threads = 2;
  return o;
}

GeneratedRecording generate(std::uint64_t seed, std::vector<ModelEffect> effects) {
  return HiddenEffectGenerator(seed).generate(kDuration, kRate, effects);
}

AxisModelCheck check(const GeneratedRecording& g, std::size_t axis, std::uint64_t seed = 1) {
  return checkAxisModel({g.axes[axis], g.rate_hz, g.temp, g.t, {}}, testOptions(seed));
}

std::string describe(const AxisModelCheck& r) {
  std::string s;
  for (const DetectedEffect& e : r.effects)
    s += std::string(modelEffectName(e.effect)) + ": statistic " + std::to_string(e.evidence.statistic) +
         ", threshold " + std::to_string(e.evidence.threshold) + "\n";
  return s.empty() ? "(no effect)" : s;
}

const DetectedEffect* find(const AxisModelCheck& r, ModelEffect e) {
  for (const DetectedEffect& d : r.effects)
    if (d.effect == e) return &d;
  return nullptr;
}

// The effects reported on `axis` must be exactly those hidden there (sample gaps: on every axis).
void expectExactlyTheHidden(const GeneratedRecording& g, std::size_t axis, const AxisModelCheck& r) {
  std::vector<std::string> expected, got;
  for (const HiddenEffect& h : g.hidden)
    if (h.axis == axis || h.effect == ModelEffect::SampleGaps) expected.emplace_back(modelEffectName(h.effect));
  for (const DetectedEffect& d : r.effects) got.emplace_back(modelEffectName(d.effect));
  std::sort(expected.begin(), expected.end());
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, expected) << "axis " << axis << ":\n" << describe(r);
}

}  // namespace

TEST(ModelCheck, CleanDataGivesNoEffectOnAnyAxis) {
  for (std::uint64_t seed : {101u, 102u}) {
    const GeneratedRecording g = generate(seed, {});
    for (std::size_t a = 0; a < 3; ++a) {
      const AxisModelCheck r = check(g, a, seed);
      EXPECT_TRUE(r.effects.empty()) << "seed " << seed << " axis " << a << ":\n" << describe(r);
      // The base model holds: extended = base, and the measured curve lies mostly in the band.
      EXPECT_EQ(r.gain.adev_log_error_base, r.gain.adev_log_error_extended);
      EXPECT_GE(r.gain.in_band_base, 0.6);
    }
  }
}

TEST(ModelCheck, FindsASinusoidWithItsFrequencyAndAmplitude) {
  const GeneratedRecording g = generate(7, {ModelEffect::Sinusoid});
  const HiddenEffect& h = g.hidden[0];
  for (std::size_t a = 0; a < 3; ++a) {
    const AxisModelCheck r = check(g, a);
    expectExactlyTheHidden(g, a, r);
    if (a != h.axis) continue;
    const DetectedEffect* d = find(r, ModelEffect::Sinusoid);
    ASSERT_NE(d, nullptr);
    // Tolerances: half a periodogram bin (1/duration) in frequency, 10 % in amplitude (the
    // least-squares amplitude has sd √(2/n)·σ ≈ 1 % of the smallest hidden amplitude here).
    EXPECT_NEAR(d->freq_hz, h.freq_hz, 0.5 / kDuration);
    EXPECT_NEAR(d->amp_dps, h.amp_dps, 0.1 * h.amp_dps);
    // The extended model is closer to the data than the base model.
    EXPECT_LT(r.gain.innovation_var_extended, r.gain.innovation_var_base);
  }
}

TEST(ModelCheck, CountsOutliers) {
  const GeneratedRecording g = generate(11, {ModelEffect::Outliers});
  const HiddenEffect& h = g.hidden[0];
  const AxisModelCheck r = check(g, h.axis);
  expectExactlyTheHidden(g, h.axis, r);
  const DetectedEffect* d = find(r, ModelEffect::Outliers);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->count, h.count);  // every hidden one is ≥ 10σ: none may be missed
  EXPECT_LT(r.gain.innovation_var_extended, r.gain.innovation_var_base);
}

TEST(ModelCheck, FindsSampleGapsInTheTimeColumn) {
  const GeneratedRecording g = generate(13, {ModelEffect::SampleGaps});
  const HiddenEffect& h = g.hidden[0];
  const AxisModelCheck r = check(g, 0);
  expectExactlyTheHidden(g, 0, r);
  const DetectedEffect* d = find(r, ModelEffect::SampleGaps);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->count, h.count);
  EXPECT_EQ(d->lost, h.lost);
}

TEST(ModelCheck, FindsATemperatureCoefficient) {
  const GeneratedRecording g = generate(17, {ModelEffect::TemperatureBias});
  const HiddenEffect& h = g.hidden[0];
  const AxisModelCheck r = check(g, h.axis);
  expectExactlyTheHidden(g, h.axis, r);
  const DetectedEffect* d = find(r, ModelEffect::TemperatureBias);
  ASSERT_NE(d, nullptr);
  EXPECT_NEAR(d->k_dps_per_c, h.k_dps_per_c, 0.25 * std::fabs(h.k_dps_per_c));
  // A neighbouring axis without the coupling: the moving temperature alone is no evidence.
  const AxisModelCheck other = check(g, (h.axis + 1) % 3);
  EXPECT_EQ(find(other, ModelEffect::TemperatureBias), nullptr) << describe(other);
}

// Clear steps (20–30 × the Allan floor) must be found exactly: count and times. Smaller ones
// (the rates script goes down to 10×) are found less often; that boundary is measured there.
GeneratedRecording generateClearSteps(std::uint64_t seed) {
  HiddenEffectGenerator gen(seed);
  gen.step_size_lo = 20.0;
  gen.step_size_hi = 30.0;
  return gen.generate(kDuration, kRate, {ModelEffect::BiasSteps});
}

TEST(ModelCheck, FindsBiasStepsAndWhen) {
  const GeneratedRecording g = generateClearSteps(19);
  const HiddenEffect& h = g.hidden[0];
  const AxisModelCheck r = check(g, h.axis);
  expectExactlyTheHidden(g, h.axis, r);
  const DetectedEffect* d = find(r, ModelEffect::BiasSteps);
  ASSERT_NE(d, nullptr);
  ASSERT_EQ(d->count, h.count);
  for (std::size_t j = 0; j < h.count; ++j) EXPECT_NEAR(d->times_s[j], h.times_s[j], 2.0) << "step " << j;
}

TEST(ModelCheck, FindsAGaussMarkovProcess) {
  // A clear one: T from 1 s to duration/300 and an Allan peak 2.5–3.5 × the base model's.
  // Longer T (to duration/40) and smaller peaks (from 1.5×) are found less often: the rates
  // script measures by how much (docs/model-check.md, detection by size).
  HiddenEffectGenerator gen(23);
  gen.gm_tau_hi_fraction = 1.0 / 300.0;
  gen.gm_peak_lo = 2.5;
  gen.gm_peak_hi = 3.5;
  const GeneratedRecording g = gen.generate(kDuration, kRate, {ModelEffect::GaussMarkov});
  const HiddenEffect& h = g.hidden[0];
  const AxisModelCheck r = check(g, h.axis);
  expectExactlyTheHidden(g, h.axis, r);
  const DetectedEffect* d = find(r, ModelEffect::GaussMarkov);
  ASSERT_NE(d, nullptr);
  // Tolerances: a factor 2 in T (the fit tries 5 values per decade, and T trades against
  // the flicker floor), 40 % in σ.
  EXPECT_LT(std::fabs(std::log(d->tau_s / h.tau_s)), std::log(2.0));
  EXPECT_NEAR(d->sigma_dps, h.sigma_dps, 0.4 * h.sigma_dps);
  EXPECT_LT(r.gain.adev_log_error_extended, r.gain.adev_log_error_base);
}

TEST(ModelCheck, AStepDuringWarmUpIsAStepNotTemperature) {
  // The generator's warm-up is fastest at the start: a step early in the record correlates
  // with temperature, yet is abrupt. Hidden: steps only (seed chosen freely; the check does
  // not know it).
  const GeneratedRecording g = generateClearSteps(29);
  const HiddenEffect& h = g.hidden[0];
  const AxisModelCheck r = check(g, h.axis);
  EXPECT_EQ(find(r, ModelEffect::TemperatureBias), nullptr) << describe(r);
  EXPECT_NE(find(r, ModelEffect::BiasSteps), nullptr) << describe(r);
}

TEST(ModelCheck, TwoEffectsAtOnce) {
  const GeneratedRecording g = generate(31, {ModelEffect::Sinusoid, ModelEffect::TemperatureBias});
  for (std::size_t a = 0; a < 3; ++a) expectExactlyTheHidden(g, a, check(g, a));
  const GeneratedRecording g2 = generate(37, {ModelEffect::Outliers, ModelEffect::BiasSteps});
  for (std::size_t a = 0; a < 3; ++a) expectExactlyTheHidden(g2, a, check(g2, a));
}

TEST(ModelCheck, AResonanceIsNamedANarrowbandLine) {
  // A lightly damped AR(2) resonance at 5 Hz (poles 0.97·e^{±iπ/5}) is the catalogue's
  // narrowband line: centre 5 Hz, half-power width −ln(0.97)·rate/π = 0.485 Hz.
  SimulationModel m;
  m.rate_hz = kRate;
  m.axes[0].terms.arw_deg_per_sqrt_h = 0.4;
  m.axes[0].terms.bias_instability_deg_per_h = 8.0;
  const double r = 0.97, theta = std::numbers::pi / 5.0;
  m.axes[0].ar.phi = {2.0 * r * std::cos(theta), -r * r};
  m.axes[0].ar.noise_var = 1e-4;
  NoiseSimulator sim(m, 150.0, 41);  // short: this one also runs under the sanitizers
  std::vector<double> x(sim.sampleCount());
  for (double& v : x) v = sim.next().rate_dps[0];
  ModelCheckOptions o = testOptions(41);
  o.replicas = 8;
  const AxisModelCheck res = checkAxisModel({x, kRate, {}, {}, {}}, o);
  const DetectedEffect* line = find(res, ModelEffect::NarrowbandLine);
  ASSERT_NE(line, nullptr) << describe(res);
  // Tolerances: over 150 s the centre of a 0.5 Hz wide line scatters by ~0.03 Hz (1 sd), its
  // width by ~15 %.
  EXPECT_NEAR(line->centre_hz, 5.0, 0.1);
  EXPECT_NEAR(line->width_hz, -std::log(r) * kRate / std::numbers::pi, 0.3 * 0.485);
  EXPECT_EQ(find(res, ModelEffect::Unexplained), nullptr) << describe(res);
}

TEST(ModelCheck, BroadbandColourIsUnexplainedNotForcedIntoTheCatalogue) {
  // A heavily damped resonance (poles 0.8·e^{±2πi·10/50}): a bump 3.6 Hz wide at 10 Hz,
  // broader than any line (2 Hz). No catalogue entry is like it (no line, no Gauss–Markov, no
  // step): unexplained, at short τ.
  SimulationModel m;
  m.rate_hz = kRate;
  m.axes[0].terms.arw_deg_per_sqrt_h = 0.4;
  m.axes[0].terms.bias_instability_deg_per_h = 8.0;
  const double r = 0.8, theta = 2.0 * std::numbers::pi * 10.0 / kRate;
  m.axes[0].ar.phi = {2.0 * r * std::cos(theta), -r * r};
  m.axes[0].ar.noise_var = 4e-3;
  NoiseSimulator sim(m, 150.0, 43);
  std::vector<double> x(sim.sampleCount());
  for (double& v : x) v = sim.next().rate_dps[0];
  ModelCheckOptions o = testOptions(43);
  o.replicas = 8;
  const AxisModelCheck res = checkAxisModel({x, kRate, {}, {}, {}}, o);
  const DetectedEffect* u = find(res, ModelEffect::Unexplained);
  ASSERT_NE(u, nullptr) << describe(res);
  EXPECT_EQ(find(res, ModelEffect::NarrowbandLine), nullptr) << describe(res);
  EXPECT_LE(u->where_lo, 0.05);  // where: around τ ≈ 1/(2·10 Hz)
  EXPECT_GE(u->where_hi, 0.05);
}

TEST(ModelCheck, ResultDoesNotDependOnTheNumberOfThreads) {
  const GeneratedRecording g = generate(43, {ModelEffect::Sinusoid});
  ModelCheckOptions one = testOptions(5), two = testOptions(5);
  one.threads = 1;
  two.threads = 3;
  const std::size_t a = g.hidden[0].axis;
  const AxisModelCheck r1 = checkAxisModel({g.axes[a], kRate, g.temp, g.t, {}}, one);
  const AxisModelCheck r2 = checkAxisModel({g.axes[a], kRate, g.temp, g.t, {}}, two);
  ASSERT_EQ(r1.effects.size(), r2.effects.size());
  for (std::size_t i = 0; i < r1.effects.size(); ++i) EXPECT_EQ(r1.effects[i].evidence, r2.effects[i].evidence);
  EXPECT_EQ(r1.gain.adev_log_error_extended, r2.gain.adev_log_error_extended);
  EXPECT_EQ(r1.allan_base.lo, r2.allan_base.lo);
}

TEST(ModelCheck, BadInputIsRejectedNamingTheProblem) {
  std::vector<double> x(5000, 0.0), t(4000, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(static_cast<double>(i));
  EXPECT_THROW(checkAxisModel({std::span<const double>(x).first(100), kRate, {}, {}, {}}), std::invalid_argument);
  EXPECT_THROW(checkAxisModel({x, 0.0, {}, {}, {}}), std::invalid_argument);
  EXPECT_THROW(checkAxisModel({x, kRate, t, {}, {}}), std::invalid_argument);
  EXPECT_THROW(checkAxisModel({x, kRate, {}, t, {}}), std::invalid_argument);
  ModelCheckOptions o;
  o.replicas = 3;
  EXPECT_THROW(checkAxisModel({x, kRate, {}, {}, {}}, o), std::invalid_argument);
  x[17] = std::nan("");
  try {
    checkAxisModel({x, kRate, {}, {}, {}});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sample 17"), std::string::npos) << e.what();
  }
}
