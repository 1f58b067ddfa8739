// The acceptance rule of the model check (docs/model-check.md, "An extension is accepted only
// if it gains"): each hidden effect, and two at once, is found and its extension gains out of
// sample (fresh replicas for the Allan figures, the held-back half of the record for the
// Kalman figures); removing outliers leaves the Allan curve the base model predicts; the
// issue's case (50 of 50 spikes found, yet the axis called unexplained and the extension
// scored worse) is a regression test; an extension that does not gain is "seen, not explained".
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kGainDuration = 600.0;
constexpr double kGainRate = 50.0;

ModelCheckOptions options(std::uint64_t seed) {
  ModelCheckOptions o;
  o.seed = seed;
  o.threads = 2;
  return o;
}

std::string describeGain(const AxisModelCheck& r) {
  std::string s;
  for (const DetectedEffect& e : r.effects)
    s += std::string(modelEffectName(e.effect)) + (e.explained ? "" : " (not explained)") + "; ";
  const ModelCheckGain& g = r.gain;
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "adev %.4g -> %.4g, band %.3f -> %.3f, held-out innovation var %.5g -> %.5g, held-out LB p %.3g -> "
                "%.3g",
                g.adev_log_error_base, g.adev_log_error_extended, g.in_band_base, g.in_band_extended,
                g.innovation_var_base_held_out, g.innovation_var_extended_held_out, g.ljung_box_p_base_held_out,
                g.ljung_box_p_extended_held_out);
  s += buf;
  if (g.tail_judged) {
    std::snprintf(buf, sizeof buf, ", held-out tail %zu (expected %.3g / %.3g, log likelihood %.4g -> %.4g)",
                  g.tail_count_held_out, g.tail_expected_base_held_out, g.tail_expected_extended_held_out,
                  g.tail_log_likelihood_base_held_out, g.tail_log_likelihood_extended_held_out);
    s += buf;
  }
  return s;
}

bool has(const AxisModelCheck& r, ModelEffect e) {
  for (const DetectedEffect& d : r.effects)
    if (d.effect == e) return true;
  return false;
}

// The gain on every measure: none worse beyond the rule's allowance, one better, the
// extension accepted, every effect explained, nothing unexplained.
void expectGain(const AxisModelCheck& r, const std::string& what) {
  const ModelCheckGain& g = r.gain;
  EXPECT_TRUE(r.verdict.judged) << what << ": " << describeGain(r);
  EXPECT_TRUE(r.verdict.accepted) << what << ": " << describeGain(r);
  EXPECT_LE(g.innovation_var_extended_held_out, g.innovation_var_base_held_out) << what << ": " << describeGain(r);
  EXPECT_LE(g.innovation_var_extended, g.innovation_var_base) << what << ": " << describeGain(r);
  EXPECT_LE(g.adev_log_error_extended, 1.5 * g.adev_log_error_base + 0.002) << what << ": " << describeGain(r);
  EXPECT_GE(g.in_band_extended, g.in_band_base - 0.2) << what << ": " << describeGain(r);
  EXPECT_FALSE(has(r, ModelEffect::Unexplained)) << what << ": " << describeGain(r);
  for (const DetectedEffect& e : r.effects) EXPECT_TRUE(e.explained) << what << ": " << describeGain(r);
}

AxisModelCheck checkHiddenAxis(const GeneratedRecording& g, std::size_t axis, std::uint64_t seed) {
  return checkAxisModel({g.axes[axis], g.rate_hz, g.temp, g.t, {}}, options(seed));
}

}  // namespace

// The case: an axis with 50 isolated spikes. All 50 were found, yet the axis was called
// unexplained at τ 0.02–0.5 s and the extension scored worse (ADEV log error 0.0104 → 0.0120,
// in-band 1.00 → 0.59). Six seeds.
TEST(ModelCheckGain, FiftySpikesAreFoundAndTheExtensionGains) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    HiddenEffectGenerator gen(seed);
    gen.outlier_count_lo = gen.outlier_count_hi = 50;
    const GeneratedRecording g = gen.generate(kGainDuration, kGainRate, {ModelEffect::Outliers});
    const AxisModelCheck r = checkHiddenAxis(g, g.hidden[0].axis, seed);
    ASSERT_TRUE(has(r, ModelEffect::Outliers)) << "seed " << seed << ": " << describeGain(r);
    for (const DetectedEffect& e : r.effects)
      if (e.effect == ModelEffect::Outliers) {
        EXPECT_EQ(e.count, 50u) << "seed " << seed;
      }
    expectGain(r, "50 spikes, seed " + std::to_string(seed));
  }
}

// Spikes are white to the Allan variance: with them removed and handed to the extension, its
// replicas must draw the base model's curve: medians within 3 % at every τ, plus a quarter of
// the band's width where 40 replicas pin their median less well (long τ).
TEST(ModelCheckGain, RemovingOutliersLeavesTheBaseModelsAllanCurve) {
  for (std::uint64_t seed : {2u, 5u}) {
    HiddenEffectGenerator gen(seed);
    gen.outlier_count_lo = gen.outlier_count_hi = 50;
    const GeneratedRecording g = gen.generate(kGainDuration, kGainRate, {ModelEffect::Outliers});
    const AxisModelCheck r = checkHiddenAxis(g, g.hidden[0].axis, seed);
    ASSERT_EQ(r.allan_base.tau_s.size(), r.allan_extended.tau_s.size());
    for (std::size_t j = 0; j < r.allan_base.tau_s.size(); ++j)
      EXPECT_NEAR(r.allan_extended.median[j] / r.allan_base.median[j], 1.0,
                  0.03 + 0.25 * (r.allan_base.hi[j] - r.allan_base.lo[j]) / r.allan_base.median[j])
          << "seed " << seed << ", tau " << r.allan_base.tau_s[j];
  }
}

// Each catalogue effect hidden alone (clear sizes, as the blind tests use), then two at once.
TEST(ModelCheckGain, EachHiddenEffectGainsOutOfSample) {
  struct Case {
    ModelEffect effect;
    std::uint64_t seed;
  };
  for (const Case& c :
       {Case{ModelEffect::Sinusoid, 7}, Case{ModelEffect::TemperatureBias, 17}, Case{ModelEffect::Outliers, 11},
        Case{ModelEffect::BiasSteps, 19}, Case{ModelEffect::GaussMarkov, 23}}) {
    HiddenEffectGenerator gen(c.seed);
    gen.step_size_lo = 20.0;
    gen.step_size_hi = 30.0;
    gen.gm_tau_hi_fraction = 1.0 / 300.0;
    gen.gm_peak_lo = 2.5;
    gen.gm_peak_hi = 3.5;
    const GeneratedRecording g = gen.generate(kGainDuration, kGainRate, {c.effect});
    const AxisModelCheck r = checkHiddenAxis(g, g.hidden[0].axis, c.seed);
    const std::string what(modelEffectName(c.effect));
    ASSERT_TRUE(has(r, c.effect)) << what << ": " << describeGain(r);
    expectGain(r, what);
  }
}

TEST(ModelCheckGain, TwoEffectsAtOnceGainOutOfSample) {
  struct Case {
    ModelEffect a, b;
    std::uint64_t seed;
  };
  for (const Case& c : {Case{ModelEffect::Sinusoid, ModelEffect::TemperatureBias, 31},
                        Case{ModelEffect::Outliers, ModelEffect::BiasSteps, 37},
                        Case{ModelEffect::Outliers, ModelEffect::Sinusoid, 41}}) {
    HiddenEffectGenerator gen(c.seed);
    gen.step_size_lo = 20.0;
    gen.step_size_hi = 30.0;
    const GeneratedRecording g = gen.generate(kGainDuration, kGainRate, {c.a, c.b});
    for (std::size_t axis = 0; axis < 3; ++axis) {
      std::vector<ModelEffect> hidden;
      for (const HiddenEffect& h : g.hidden)
        if (h.axis == axis) hidden.push_back(h.effect);
      if (hidden.empty()) continue;
      const AxisModelCheck r = checkHiddenAxis(g, axis, c.seed);
      const std::string what = std::string(modelEffectName(c.a)) + " + " + std::string(modelEffectName(c.b)) +
                               ", axis " + std::to_string(axis);
      for (ModelEffect e : hidden) EXPECT_TRUE(has(r, e)) << what << ": " << describeGain(r);
      expectGain(r, what);
    }
  }
}

// An extension that is not accepted was better on no more measures than it was worse on.
TEST(ModelCheckGain, AnExtensionThatDoesNotGainIsSeenNotExplained) {
  // Broadband colour (a resonance 3.6 Hz wide at 10 Hz: poles 0.8·e^{±2πi·10/50}) is
  // outside the catalogue: whatever the check names on it must not be accepted as
  // an explanation unless it gains; either way the axis is `unexplained`
  // (tests/processing/test_model_check.cpp has the colour alone).
  HiddenEffectGenerator gen(3);
  const GeneratedRecording g = gen.generate(kGainDuration, kGainRate, {});
  std::vector<double> x = g.axes[0];
  double a1 = 0.0, a2 = 0.0;
  NormalGenerator n(9);
  const double phi1 = 2.0 * 0.8 * std::cos(2.0 * std::numbers::pi * 10.0 / 50.0), phi2 = -0.64;
  for (double& v : x) {
    const double r = phi1 * a1 + phi2 * a2 + 0.05 * n.next();
    a2 = a1;
    a1 = r;
    v += r;
  }
  const AxisModelCheck r = checkAxisModel({x, g.rate_hz, g.temp, g.t, {}}, options(3));
  EXPECT_TRUE(has(r, ModelEffect::Unexplained)) << describeGain(r);
  for (const DetectedEffect& e : r.effects)
    if (!e.explained) {
      EXPECT_FALSE(r.verdict.accepted) << describeGain(r);
    }
  if (r.verdict.judged && !r.verdict.accepted) {
    const ExtensionVerdict& v = r.verdict;
    const int worse =
        int{v.adev_worse} + int{v.band_worse} + int{v.innovation_worse} + int{v.ljung_box_worse} + int{v.tail_worse};
    const int better = int{v.adev_better} + int{v.band_better} + int{v.innovation_better} + int{v.ljung_box_better} +
                       int{v.tail_better};
    EXPECT_LE(better, worse);
  }
}

// Outliers are judged by a measure that sees them (issue 36, item 2): the held-back half's
// innovations beyond 5 sigma, whose count the base model puts at its Gaussian tail (~0.01 in
// 15 000 samples) and the extended model at that plus the first half's rate of named outliers.
// The generator's outliers (3-30 per axis) at 6-30 x the white sd, the smallest a little above
// what the robust z names, twelve seeds: the outliers named, the extension accepted and, when
// they are the only effect named, judged without the Allan measures (its curve is then the base
// model's by construction), and wherever the
// first half named some and the second half has any beyond 5 sigma, the tail better beyond its
// allowance; never worse.
TEST(ModelCheckGain, OutliersGainOnTheHeldOutTail) {
  std::size_t tail_compared = 0;
  for (std::uint64_t seed = 61; seed <= 72; ++seed) {
    HiddenEffectGenerator gen(seed);
    gen.outlier_size_lo = 6.0;
    const GeneratedRecording g = gen.generate(kGainDuration, kGainRate, {ModelEffect::Outliers});
    const AxisModelCheck r = checkHiddenAxis(g, g.hidden[0].axis, seed);
    const std::string what = "seed " + std::to_string(seed) + ", " + std::to_string(g.hidden[0].count) + " hidden";
    ASSERT_TRUE(has(r, ModelEffect::Outliers)) << what << ": " << describeGain(r);
    const ModelCheckGain& gain = r.gain;
    ASSERT_TRUE(gain.tail_judged) << what;
    bool alone = true;
    for (const DetectedEffect& e : r.effects) alone = alone && e.effect == ModelEffect::Outliers;
    EXPECT_EQ(r.verdict.allan_judged, !alone) << what << ": " << describeGain(r);
    EXPECT_TRUE(r.verdict.accepted) << what << ": " << describeGain(r);
    EXPECT_FALSE(r.verdict.tail_worse) << what << ": " << describeGain(r);
    EXPECT_NEAR(gain.tail_expected_base_held_out, 0.0086, 0.001) << what;
    if (gain.tail_expected_extended_held_out >= 1.0 && gain.tail_count_held_out >= 1) {
      ++tail_compared;
      EXPECT_TRUE(r.verdict.tail_better) << what << ": " << describeGain(r);
      EXPECT_GT(gain.tail_log_likelihood_extended_held_out, gain.tail_log_likelihood_base_held_out + 3.0)
          << what << ": " << describeGain(r);
    }
  }
  EXPECT_GE(tail_compared, 8u);
}
