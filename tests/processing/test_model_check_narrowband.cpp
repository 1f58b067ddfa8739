// The model check's narrowband lines, blind: a line whose frequency wanders (width 0.1–0.5 Hz,
// simulation/narrowband_line.hpp) hidden by processing/model_check/hidden_effect_generator.hpp
// among the base model's terms and a moving temperature channel; the check sees the columns.
// Rates over many seeds (power, false lines through every DLPF setting) are measured by
// bench/model_check_rates.cpp, not here.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "processing/base/portable_random.hpp"
#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"
#include "processing/model_check/pipeline.hpp"
#include "processing/simulation/narrowband_line.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kNarrowbandDuration = 600.0;
constexpr double kNarrowbandRate = 50.0;

ModelCheckOptions narrowbandOptions(std::uint64_t seed) {
  ModelCheckOptions o;
  o.seed = seed;
  o.threads = 2;
  return o;
}

std::string narrowbandDescribe(const AxisModelCheck& r) {
  std::string s;
  for (const DetectedEffect& e : r.effects) {
    s += std::string(modelEffectName(e.effect));
    if (e.effect == ModelEffect::NarrowbandLine)
      s += " centre " + std::to_string(e.centre_hz) + " width " + std::to_string(e.width_hz) + " rms " +
           std::to_string(e.rms_dps);
    if (e.effect == ModelEffect::Sinusoid) s += " at " + std::to_string(e.freq_hz);
    s += "\n";
  }
  return s.empty() ? "(no effect)" : s;
}

}  // namespace

// Named as a narrowband line on its axis alone, centre within 1 %, width within a factor 1.5,
// rms within a factor 1.3, and the intervals hold the hidden values.
TEST(ModelCheckNarrowband, NamesAHiddenWanderingLineWithCentreWidthAndRms) {
  for (std::uint64_t seed : {21u, 22u, 23u}) {
    // Clear lines (rms 0.3–0.5 × the white sd; the generator reaches down to 0.15): at the
    // low end the width scatters by more than the factor asked (bench/model_check_line_power).
    HiddenEffectGenerator gen(seed);
    gen.line_rms_lo = 0.3;
    const GeneratedRecording g = gen.generate(kNarrowbandDuration, kNarrowbandRate, {ModelEffect::NarrowbandLine});
    const HiddenEffect& h = g.hidden.at(0);
    for (std::size_t a = 0; a < 3; ++a) {
      const AxisModelCheck r = checkAxisModel({g.axes[a], g.rate_hz, g.temp, g.t, {}}, narrowbandOptions(seed));
      std::size_t lines = 0, sinusoids = 0;
      for (const DetectedEffect& e : r.effects) {
        lines += e.effect == ModelEffect::NarrowbandLine ? 1 : 0;
        sinusoids += e.effect == ModelEffect::Sinusoid ? 1 : 0;
      }
      if (a != h.axis) {
        EXPECT_EQ(lines + sinusoids, 0u) << "seed " << seed << " axis " << a << "\n" << narrowbandDescribe(r);
        continue;
      }
      ASSERT_EQ(lines, 1u) << "seed " << seed << " hidden centre " << h.centre_hz << " width " << h.width_hz << "\n"
                           << narrowbandDescribe(r);
      EXPECT_EQ(sinusoids, 0u) << narrowbandDescribe(r);
      for (const DetectedEffect& e : r.effects) {
        if (e.effect != ModelEffect::NarrowbandLine) continue;
        EXPECT_NEAR(e.centre_hz, h.centre_hz, 0.01 * h.centre_hz) << "seed " << seed;
        EXPECT_GT(e.width_hz, h.width_hz / 1.5) << "seed " << seed;
        EXPECT_LT(e.width_hz, h.width_hz * 1.5)
            << "seed " << seed << " hidden " << h.centre_hz << " " << h.width_hz << " " << h.rms_dps << "\n"
            << narrowbandDescribe(r);
        EXPECT_GT(e.rms_dps, h.rms_dps / 1.3) << "seed " << seed;
        EXPECT_LT(e.rms_dps, h.rms_dps * 1.3) << "seed " << seed;
        EXPECT_TRUE(e.centre_interval.stated && e.width_interval.stated && e.rms_interval.stated);
        EXPECT_TRUE(e.explained) << "the extension with the line must gain";
      }
      // The extended model's Kalman filter carries the line: its held-out innovations are
      // smaller than the base model's.
      EXPECT_LT(r.gain.innovation_var_extended_held_out, r.gain.innovation_var_base_held_out);
    }
  }
}

// A fixed sinusoid stays a sinusoid: its width is not resolved.
TEST(ModelCheckNarrowband, AFixedSinusoidIsNotNamedNarrowband) {
  const GeneratedRecording g =
      HiddenEffectGenerator(7).generate(kNarrowbandDuration, kNarrowbandRate, {ModelEffect::Sinusoid});
  const HiddenEffect& h = g.hidden.at(0);
  const AxisModelCheck r = checkAxisModel({g.axes[h.axis], g.rate_hz, g.temp, g.t, {}}, narrowbandOptions(7));
  for (const DetectedEffect& e : r.effects) EXPECT_NE(e.effect, ModelEffect::NarrowbandLine) << narrowbandDescribe(r);
}

// The parts, on a known spectrum: the Whittle fit recovers the resonance it is given, and the
// shrink takes the line's power out of the series and leaves the background's.
TEST(ModelCheckNarrowband, WhittleFitAndShrinkOnAKnownLine) {
  using namespace gyrod::processing::model_check_detail;
  const double rate = 100.0;
  const std::size_t n = 60000;
  const NarrowbandLine line{31.4, 0.3, 0.05};
  const NarrowbandLineRecursion rec = narrowbandLineRecursion(line, rate);
  gyrod::processing::NormalGenerator gauss(5);
  const double white_sd = 0.05;
  std::vector<double> x(n), y(n + 2000, 0.0);
  for (std::size_t i = 2; i < y.size(); ++i)
    y[i] = rec.a1 * y[i - 1] + rec.a2 * y[i - 2] + std::sqrt(rec.drive_var) * gauss.next();
  for (std::size_t i = 0; i < n; ++i) x[i] = white_sd * gauss.next() + y[i + 2000];
  const Periodogram p = hannPeriodogram(x);
  const double df = rate / static_cast<double>(p.nfft);
  std::vector<double> bg = blockMedianBackground(p.power, lineBackgroundBlock(df));
  for (double& v : bg) v *= 2.0 / (rate * p.window_power);
  const NarrowbandFit fit = fitNarrowbandLine(
      onesidedPsd(p, rate), bg, df, rate, static_cast<std::size_t>(line.centre_hz / df), 64, 64, p.power.size() - 10);
  ASSERT_TRUE(fit.fitted);
  EXPECT_TRUE(fit.resolved);
  EXPECT_NEAR(fit.centre_hz, line.centre_hz, 0.02);
  EXPECT_NEAR(fit.width_hz, line.width_hz, 0.3 * line.width_hz);
  EXPECT_NEAR(fit.rms_dps, line.rms_dps, 0.15 * line.rms_dps);
  // White noise of sd s has a one-sided PSD of 2·s²/rate.
  EXPECT_NEAR(fit.background_psd, 2.0 * white_sd * white_sd / rate, 0.1 * 2.0 * white_sd * white_sd / rate);

  double before = 0.0, after = 0.0;
  std::vector<double> shrunk = x;
  shrinkNarrowbandLine(shrunk, {fit.centre_hz, fit.width_hz, fit.rms_dps}, fit.background_psd, rate);
  for (std::size_t i = 0; i < n; ++i) {
    before += x[i] * x[i];
    after += shrunk[i] * shrunk[i];
  }
  // The line's variance (0.05²) is gone, the white noise's (0.05²) stays: 2 → 1 within 5 %.
  EXPECT_NEAR(after / before, 0.5, 0.05);
}

// A line that moves over the record, as the 20 Hz line of the 10-minute real record does
// (20.55 Hz in its first half, 19.93 Hz in its second): a narrowband line at f1 in the first
// half and at f2 = 1.03·f1 in the second (the resonance's state carried across), hidden on a
// clean generator record. Over the whole record the two are one wide bump; the scan of the
// halves names each where it is, centre within 1 %.
TEST(ModelCheckNarrowband, ALineThatMovesBetweenTheHalvesIsNamedInEach) {
  for (std::uint64_t seed : {31u, 32u, 33u}) {
    HiddenEffectGenerator gen(seed);
    GeneratedRecording g = gen.generate(kNarrowbandDuration, kNarrowbandRate, {});
    const double white_sd = g.terms[0].get(NoiseTerm::AngleRandomWalk) / 60.0 * std::sqrt(g.rate_hz);
    const double f1 = gen.uniform(8.0, 16.0), f2 = 1.03 * f1;
    std::vector<double>& x = g.axes[0];
    NormalGenerator drive(seed ^ 0x9E3779B97F4A7C15ULL);
    double y1 = 0.0, y2 = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const NarrowbandLine line{i < x.size() / 2 ? f1 : f2, 0.1, 0.4 * white_sd};
      const NarrowbandLineRecursion r = narrowbandLineRecursion(line, g.rate_hz);
      const double y = r.a1 * y1 + r.a2 * y2 + std::sqrt(r.drive_var) * drive.next();
      y2 = y1;
      y1 = y;
      if (i >= 2000) x[i] += y;  // past the resonance's start from rest (its memory is ~3 s)
    }
    const AxisModelCheck r = checkAxisModel({x, g.rate_hz, g.temp, g.t, {}}, narrowbandOptions(seed));
    bool at_f1 = false, at_f2 = false;
    for (const DetectedEffect& e : r.effects) {
      if (e.effect != ModelEffect::NarrowbandLine && e.effect != ModelEffect::Sinusoid) continue;
      const double f = e.effect == ModelEffect::NarrowbandLine ? e.centre_hz : e.freq_hz;
      at_f1 = at_f1 || std::fabs(f - f1) <= 0.01 * f1;
      at_f2 = at_f2 || std::fabs(f - f2) <= 0.01 * f2;
    }
    EXPECT_TRUE(at_f1 && at_f2) << "seed " << seed << ": hidden " << f1 << " then " << f2 << " Hz\n"
                                << narrowbandDescribe(r);
  }
}

// A line at the top of the band, as the one near 48.8 Hz on the 99.4 Hz records of
// tests/data/mpu6050-sensor-fusion-set2 (98.2 % of Nyquist): hidden at 97.5–99 % of Nyquist on
// a clean generator record, 0.3 Hz wide, it is named as narrowband with its centre within 1 %
// and its width within a factor 1.5.
TEST(ModelCheckNarrowband, ALineNearNyquistIsNamed) {
  for (std::uint64_t seed : {41u, 42u, 43u}) {
    HiddenEffectGenerator gen(seed);
    GeneratedRecording g = gen.generate(kNarrowbandDuration, kNarrowbandRate, {});
    const double white_sd = g.terms[0].get(NoiseTerm::AngleRandomWalk) / 60.0 * std::sqrt(g.rate_hz);
    const NarrowbandLine line{gen.uniform(0.975, 0.99) * g.rate_hz / 2.0, 0.3, 0.4 * white_sd};
    const NarrowbandLineRecursion rec = narrowbandLineRecursion(line, g.rate_hz);
    NormalGenerator drive(seed ^ 0x9E3779B97F4A7C15ULL);
    std::vector<double>& x = g.axes[0];
    double y1 = 0.0, y2 = 0.0;
    for (std::size_t i = 0; i < x.size() + 2000; ++i) {
      const double y = rec.a1 * y1 + rec.a2 * y2 + std::sqrt(rec.drive_var) * drive.next();
      y2 = y1;
      y1 = y;
      if (i >= 2000) x[i - 2000] += y;  // past the resonance's start from rest
    }
    const AxisModelCheck r = checkAxisModel({x, g.rate_hz, g.temp, g.t, {}}, narrowbandOptions(seed));
    std::size_t named = 0;
    for (const DetectedEffect& e : r.effects) {
      if (e.effect != ModelEffect::NarrowbandLine) continue;
      ++named;
      EXPECT_NEAR(e.centre_hz, line.centre_hz, 0.01 * line.centre_hz) << "seed " << seed;
      EXPECT_GT(e.width_hz, line.width_hz / 1.5) << "seed " << seed << "\n" << narrowbandDescribe(r);
      EXPECT_LT(e.width_hz, line.width_hz * 1.5) << "seed " << seed << "\n" << narrowbandDescribe(r);
    }
    EXPECT_EQ(named, 1u) << "seed " << seed << ": hidden at " << line.centre_hz << " Hz\n" << narrowbandDescribe(r);
  }
}
