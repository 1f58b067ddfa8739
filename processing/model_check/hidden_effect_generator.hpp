#pragma once
// Synthetic data for the model check (its tests, bench/model_check_rates.cpp): a static
// 3-axis recording of base-model noise (the paper's five terms, random per axis, quantised
// as an MPU6050 at FS_SEL 0) with a realistic temperature channel that always moves (warm-up
// + room cycle + noise), and hidden effects from the catalogue with random parameters on
// random axes. Everything comes from the seed. The check under test never sees this file's
// choices: it gets the columns t, gx, gy, gz, temp only. Pure: no I/O.
//
// Effect sizes are drawn relative to the axis's own noise so that a hidden effect is
// detectable in principle but not obvious (ranges below, and in docs/model-check.md).
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "processing/base/noise_terms.hpp"
#include "processing/base/portable_random.hpp"
#include "processing/model_check/model_check.hpp"
#include "processing/simulation/noise_simulator.hpp"

namespace gyrod::processing {

struct HiddenEffect {
  ModelEffect effect = ModelEffect::Unexplained;
  std::size_t axis = 0;  // 0..2 (sample_gaps: all axes)
  double k_dps_per_c = 0.0;
  double freq_hz = 0.0, amp_dps = 0.0;                    // sinusoid; outliers: amp_dps the size of each spike
  double centre_hz = 0.0, width_hz = 0.0, rms_dps = 0.0;  // narrowband line
  double tau_s = 0.0, sigma_dps = 0.0;
  std::vector<double> times_s, sizes_dps;  // bias steps
  std::size_t count = 0;                   // steps, outliers, gaps
  std::size_t lost = 0;                    // gaps
};

struct GeneratedRecording {
  double rate_hz = 50.0;
  std::vector<double> t, temp;
  std::array<std::vector<double>, 3> axes;
  std::array<NoiseTerms, 3> terms;  // the base model of each axis
  std::vector<HiddenEffect> hidden;
};

// The effects a generator may hide (the catalogue; `unexplained` is not an effect one hides).
inline constexpr std::array<ModelEffect, 7> kHideableEffects = {
    ModelEffect::TemperatureBias, ModelEffect::Sinusoid,   ModelEffect::GaussMarkov,   ModelEffect::BiasSteps,
    ModelEffect::Outliers,        ModelEffect::SampleGaps, ModelEffect::NarrowbandLine};

class HiddenEffectGenerator {
 public:
  explicit HiddenEffectGenerator(std::uint64_t seed) : rng_(seed) {}

  // Size range of a hidden bias step, in multiples of the axis's smallest Allan deviation
  // over τ = 2–128 s. The default is the rates script's range, which reaches down to where
  // detection stops being certain (docs/model-check.md, detection by size); a unit test that
  // asserts the exact count and times of *clear* steps asks for larger ones.
  double step_size_lo = 10.0, step_size_hi = 20.0;
  // Number of hidden steps on the axis (inclusive range), each at a uniform time in 0.1–0.9 of
  // the record, at least step_min_gap × the duration from the others.
  std::size_t step_count_lo = 1, step_count_hi = 3;
  double step_min_gap = 0.1;
  // A hidden Gauss–Markov process: T log-uniform from 1 s to duration × gm_tau_hi_fraction,
  // σ such that its Allan-deviation peak is gm_peak_lo..gm_peak_hi × the base model's there.
  double gm_tau_hi_fraction = 1.0 / 40.0;
  double gm_peak_lo = 1.5, gm_peak_hi = 3.0;
  // Number of hidden outliers (inclusive range) and their size in multiples of the white sd.
  std::size_t outlier_count_lo = 3, outlier_count_hi = 30;
  double outlier_size_lo = 10.0, outlier_size_hi = 30.0;
  // A hidden narrowband line: centre uniform over 5 Hz .. 0.4 × rate (real MPU6050 lines sit
  // at 11–38 Hz; below ~5 Hz a wandering line's own centre scatters by more than 1 % over
  // 10 min: its bootstrap interval is ±0.03 Hz at 2 Hz for a width of 0.3 Hz), width uniform
  // over line_width_lo..hi Hz, rms line_rms_lo..hi × the white noise's sd.
  double line_width_lo = 0.1, line_width_hi = 0.5;
  double line_rms_lo = 0.15, line_rms_hi = 0.5;
  // The chip's DLPF (DLPF_CFG 0..6) the recording is made through, as gyrod records it: the
  // analog noise at the internal rate, filtered, decimated to the rate (which must be
  // reachable), then quantised. None: the noise is made at the output rate (no DLPF).
  std::optional<int> dlpf_cfg;

  double uniform(double lo, double hi) { return lo + (hi - lo) * rng_.uniform(); }
  double logUniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  std::size_t integer(std::size_t lo, std::size_t hi) {  // inclusive
    return lo + static_cast<std::size_t>(rng_.uniform() * static_cast<double>(hi - lo + 1));
  }
  ModelEffect randomEffect() { return kHideableEffects[integer(0, kHideableEffects.size() - 1)]; }

  // `effects`: what to hide, each on a random axis (several may share one).
  GeneratedRecording generate(double duration_s, double rate_hz, const std::vector<ModelEffect>& effects);

 private:
  std::uint64_t next64() { return rng_.next(); }
  // The parameters of one hidden effect, drawn; the simulator's extras of its axis get it.
  HiddenEffect drawEffect(ModelEffect e, double duration_s, double rate_hz, double temp_residual_std,
                          const std::array<double, 3>& white_std, const std::array<double, 3>& flat_adev,
                          const std::array<NoiseTerms, 3>& terms, SimulationModel& model);
  void removeGapRows(GeneratedRecording& g, const HiddenEffect& h);

  Xoshiro256StarStar rng_;
};

}  // namespace gyrod::processing
