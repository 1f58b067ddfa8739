// The still detector on simulated white rate noise (the case its probabilities are stated
// for): the false-moving rate at rest and the false-still probability under a constant
// rotation against the header's formulas, motion with zero mean caught by the difference
// test, and the parameter checks.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "processing/motion/still_detector.hpp"
#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kRateHz = 50.0;

SimulationModel whiteNoiseModel() {
  SimulationModel m;  // pure: white rate noise at the output rate, nothing else
  m.rate_hz = kRateHz;
  for (auto& axis : m.axes) axis.terms.arw_deg_per_sqrt_h = 0.95;
  return m;
}

std::array<StillNoiseLevel, kMotionAxes> levelsOf(const SimulationModel& m, std::size_t window) {
  std::array<StillNoiseLevel, kMotionAxes> levels{};
  for (std::size_t a = 0; a < kMotionAxes; ++a) levels[a] = stillNoiseLevelFromTerms(m.axes[a].terms, kRateHz, window);
  return levels;
}

struct WindowCount {
  std::size_t windows = 0, still = 0;
  double fraction() const { return static_cast<double>(still) / static_cast<double>(windows); }
};

// Decisions at the end of non-overlapping windows (independent trials) over `seconds`.
WindowCount countStillWindows(StillDetector& detector, NoiseSimulator& sim, double seconds) {
  WindowCount count;
  const auto samples = static_cast<std::size_t>(seconds * kRateHz);
  const AngularRate zero{};
  for (std::size_t i = 1; i <= samples; ++i) {
    const SimulatedSample s = sim.next();
    const bool still = detector.update(s.rate_dps, zero, zero);
    if (i % detector.windowSamples() == 0) {
      ++count.windows;
      count.still += still ? 1 : 0;
    }
  }
  return count;
}

// |observed − p| within 4.5 binomial standard deviations (plus a floor for tiny p).
void expectBinomial(const WindowCount& c, double p, const char* what) {
  const double sd = std::sqrt(p * (1.0 - p) / static_cast<double>(c.windows));
  std::printf("%s: observed %.4f, stated %.4f (±%.4f, %zu windows)\n", what, c.fraction(), p, sd, c.windows);
  EXPECT_NEAR(c.fraction(), p, 4.5 * sd + 1.0 / static_cast<double>(c.windows)) << what;
}

}  // namespace

TEST(StillDetector, FalseMovingRateAtRestIsTheStatedOne) {
  const SimulationModel m = whiteNoiseModel();
  StillDetectorParameters p;  // W = 25, z = 3, αd = 1e-3
  StillDetector detector(p, levelsOf(m, p.window_samples));
  NoiseSimulator sim(m, 4000.0, 11);
  const WindowCount c = countStillWindows(detector, sim, 4000.0);
  expectBinomial(c, 1.0 - detector.falseMovingProbability(), "P(still | at rest)");
}

TEST(StillDetector, FalseStillUnderAConstantRotationIsTheStatedOne) {
  const SimulationModel m = whiteNoiseModel();
  StillDetectorParameters p;
  p.window_samples = 50;
  for (double fraction_of_resolution : {0.5, 1.0, 1.5}) {
    StillDetector detector(p, levelsOf(m, p.window_samples));
    const double resolution = p.mean_threshold_sigmas * std::sqrt(detector.windowVariance(1));
    const double omega = fraction_of_resolution * resolution;
    NoiseSimulator sim(m, 1500.0, 100 + static_cast<std::uint64_t>(10 * fraction_of_resolution),
                       MotionProfile::constant(1, omega));
    const WindowCount c = countStillWindows(detector, sim, 1500.0);
    char what[96];
    std::snprintf(what, sizeof what, "P(still | %.4f deg/s = %.1f x resolution)", omega, fraction_of_resolution);
    expectBinomial(c, detector.falseStillProbability(1, omega), what);
  }
}

TEST(StillDetector, MotionWithZeroMeanIsCaughtByTheDifferenceTest) {
  const SimulationModel m = whiteNoiseModel();
  StillDetectorParameters p;
  p.window_samples = 50;  // exactly one period of the 1 Hz sine: its window mean is 0
  StillDetector detector(p, levelsOf(m, p.window_samples));
  // 5 °/s at 1 Hz changes by up to 0.63 °/s from sample to sample, 4× the noise's 0.16 °/s
  // (σ of a difference, √2·σ0): the mean test cannot see it, the difference test must.
  NoiseSimulator sim(m, 120.0, 5, MotionProfile::sine(0, 1.0, 5.0, 10.0));
  const AngularRate zero{};
  std::size_t still_during_sine = 0, still_before = 0;
  for (int i = 0; i < 6000; ++i) {
    const SimulatedSample s = sim.next();
    const bool still = detector.update(s.rate_dps, zero, zero);
    if (s.t_s >= 11.0) still_during_sine += still ? 1 : 0;  // a whole window into the sine
    if (s.t_s >= 1.0 && s.t_s < 10.0) still_before += still ? 1 : 0;
  }
  EXPECT_EQ(still_during_sine, 0u);
  EXPECT_GT(still_before, 400u);  // of 450
}

TEST(StillDetector, AStepIsSeenAsSoonAsTheWindowMeanCanShowIt) {
  // A large step shows in the difference at once; a small one once the part of the window it
  // fills moves the mean past z·σm, i.e. after about W·z·σm/step samples.
  const SimulationModel m = whiteNoiseModel();
  for (const double step : {10.0, 0.5}) {
    StillDetector detector(StillDetectorParameters{}, levelsOf(m, 25));
    const double samples_needed = 25.0 * 3.0 * std::sqrt(detector.windowVariance(2)) / step;
    const auto allowed = static_cast<std::size_t>(std::ceil(2.0 * samples_needed));
    NoiseSimulator sim(m, 60.0, 9, MotionProfile::step(2, 20.0, step));
    const AngularRate zero{};
    std::size_t after_step = 0;
    for (int i = 0; i < 1500; ++i) {
      const SimulatedSample s = sim.next();
      const bool still = detector.update(s.rate_dps, zero, zero);
      if (s.t_s < 20.0) continue;
      ++after_step;
      if (after_step > allowed) {
        ASSERT_FALSE(still) << "step " << step << ", sample " << after_step << " after it";
      }
    }
    std::printf("step %.1f deg/s: moving from at most %zu samples after it\n", step, allowed);
  }
}

TEST(StillDetector, TheRingIsRecomputedSoRunningSumsDoNotDrift) {
  const SimulationModel m = whiteNoiseModel();
  StillDetector detector(StillDetectorParameters{}, levelsOf(m, 25));
  const AngularRate zero{};
  for (int i = 0; i < 200000; ++i) {  // large values pass through, then small ones
    const double big = (i % 2 == 0 ? 1e6 : -1e6) + i;
    detector.update({big, 0.0, 0.0}, zero, zero);
  }
  for (int i = 0; i < 25; ++i) detector.update({0.001, 0.0, 0.0}, zero, zero);
  EXPECT_NEAR(detector.windowMean(0), 0.001, 1e-15);
}

TEST(StillDetector, BadParametersNameTheParameter) {
  const auto levels = levelsOf(whiteNoiseModel(), 25);
  auto message = [&](StillDetectorParameters p, std::array<StillNoiseLevel, kMotionAxes> l) -> std::string {
    try {
      StillDetector d(p, l);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  StillDetectorParameters p;
  p.window_samples = 2;
  EXPECT_NE(message(p, levels).find("still.window_samples"), std::string::npos);
  p = {};
  p.mean_threshold_sigmas = 0.0;
  EXPECT_NE(message(p, levels).find("still.mean_threshold_sigmas"), std::string::npos);
  p = {};
  p.difference_false_alarm = 1.0;
  EXPECT_NE(message(p, levels).find("still.difference_false_alarm"), std::string::npos);
  auto bad = levels;
  bad[2].sample_allan_variance = 0.0;
  const std::string msg = message({}, bad);
  EXPECT_NE(msg.find("axis z: sample_allan_variance"), std::string::npos) << msg;
}

// ---- with the accelerometer -------------------------------------------------------------

namespace {

// The white-noise gyro of the tests above with an accelerometer of 2 mg per sample at 50 Hz
// (N = 2 mg·/√50 Hz = 283 µg/√Hz, a little quieter than the product spec's 400 µg/√Hz).
SimulationModel withAccel(double sigma_g = 0.002) {
  SimulationModel m = whiteNoiseModel();
  m.accel = AccelModel{};
  for (auto& axis : m.accel->axes) axis.velocity_random_walk_g_per_sqrt_hz = sigma_g / std::sqrt(kRateHz);
  return m;
}

struct Verdicts {
  WindowCount gyro_only, with_accel;
};

// Both detectors see the same samples from `from_s` on; only one is fed the accel.
Verdicts runBoth(const StillDetectorParameters& p, NoiseSimulator& sim, double seconds, double from_s) {
  const auto levels = levelsOf(whiteNoiseModel(), p.window_samples);
  StillDetector gyro_only(p, levels), with_accel(p, levels);
  Verdicts v;
  const AngularRate zero{};
  const auto samples = static_cast<std::size_t>(seconds * kRateHz);
  for (std::size_t i = 1; i <= samples; ++i) {
    const SimulatedSample s = sim.next();
    with_accel.observeAccel(s.accel_g);
    const bool a = gyro_only.update(s.rate_dps, zero, zero);
    const bool b = with_accel.update(s.rate_dps, zero, zero);
    if (s.t_s < from_s || i % p.window_samples != 0) continue;
    ++v.gyro_only.windows;
    ++v.with_accel.windows;
    v.gyro_only.still += a ? 1 : 0;
    v.with_accel.still += b ? 1 : 0;
  }
  return v;
}

}  // namespace

TEST(StillDetectorAccel, ASlowTiltBelowTheGyrosResolutionIsCaughtByTheAccel) {
  const SimulationModel m = withAccel();
  StillDetectorParameters p;  // W = 25, Wa = 250, z = 3, σa = 3 mg
  StillDetector probe(p, levelsOf(m, p.window_samples));
  const double resolution = p.mean_threshold_sigmas * std::sqrt(probe.windowVariance(0));
  const double omega = 0.6 * resolution;  // 0.04 °/s about x: the gyro's mean test passes it mostly
  NoiseSimulator sim(m, 600.0, 21, MotionProfile::constant(0, omega));
  const Verdicts v = runBoth(p, sim, 600.0, 10.0);
  std::printf("tilt at %.4f deg/s (resolution %.4f): still by the gyro alone %.3f, with accel %.3f (%zu windows)\n",
              omega, resolution, v.gyro_only.fraction(), v.with_accel.fraction(), v.gyro_only.windows);
  // The gyro alone: P_fs(0.6·resolution) ≈ 0.88 (header formula).
  EXPECT_NEAR(v.gyro_only.fraction(), probe.falseStillProbability(0, omega), 0.05);
  // The accel sees gravity move by ω/rate = 14 µg per sample against a slope bound of 7.9 µg.
  EXPECT_LT(v.with_accel.fraction(), 0.01);
}

TEST(StillDetectorAccel, AtRestInAnyAttitudeTheAccelRarelyObjects) {
  // Tilted by 30° about y before the record starts (the attitude does not matter, only
  // its steadiness), accel noise at the configured σa: the accel adds about
  // 1 − ((1 − αm)(1 − αd))³ ≈ 1.1 % false moving per window.
  SimulationModel m = withAccel(0.003);
  NoiseSimulator sim(m, 2000.0, 23, MotionProfile::constant(1, 30.0, 0.0, 1.0));
  StillDetectorParameters p;
  const Verdicts v = runBoth(p, sim, 2000.0, 10.0);
  std::printf("at rest: still by the gyro alone %.4f, with accel %.4f (%zu windows)\n", v.gyro_only.fraction(),
              v.with_accel.fraction(), v.gyro_only.windows);
  EXPECT_GT(v.gyro_only.fraction(), 0.97);
  EXPECT_GT(v.with_accel.fraction(), v.gyro_only.fraction() - 0.04);
  EXPECT_LE(v.with_accel.still, v.gyro_only.still);  // the accel can only veto
}

TEST(StillDetectorAccel, VibrationOnTheAccelAloneIsCaughtByItsDifferenceTest) {
  // A board on a vibrating table that does not rotate: 20 mg at 7 Hz on z, no gyro signal.
  StillDetectorParameters p;
  const auto levels = levelsOf(whiteNoiseModel(), p.window_samples);
  StillDetector d(p, levels);
  NoiseSimulator sim(withAccel(), 60.0, 31);
  const AngularRate zero{};
  std::size_t still = 0;
  for (int i = 0; i < 3000; ++i) {
    SimulatedSample s = sim.next();
    s.accel_g[2] += 0.02 * portableSinOfCycles(7.0 * s.t_s);
    d.observeAccel(s.accel_g);
    if (d.update(s.rate_dps, zero, zero) && i >= 250) ++still;
  }
  EXPECT_EQ(still, 0u);
}

TEST(StillDetectorAccel, WithoutAccelTheVerdictsAreExactlyTheGyrosAlone) {
  // NaN accel (a device without it) and no accel at all give the same verdicts sample by sample.
  const SimulationModel m = whiteNoiseModel();
  StillDetectorParameters p;
  StillDetector plain(p, levelsOf(m, p.window_samples)), fed_nan(p, levelsOf(m, p.window_samples));
  NoiseSimulator sim(m, 200.0, 41, MotionProfile::sine(2, 0.2, 0.3, 50.0, 50.0));
  const AngularRate zero{};
  const std::array<double, 3> none = {std::nan(""), std::nan(""), std::nan("")};
  std::size_t still = 0;
  for (int i = 0; i < 10000; ++i) {
    const SimulatedSample s = sim.next();
    fed_nan.observeAccel(none);
    const bool a = plain.update(s.rate_dps, zero, zero);
    ASSERT_EQ(fed_nan.update(s.rate_dps, zero, zero), a) << "sample " << i;
    EXPECT_FALSE(fed_nan.usingAccel());
    still += a ? 1 : 0;
  }
  EXPECT_GT(still, 1000u);  // the comparison covered both verdicts
  EXPECT_LT(still, 10000u);
}

TEST(StillDetectorAccel, BadAccelParametersNameTheParameter) {
  const auto levels = levelsOf(whiteNoiseModel(), 25);
  auto message = [&](StillDetectorParameters p) -> std::string {
    try {
      StillDetector d(p, levels);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  StillDetectorParameters p;
  p.accel_window_samples = 2;
  EXPECT_NE(message(p).find("still.accel_window_samples"), std::string::npos);
  p = {};
  p.accel_noise_g = 0.0;
  EXPECT_NE(message(p).find("still.accel_noise_g"), std::string::npos);
}
