#pragma once
// Test data for the model check: a static 3-axis recording of base-model noise (the
// paper's five terms, random per axis, quantised as an MPU6050 at FS_SEL 0) with a
// realistic temperature channel that always moves (warm-up + room cycle + noise), and
// hidden effects from the catalogue with random parameters on random axes. Everything
// comes from the seed. The check under test never sees this file's choices: it gets the
// columns t, gx, gy, gz, temp only.
//
// Effect sizes are drawn relative to the axis's own noise so that a hidden effect is
// detectable in principle but not obvious (ranges below, and in docs/model-check.md).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "processing/model_check.hpp"
#include "processing/noise_simulator.hpp"
#include "processing/noise_terms.hpp"
#include "processing/portable_random.hpp"

namespace gyrod::test {

using processing::ModelEffect;

struct HiddenEffect {
  ModelEffect effect = ModelEffect::Unexplained;
  std::size_t axis = 0;  // 0..2 (sample_gaps: all axes)
  double k_dps_per_c = 0.0;
  double freq_hz = 0.0, amp_dps = 0.0;
  double tau_s = 0.0, sigma_dps = 0.0;
  std::vector<double> times_s, sizes_dps;  // bias steps
  std::size_t count = 0;                   // steps, outliers, gaps
  std::size_t lost = 0;                    // gaps
};

struct GeneratedRecording {
  double rate_hz = 50.0;
  std::vector<double> t, temp;
  std::array<std::vector<double>, 3> axes;
  std::array<processing::NoiseTerms, 3> terms;  // the base model of each axis
  std::vector<HiddenEffect> hidden;
};

// The effects a generator may hide (the catalogue; `unexplained` is not an effect one hides).
inline constexpr std::array<ModelEffect, 6> kHideableEffects = {
    ModelEffect::TemperatureBias, ModelEffect::Sinusoid, ModelEffect::GaussMarkov,
    ModelEffect::BiasSteps,       ModelEffect::Outliers, ModelEffect::SampleGaps};

class HiddenEffectGenerator {
 public:
  explicit HiddenEffectGenerator(std::uint64_t seed) : rng_(seed) {}

  // Size range of a hidden bias step, in multiples of the axis's smallest Allan deviation
  // over τ = 2–128 s. The default is the rates script's range, which reaches down to where
  // detection stops being certain (docs/model-check.md, detection by size); a unit test that
  // asserts the exact count and times of *clear* steps asks for larger ones.
  double step_size_lo = 10.0, step_size_hi = 20.0;
  // A hidden Gauss–Markov process: T log-uniform from 1 s to duration × gm_tau_hi_fraction,
  // σ such that its Allan-deviation peak is gm_peak_lo..gm_peak_hi × the base model's there.
  double gm_tau_hi_fraction = 1.0 / 40.0;
  double gm_peak_lo = 1.5, gm_peak_hi = 3.0;

  double uniform(double lo, double hi) { return lo + (hi - lo) * rng_.uniform(); }
  double logUniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  std::size_t integer(std::size_t lo, std::size_t hi) {  // inclusive
    return lo + static_cast<std::size_t>(rng_.uniform() * static_cast<double>(hi - lo + 1));
  }
  ModelEffect randomEffect() { return kHideableEffects[integer(0, kHideableEffects.size() - 1)]; }

  // `effects`: what to hide, each on a random axis (several may share one).
  GeneratedRecording generate(double duration_s, double rate_hz, const std::vector<ModelEffect>& effects) {
    GeneratedRecording g;
    g.rate_hz = rate_hz;
    const auto n = static_cast<std::size_t>(std::floor(duration_s * rate_hz + 1e-9));
    processing::SimulationModel model;
    model.rate_hz = rate_hz;
    model.fs_sel = 0;  // 131 LSB per deg/s, as the MPU6050 at ±250 deg/s
    std::array<double, 3> white_std{}, flat_adev{};
    for (std::size_t a = 0; a < 3; ++a) {
      processing::NoiseTerms& t = g.terms[a];
      t.quantization_urad = uniform(0.0, 5.0);
      t.arw_deg_per_sqrt_h = uniform(0.25, 0.8);
      t.bias_instability_deg_per_h = uniform(3.0, 20.0);
      t.rrw_deg_per_h_sqrt_h = uniform(0.0, 10.0);
      model.axes[a].terms = t;
      model.axes[a].bias_dps = uniform(-2.0, 2.0);
      white_std[a] = t.arw_deg_per_sqrt_h / 60.0 * std::sqrt(rate_hz);
      flat_adev[a] = processing::kBiasInstabilityFactor * t.bias_instability_deg_per_h / 3600.0;
    }
    // Temperature: warm-up of ΔW over τw from room temperature, a room cycle, sensor noise.
    const double room = uniform(18.0, 28.0), warm = uniform(3.0, 12.0), tau_w = uniform(200.0, 900.0);
    const double cycle_amp = uniform(0.3, 1.5), cycle_period = uniform(1200.0, 5400.0), cycle_phase = uniform(0.0, 6.283);
    std::vector<double> true_temp(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double t = static_cast<double>(i) / rate_hz;
      true_temp[i] = room + warm * (1.0 - std::exp(-t / tau_w)) +
                     cycle_amp * std::sin(2.0 * std::numbers::pi * t / cycle_period + cycle_phase);
    }
    const double temp_residual_std = detrendedStd(true_temp);

    std::vector<HiddenEffect> gaps;
    for (ModelEffect e : effects) {
      HiddenEffect h;
      h.effect = e;
      h.axis = integer(0, 2);
      processing::AxisExtraEffects& extra = model.axes[h.axis].extra;
      const processing::NoiseTerms& terms = g.terms[h.axis];
      switch (e) {
        case ModelEffect::TemperatureBias:
          // |k|·(rms detrended temperature) = 3..10 × the bias-instability floor.
          h.k_dps_per_c = (rng_.uniform() < 0.5 ? -1.0 : 1.0) * uniform(3.0, 10.0) * flat_adev[h.axis] / temp_residual_std;
          break;
        case ModelEffect::Sinusoid:
          h.freq_hz = logUniform(0.2, 0.4 * rate_hz);
          h.amp_dps = uniform(0.1, 0.5) * white_std[h.axis];
          extra.sinusoids.push_back({h.freq_hz, h.amp_dps, uniform(0.0, 6.283)});
          break;
        case ModelEffect::GaussMarkov: {
          h.tau_s = logUniform(1.0, duration_s * gm_tau_hi_fraction);
          // Peak of its Allan deviation 1.5..3 × the base model's there.
          double peak_ratio = 0.0, at = 0.0;
          for (double tau = h.tau_s / 10.0; tau < h.tau_s * 10.0; tau *= 1.05) {
            const double r = processing::gaussMarkovAllanVariance(tau, h.tau_s, 1.0) /
                             processing::allanVarianceOfTerms(terms, tau);
            if (r > peak_ratio) {
              peak_ratio = r;
              at = tau;
            }
          }
          (void)at;
          h.sigma_dps = uniform(gm_peak_lo, gm_peak_hi) / std::sqrt(peak_ratio);
          extra.gauss_markov_tau_s = h.tau_s;
          extra.gauss_markov_sigma_dps = h.sigma_dps;
          break;
        }
        case ModelEffect::BiasSteps: {
          h.count = integer(1, 3);
          // Sizes 10..20 × the smallest base Allan deviation over τ = 2..128 s (a step of D
          // shows as a Haar difference of D against a noise sd of about √2·σ(τ)).
          double floor_adev = 1e300;
          for (double tau = 2.0; tau <= 128.0; tau *= 2.0)
            floor_adev = std::min(floor_adev, std::sqrt(processing::allanVarianceOfTerms(terms, tau)));
          while (h.times_s.size() < h.count) {
            const double t = uniform(0.1, 0.9) * duration_s;
            bool apart = true;
            for (double u : h.times_s) apart = apart && std::fabs(u - t) > 0.1 * duration_s;
            if (apart) h.times_s.push_back(t);
          }
          std::sort(h.times_s.begin(), h.times_s.end());
          for (double t : h.times_s) {
            h.sizes_dps.push_back((rng_.uniform() < 0.5 ? -1.0 : 1.0) * uniform(step_size_lo, step_size_hi) * floor_adev);
            extra.bias_steps.push_back({t, h.sizes_dps.back()});
          }
          break;
        }
        case ModelEffect::Outliers:
          h.count = integer(3, 30);
          extra.outlier_count += h.count;
          extra.outlier_amplitude_dps = uniform(10.0, 30.0) * white_std[h.axis];
          break;
        case ModelEffect::SampleGaps:
          h.count = integer(1, 5);
          for (std::size_t j = 0; j < h.count; ++j) h.lost += integer(1, 50);
          gaps.push_back(h);
          break;
        case ModelEffect::Unexplained:
          break;
      }
      g.hidden.push_back(h);
    }

    processing::NoiseSimulator sim(model, duration_s, next64());
    for (auto& axis : g.axes) axis.resize(n);
    g.temp.resize(n);
    g.t.resize(n);
    processing::NormalGenerator temp_noise(next64());
    double temp_mean = 0.0;
    for (double v : true_temp) temp_mean += v / static_cast<double>(n);
    for (std::size_t i = 0; i < n; ++i) {
      const processing::SimulatedSample s = sim.next();
      g.t[i] = static_cast<double>(i) / rate_hz;
      for (std::size_t a = 0; a < 3; ++a) g.axes[a][i] = s.rate_dps[a];
      const double measured_temp = true_temp[i] + 0.02 * temp_noise.next();
      g.temp[i] = std::round(measured_temp * 340.0) / 340.0;  // TEMP_OUT resolution
    }
    for (const HiddenEffect& h : g.hidden) {
      if (h.effect != ModelEffect::TemperatureBias) continue;
      for (std::size_t i = 0; i < n; ++i) {
        const double v = g.axes[h.axis][i] + h.k_dps_per_c * (true_temp[i] - temp_mean);
        g.axes[h.axis][i] = std::round(v * 131.0) / 131.0;
      }
    }
    // Gaps: rows removed (a sample lost on the link); t keeps the sample clock.
    for (const HiddenEffect& h : gaps) {
      std::size_t left = h.lost;
      for (std::size_t j = 0; j < h.count; ++j) {
        const std::size_t len = j + 1 == h.count ? left : std::max<std::size_t>(1, std::min(left - (h.count - 1 - j), integer(1, 50)));
        left -= len;
        const std::size_t at = integer(g.t.size() / 10, g.t.size() * 9 / 10);
        eraseRows(g, at, len);
      }
    }
    return g;
  }

 private:
  std::uint64_t next64() { return rng_.next(); }

  static double detrendedStd(const std::vector<double>& x) {
    const double n = static_cast<double>(x.size());
    const double mid = 0.5 * (n - 1.0);
    double mean = 0.0, sxy = 0.0, sxx = 0.0;
    for (double v : x) mean += v / n;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double c = static_cast<double>(i) - mid;
      sxy += c * (x[i] - mean);
      sxx += c * c;
    }
    const double slope = sxy / sxx;
    double ss = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double r = x[i] - mean - slope * (static_cast<double>(i) - mid);
      ss += r * r;
    }
    return std::sqrt(ss / n);
  }

  static void eraseRows(GeneratedRecording& g, std::size_t at, std::size_t len) {
    auto erase = [&](std::vector<double>& v) {
      v.erase(v.begin() + static_cast<std::ptrdiff_t>(at), v.begin() + static_cast<std::ptrdiff_t>(at + len));
    };
    erase(g.t);
    erase(g.temp);
    for (auto& a : g.axes) erase(a);
  }

  processing::Xoshiro256StarStar rng_;
};

}  // namespace gyrod::test
