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
#include "processing/model_check/pipeline.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kMisfitDuration = 240.0;
constexpr double kMisfitRate = 50.0;

ModelCheckOptions misfitOptions(std::uint64_t seed) {
  ModelCheckOptions o;
  o.seed = seed;
  o.threads = 2;
  return o;
}

std::string describeMisfit(const AxisModelCheck& r) {
  std::string s;
  for (const DetectedEffect& e : r.effects)
    s += std::string(modelEffectName(e.effect)) + (e.explained ? "" : " (not explained)") + "; ";
  const ModelMisfit& m = r.misfit;
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "accepted %d; held-out LB p %.3g (AR(%zu)), in band %.3f (replicas: median %.3f, lowest %.3f; p %.3g); "
                "tau %.3g-%.3g s (x%.3g); %.4g-%.4g Hz (x%.3g)",
                int{r.verdict.judged && r.verdict.accepted}, m.ljung_box_p_held_out, m.whiteness_ar_order, m.in_band,
                m.in_band_replica_median, m.in_band_replica_lowest, m.band_p, m.tau_lo_s, m.tau_hi_s, m.adev_ratio,
                m.freq_lo_hz, m.freq_hi_hz, m.power_ratio);
  return s + buf;
}

// A narrow line whose phase is a random walk: amp·sin(φ_i), φ_i = φ_{i−1} + 2πf/rate + δ_i,
// δ_i ~ N(0, s²). Its spectrum is a Lorentzian of full width at half maximum D/π Hz (phase
// diffusion D = s²·rate rad²/s): s² = π·width/rate.
std::vector<double> misfitWanderingLine(std::size_t n, double rate, double freq_hz, double width_hz, double amp,
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

// Band-limited Gaussian noise: one component per Fourier bin of the record between lo_hz and
// hi_hz, Rayleigh amplitudes and uniform phases, scaled to rms `rms`. No catalogued effect is
// a band of noise several hertz wide.
std::vector<double> misfitNoiseBump(std::size_t n, double rate, double lo_hz, double hi_hz, double rms,
                                    std::uint64_t seed) {
  NormalGenerator normal(seed);
  const double df = rate / static_cast<double>(n);
  std::vector<double> x(n, 0.0);
  for (double f = std::ceil(lo_hz / df) * df; f <= hi_hz; f += df) {
    const double a = normal.next(), b = normal.next();
    const double w = 2.0 * std::numbers::pi * f / rate;
    for (std::size_t i = 0; i < n; ++i) {
      const double t = w * static_cast<double>(i);
      x[i] += a * std::cos(t) + b * std::sin(t);
    }
  }
  double ss = 0.0;
  for (double v : x) ss += v * v;
  const double scale = rms / std::sqrt(ss / static_cast<double>(n));
  for (double& v : x) v *= scale;
  return x;
}

double misfitStandardDeviation(const std::vector<double>& x) {
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
  std::vector<double> x = misfitWanderingLine(4400, kMisfitRate, 12.3, 0.3, 0.5, 6);
  for (double& v : x) v += normal.next();
  const SpectralExcess e = innovationSpectralExcess(x, kMisfitRate);
  ASSERT_TRUE(e.found);
  EXPECT_LE(e.freq_lo_hz, 12.3);
  EXPECT_GE(e.freq_hi_hz, 12.3);
  EXPECT_LT(e.freq_hi_hz - e.freq_lo_hz, 2.0);
  EXPECT_GT(e.power_ratio, e.threshold);
}

// Log Allan curves of a right model, drawn as the replicas are: correlated across τ (the
// clusters overlap), wider and skewed at long τ (few clusters).
std::vector<double> jointBandTestCurve(NormalGenerator& normal, std::size_t taus) {
  std::vector<double> curve(taus);
  double walk = 0.0;
  for (std::size_t j = 0; j < taus; ++j) {
    walk = 0.8 * walk + 0.6 * normal.next();
    const double width = 0.02 * std::pow(1.4, static_cast<double>(j));
    const double skewed = walk + 0.3 * (walk * walk - 1.0);
    curve[j] = -0.5 * std::log(1.0 + static_cast<double>(j)) + width * skewed;
  }
  return curve;
}

// The simultaneous band holds a fresh curve of the same model whole about 90 % of the time,
// where the per-τ band holds it whole far less often; each replica's own share is there for
// the band test.
TEST(ModelCheckMisfit, SimultaneousBandHoldsNinetyPercentOfWholeCurves) {
  constexpr std::size_t kTaus = 15, kReplicas = 40, kTrials = 100, kFresh = 20;
  model_check_detail::Context c;
  for (std::size_t j = 0; j < kTaus; ++j) {
    c.ms.push_back(std::size_t{1} << j);
    c.taus.push_back(0.02 * static_cast<double>(c.ms.back()));
  }
  NormalGenerator normal(77);
  std::size_t whole_joint = 0, whole_per_tau = 0, curves = 0;
  double share_sum = 0.0;
  for (std::size_t trial = 0; trial < kTrials; ++trial) {
    std::vector<model_check_detail::SeriesStats> reps(kReplicas);
    for (auto& r : reps) r.log_adev = jointBandTestCurve(normal, kTaus);
    const model_check_detail::AllanNull null = model_check_detail::allanNull(reps, reps.front().log_adev, c, 0.01);
    const AllanBand& b = null.band;
    ASSERT_EQ(b.joint_lo.size(), kTaus);
    ASSERT_EQ(b.replica_in_joint_band.size(), kReplicas);
    for (std::size_t f = 0; f < kFresh; ++f) {
      const std::vector<double> fresh = jointBandTestCurve(normal, kTaus);
      std::size_t in_joint = 0, in_per_tau = 0;
      for (std::size_t j = 0; j < kTaus; ++j) {
        const double v = std::exp(fresh[j]);
        in_joint += (v >= b.joint_lo[j] && v <= b.joint_hi[j]) ? 1 : 0;
        in_per_tau += (v >= b.lo[j] && v <= b.hi[j]) ? 1 : 0;
      }
      whole_joint += in_joint == kTaus ? 1 : 0;
      whole_per_tau += in_per_tau == kTaus ? 1 : 0;
      share_sum += static_cast<double>(in_joint) / static_cast<double>(kTaus);
      ++curves;
    }
  }
  const double joint = static_cast<double>(whole_joint) / static_cast<double>(curves);
  const double per_tau = static_cast<double>(whole_per_tau) / static_cast<double>(curves);
  RecordProperty("whole_joint", std::to_string(joint));
  RecordProperty("whole_per_tau", std::to_string(per_tau));
  EXPECT_GT(joint, 0.84);
  EXPECT_LT(joint, 0.95);
  EXPECT_LT(per_tau, 0.7);
  EXPECT_GT(share_sum / static_cast<double>(curves), 0.98);
}

// Clean records fit: no effect, both tests pass, nothing is placed; the whiteness test saw a
// held-out p at or above 1e-3 (the rule the text's "holds" rests on).
TEST(ModelCheckMisfit, CleanRecordsFit) {
  for (std::uint64_t seed : {201u, 202u}) {
    const GeneratedRecording g = HiddenEffectGenerator(seed).generate(kMisfitDuration, kMisfitRate, {});
    for (std::size_t a = 0; a < 3; ++a) {
      const AxisModelCheck r = checkAxisModel({g.axes[a], g.rate_hz, g.temp, g.t, {}}, misfitOptions(seed));
      const std::string what = "seed " + std::to_string(seed) + " axis " + std::to_string(a) + ": " + describeMisfit(r);
      EXPECT_TRUE(r.effects.empty()) << what;
      EXPECT_FALSE(r.misfit.fails()) << what;
      EXPECT_GE(r.misfit.ljung_box_p_held_out, kMisfitWhitenessP) << what;
      EXPECT_TRUE(std::isnan(r.misfit.tau_lo_s)) << what;
      EXPECT_TRUE(std::isnan(r.misfit.freq_lo_hz)) << what;
      EXPECT_TRUE(r.misfit.joint_band) << what;
      EXPECT_EQ(r.misfit.in_band, r.allan_base.measured_in_joint_band) << what;
      EXPECT_EQ(r.allan_base.replica_in_joint_band.size(), misfitOptions(seed).replicas) << what;
    }
  }
}

// Clean records through the narrowest DLPF (the generator's noise through the simulator's
// filter at the internal rate, told to the check): they fit. AR(p ≤ 8) by AIC against
// χ²(30 − p) gave held-out p down to 1e-9 on such records (docs/model-check.md, "Misfit").
TEST(ModelCheckMisfit, CleanDlpfRecordsFit) {
  for (std::uint64_t seed : {401u, 402u}) {
    HiddenEffectGenerator gen(seed);
    gen.dlpf_cfg = 6;
    const GeneratedRecording g = gen.generate(kMisfitDuration, kMisfitRate, {});
    for (std::size_t a = 0; a < 3; ++a) {
      const AxisModelCheck r = checkAxisModel({g.axes[a], g.rate_hz, g.temp, g.t, {6, 0}}, misfitOptions(seed));
      const std::string what = "seed " + std::to_string(seed) + " axis " + std::to_string(a) + ": " + describeMisfit(r);
      EXPECT_FALSE(r.misfit.fails()) << what;
      EXPECT_GE(r.misfit.ljung_box_p_held_out, kMisfitWhitenessP) << what;
      EXPECT_EQ(r.misfit.whiteness_q > 0.0, true) << what;
    }
  }
}

// The block Ljung–Box on white noise: its mean-removal bias is taken off, so Q has the mean
// of χ²(lags) (30), within 3 standard errors over 200 series.
TEST(ModelCheckMisfit, BlockLjungBoxIsChiSquareOnWhiteNoise) {
  double sum = 0.0;
  const std::size_t series = 200;
  for (std::uint64_t seed = 1; seed <= series; ++seed) {
    NormalGenerator normal(seed);
    std::vector<double> x(8192);
    for (double& v : x) v = normal.next();
    sum += blockLjungBox(x, 30, kWhitenessBlock).q;
  }
  const double mean = sum / static_cast<double>(series);
  EXPECT_NEAR(mean, 30.0, 3.0 * std::sqrt(60.0 / static_cast<double>(series)));
}

// The halves' colour statistic on white noise has the mean of χ²(kHalvesLags), within 3
// standard errors over 200 series; the spectrum statistic is finite and at a frequency inside
// (0, Nyquist).
TEST(ModelCheckMisfit, HalvesColourIsChiSquareOnWhiteNoise) {
  double sum = 0.0;
  const std::size_t series = 200;
  for (std::uint64_t seed = 1; seed <= series; ++seed) {
    NormalGenerator normal(seed + 7000);
    std::vector<double> x(8000);
    for (double& v : x) v = normal.next();
    const HalvesChange h = halvesChange(x, kMisfitRate);
    sum += h.colour_q;
    ASSERT_TRUE(std::isfinite(h.spectrum_stat));
    EXPECT_GT(h.spectrum_hz, 0.0);
    EXPECT_LT(h.spectrum_hz, kMisfitRate / 2);
  }
  const double lags = static_cast<double>(kHalvesLags);
  EXPECT_NEAR(sum / static_cast<double>(series), lags, 3.0 * std::sqrt(2.0 * lags / static_cast<double>(series)));
}

// A series whose second half is coloured (AR(1), φ 0.15) and one whose line moves from 9 to
// 9.6 Hz halfway: each stands far outside white noise's own statistics (40 series), on the
// statistic that sees it, and names the change (the lag-1 autocorrelations; the bin).
TEST(ModelCheckMisfit, AColourChangeAndAMovingLineAreSeenBetweenHalves) {
  const std::size_t n = 12000;
  std::vector<double> null_colour, null_spectrum;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    NormalGenerator normal(seed + 9000);
    std::vector<double> x(n);
    for (double& v : x) v = normal.next();
    const HalvesChange h = halvesChange(x, kMisfitRate);
    null_colour.push_back(h.colour_q);
    null_spectrum.push_back(h.spectrum_stat);
  }
  NormalGenerator normal(77);
  std::vector<double> coloured(n), moving(n);
  double previous = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double e = normal.next();
    coloured[i] = i < n / 2 ? e : 0.15 * previous + e;
    previous = coloured[i];
    const double f = i < n / 2 ? 9.0 : 9.6;
    moving[i] = normal.next() + 0.3 * std::sin(2.0 * std::numbers::pi * f * static_cast<double>(i) / kMisfitRate);
  }
  const HalvesChange c = halvesChange(coloured, kMisfitRate);
  EXPECT_LT(gumbelNullP(c.colour_q, null_colour), 1e-4) << c.colour_q;
  EXPECT_NEAR(c.lag1_first, 0.0, 0.05);
  EXPECT_NEAR(c.lag1_second, 0.15, 0.05);
  const HalvesChange m = halvesChange(moving, kMisfitRate);
  EXPECT_LT(gumbelNullP(m.spectrum_stat, null_spectrum), 1e-4) << m.spectrum_stat;
  const double bin = kMisfitRate / 256.0;  // the segment for 6000-sample halves
  const bool at_a_line = std::fabs(m.spectrum_hz - 9.0) <= bin || std::fabs(m.spectrum_hz - 9.6) <= bin;
  EXPECT_TRUE(at_a_line) << m.spectrum_hz;
  EXPECT_GT(gumbelNullP(c.spectrum_stat, null_spectrum), 1e-4);  // a colour change of 0.15 is no line
}

// A generated record whose noise turns coloured halfway (AR(1), φ 0.15, on axis 0): what the
// first half's model leaves of the second is not white, and the misfit says the record
// changed between its halves.
TEST(ModelCheckMisfit, ARecordThatChangesColourIsToldApart) {
  GeneratedRecording g = HiddenEffectGenerator(601).generate(kMisfitDuration, kMisfitRate, {});
  std::vector<double>& x = g.axes[0];
  double mean = 0.0;
  for (std::size_t i = x.size() / 2; i < x.size(); ++i) mean += x[i];
  mean /= static_cast<double>(x.size() - x.size() / 2);
  double previous = 0.0;  // the filter runs on the deviations: the level stays, no step
  for (std::size_t i = x.size() / 2; i < x.size(); ++i) {
    previous = (x[i] - mean) + 0.15 * previous;
    x[i] = mean + previous;
  }
  const AxisModelCheck r = checkAxisModel({x, g.rate_hz, g.temp, g.t, {}}, misfitOptions(601));
  const std::string what = describeMisfit(r) + "; halves colour p " + std::to_string(r.misfit.halves_colour_p);
  EXPECT_TRUE(r.misfit.fails() || r.misfit.marginal) << what;
  EXPECT_TRUE(r.misfit.halves_differ) << what;
  EXPECT_LT(r.misfit.halves_colour_p, kHalvesAlpha / 2) << what;
  EXPECT_GT(r.misfit.halves_lag1_second - r.misfit.halves_lag1_first, 0.05) << what;
}

// A band of noise 4 Hz wide (not in the catalogue) of the axis's rms on one axis: the model
// does not fit, placed in frequency around the band. The AR model of the whiteness test
// whitens a stationary bump largely, so the band test and the spectrum against the replicas
// carry it.
TEST(ModelCheckMisfit, ANoiseBumpDoesNotFitAndIsPlaced) {
  for (std::uint64_t seed : {501u, 502u}) {
    GeneratedRecording g = HiddenEffectGenerator(seed).generate(kMisfitDuration, kMisfitRate, {});
    std::vector<double>& x = g.axes[0];
    const std::vector<double> bump =
        misfitNoiseBump(x.size(), kMisfitRate, 6.0, 10.0, misfitStandardDeviation(x), seed);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += bump[i];
    const AxisModelCheck r = checkAxisModel({x, g.rate_hz, g.temp, g.t, {}}, misfitOptions(seed));
    const std::string what = "seed " + std::to_string(seed) + ": " + describeMisfit(r);
    EXPECT_TRUE(r.misfit.fails()) << what;
    EXPECT_LE(r.misfit.freq_lo_hz, 10.0) << what;
    EXPECT_GE(r.misfit.freq_hi_hz, 6.0) << what;
    EXPECT_LT(r.misfit.freq_hi_hz, 20.0) << what;
    EXPECT_GT(r.misfit.power_ratio, 1.5) << what;
  }
}

// A line whose frequency wanders (0.3 Hz wide, of the axis's rms) is the catalogue's
// narrowband line: named near its frequency, and the extended model with it fits.
TEST(ModelCheckMisfit, AWanderingLineIsNamedAndTheExtendedModelFits) {
  for (std::uint64_t seed : {301u, 302u}) {
    GeneratedRecording g = HiddenEffectGenerator(seed).generate(kMisfitDuration, kMisfitRate, {});
    std::vector<double>& x = g.axes[1];
    const double freq = 7.3 + 0.5 * static_cast<double>(seed - 301);
    const std::vector<double> line =
        misfitWanderingLine(x.size(), kMisfitRate, freq, 0.3, misfitStandardDeviation(x), seed);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += line[i];
    const AxisModelCheck r = checkAxisModel({x, g.rate_hz, g.temp, g.t, {}}, misfitOptions(seed));
    const std::string what = "seed " + std::to_string(seed) + ": " + describeMisfit(r);
    bool named = false;
    for (const DetectedEffect& e : r.effects)
      named = named || (e.effect == ModelEffect::NarrowbandLine && std::fabs(e.centre_hz - freq) < 0.1);
    EXPECT_TRUE(named) << what;
    EXPECT_FALSE(r.misfit.fails()) << what;
  }
}

// The clean-record figures of docs/model-check.md, "Misfit" (--gtest_also_run_disabled_tests).
TEST(ModelCheckMisfit, DISABLED_Survey) {
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    const GeneratedRecording g = HiddenEffectGenerator(seed).generate(kMisfitDuration, kMisfitRate, {});
    for (std::size_t a = 0; a < 3; ++a) {
      const AxisModelCheck r = checkAxisModel({g.axes[a], g.rate_hz, g.temp, g.t, {}}, misfitOptions(seed));
      std::printf("clean seed %llu axis %zu: %s\n", static_cast<unsigned long long>(seed), a,
                  describeMisfit(r).c_str());
    }
  }
}
