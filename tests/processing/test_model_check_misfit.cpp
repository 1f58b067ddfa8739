// The misfit of the model the check ends with (docs/model-check.md, "Misfit"): the spectral
// excess test is calibrated on white noise; a clean generated record fits; a record with a
// narrow line whose phase wanders (not in the catalogue: no fixed sinusoid takes it out) does
// not, and the misfit names a frequency band holding the line's centre.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "processing/base/portable_random.hpp"
#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kDuration = 240.0;
constexpr double kRate = 50.0;

ModelCheckOptions options(std::uint64_t seed) {
  ModelCheckOptions o;
  o.seed = seed;
  o.threads = 2;
  return o;
}

std::string describe(const AxisModelCheck& r) {
  std::string s;
  for (const DetectedEffect& e : r.effects)
    s += std::string(modelEffectName(e.effect)) + (e.explained ? "" : " (not explained)") + "; ";
  const ModelMisfit& m = r.misfit;
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "accepted %d; held-out LB p %.3g, in band %.3f; tau %.3g-%.3g s (x%.3g); %.4g-%.4g Hz (x%.3g)",
                int{r.verdict.judged && r.verdict.accepted}, m.ljung_box_p_held_out, m.in_band, m.tau_lo_s, m.tau_hi_s,
                m.adev_ratio, m.freq_lo_hz, m.freq_hi_hz, m.power_ratio);
  return s + buf;
}

// A narrow line whose phase is a random walk: amp·sin(φ_i), φ_i = φ_{i−1} + 2πf/rate + δ_i,
// δ_i ~ N(0, s²). Its spectrum is a Lorentzian of full width at half maximum D/π Hz (phase
// diffusion D = s²·rate rad²/s): s² = π·width/rate.
std::vector<double> wanderingLine(std::size_t n, double rate, double freq_hz, double width_hz, double amp,
                                  std::uint64_t seed) {
  NormalGenerator normal(seed);
  const double s = std::sqrt(std::numbers::pi * width_hz / rate);
  std::vector<double> x(n);
  double phase = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    phase += 2.0 * std::numbers::pi * freq_hz / rate + s * normal.next();
    x[i] = amp * std::sin(phase);
  }
  return x;
}

double standardDeviation(const std::vector<double>& x) {
  double m = 0.0, ss = 0.0;
  for (double v : x) m += v;
  m /= static_cast<double>(x.size());
  for (double v : x) ss += (v - m) * (v - m);
  return std::sqrt(ss / static_cast<double>(x.size()));
}

}  // namespace

// White noise of the length of a short record's held-back half: a band stands out in about
// 1e-3 of series by construction (Bonferroni over the bins); allow a few in 300.
TEST(ModelCheckMisfit, WhiteNoiseRarelyShowsSpectralExcess) {
  for (std::size_t n : {4400u, 30000u}) {
    std::size_t found = 0;
    for (std::uint64_t seed = 1; seed <= (n > 10000 ? 60u : 300u); ++seed) {
      NormalGenerator normal(seed);
      std::vector<double> x(n);
      for (double& v : x) v = 0.3 * normal.next();
      const SpectralExcess e = innovationSpectralExcess(x, 50.0);
      found += e.found ? 1 : 0;
      EXPECT_GT(e.threshold, 1.0);
    }
    EXPECT_LE(found, 3u) << n << " samples";
  }
}

TEST(ModelCheckMisfit, SpectralExcessFindsALine) {
  NormalGenerator normal(5);
  std::vector<double> x = wanderingLine(4400, kRate, 12.3, 0.3, 0.5, 6);
  for (double& v : x) v += normal.next();
  const SpectralExcess e = innovationSpectralExcess(x, kRate);
  ASSERT_TRUE(e.found);
  EXPECT_LE(e.freq_lo_hz, 12.3);
  EXPECT_GE(e.freq_hi_hz, 12.3);
  EXPECT_LT(e.freq_hi_hz - e.freq_lo_hz, 2.0);
  EXPECT_GT(e.power_ratio, e.threshold);
}

// Not every clean record passes the two tests (docs/model-check.md, "Misfit": on the
// generator's records about a third of the axes fail the whiteness test, a tenth the band
// test; ModelCheckMisfit.DISABLED_Survey prints them). This one passes both on every axis,
// and then nothing may be stated.
TEST(ModelCheckMisfit, ACleanRecordFits) {
  for (std::uint64_t seed : {201u}) {
    const GeneratedRecording g = HiddenEffectGenerator(seed).generate(kDuration, kRate, {});
    for (std::size_t a = 0; a < 3; ++a) {
      const AxisModelCheck r = checkAxisModel({g.axes[a], g.rate_hz, g.temp, g.t, {}}, options(seed));
      const std::string what = "seed " + std::to_string(seed) + " axis " + std::to_string(a) + ": " + describe(r);
      EXPECT_TRUE(r.effects.empty()) << what;
      EXPECT_FALSE(r.misfit.fails()) << what;
      EXPECT_TRUE(std::isnan(r.misfit.tau_lo_s)) << what;
      EXPECT_TRUE(std::isnan(r.misfit.freq_lo_hz)) << what;
      EXPECT_EQ(r.misfit.ljung_box_p_held_out, r.gain.ljung_box_p_base_held_out) << what;
      EXPECT_EQ(r.misfit.in_band, r.gain.in_band_base) << what;
    }
  }
}

TEST(ModelCheckMisfit, AWanderingLineDoesNotFitAndIsPlaced) {
  for (std::uint64_t seed : {301u, 302u}) {
    GeneratedRecording g = HiddenEffectGenerator(seed).generate(kDuration, kRate, {});
    std::vector<double>& x = g.axes[1];
    const double freq = 7.3 + 0.5 * static_cast<double>(seed - 301);
    const std::vector<double> line = wanderingLine(x.size(), kRate, freq, 0.3, standardDeviation(x), seed);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += line[i];
    const AxisModelCheck r = checkAxisModel({x, g.rate_hz, g.temp, g.t, {}}, options(seed));
    const std::string what = "seed " + std::to_string(seed) + ": " + describe(r);
    EXPECT_TRUE(r.misfit.fails()) << what;
    EXPECT_LE(r.misfit.freq_lo_hz, freq) << what;
    EXPECT_GE(r.misfit.freq_hi_hz, freq) << what;
    EXPECT_LT(r.misfit.freq_hi_hz - r.misfit.freq_lo_hz, 2.0) << what;
    EXPECT_GT(r.misfit.power_ratio, 2.0) << what;
  }
}

// The clean-record figures of docs/model-check.md, "Misfit" (--gtest_also_run_disabled_tests).
TEST(ModelCheckMisfit, DISABLED_Survey) {
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    const GeneratedRecording g = HiddenEffectGenerator(seed).generate(kDuration, kRate, {});
    for (std::size_t a = 0; a < 3; ++a) {
      const AxisModelCheck r = checkAxisModel({g.axes[a], g.rate_hz, g.temp, g.t, {}}, options(seed));
      std::printf("clean seed %llu axis %zu: %s\n", static_cast<unsigned long long>(seed), a, describe(r).c_str());
    }
  }
}
