// Synthetic recordings with hidden effects for the model check; see hidden_effect_generator.hpp.
#include "processing/model_check/hidden_effect_generator.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "processing/simulation/noise_simulator.hpp"

namespace gyrod::processing {
namespace {

// Standard deviation of x about its least-squares line.
double detrendedStd(const std::vector<double>& x) {
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

// Rows [at, at + len) removed from every column.
void eraseRows(GeneratedRecording& g, std::size_t at, std::size_t len) {
  auto erase = [&](std::vector<double>& v) {
    v.erase(v.begin() + static_cast<std::ptrdiff_t>(at), v.begin() + static_cast<std::ptrdiff_t>(at + len));
  };
  erase(g.t);
  erase(g.temp);
  for (auto& a : g.axes) erase(a);
}

}  // namespace

HiddenEffect HiddenEffectGenerator::drawEffect(ModelEffect e, double duration_s, double rate_hz,
                                               double temp_residual_std, const std::array<double, 3>& white_std,
                                               const std::array<double, 3>& flat_adev,
                                               const std::array<NoiseTerms, 3>& axis_terms, SimulationModel& model) {
  HiddenEffect h;
  h.effect = e;
  h.axis = integer(0, 2);
  AxisExtraEffects& extra = model.axes[h.axis].extra;
  const NoiseTerms& terms = axis_terms[h.axis];
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
        const double r = gaussMarkovAllanVariance(tau, h.tau_s, 1.0) / allanVarianceOfTerms(terms, tau);
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
      h.count = integer(step_count_lo, step_count_hi);
      // Sizes 10..20 × the smallest base Allan deviation over τ = 2..128 s (a step of D
      // shows as a Haar difference of D against a noise sd of about √2·σ(τ)).
      double floor_adev = 1e300;
      for (double tau = 2.0; tau <= 128.0; tau *= 2.0)
        floor_adev = std::min(floor_adev, std::sqrt(allanVarianceOfTerms(terms, tau)));
      while (h.times_s.size() < h.count) {
        const double t = uniform(0.1, 0.9) * duration_s;
        bool apart = true;
        for (double u : h.times_s) apart = apart && std::fabs(u - t) > step_min_gap * duration_s;
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
      h.count = integer(outlier_count_lo, outlier_count_hi);
      extra.outlier_count += h.count;
      extra.outlier_amplitude_dps = uniform(outlier_size_lo, outlier_size_hi) * white_std[h.axis];
      h.amp_dps = extra.outlier_amplitude_dps;  // the size of every spike (the coverage bench checks it)
      break;
    case ModelEffect::SampleGaps:
      h.count = integer(1, 5);
      for (std::size_t j = 0; j < h.count; ++j) h.lost += integer(1, 50);
      break;
    case ModelEffect::NarrowbandLine:
      h.centre_hz = uniform(5.0, 0.4 * rate_hz);
      h.width_hz = uniform(line_width_lo, line_width_hi);
      h.rms_dps = uniform(line_rms_lo, line_rms_hi) * white_std[h.axis];
      extra.narrowband_lines.push_back({h.centre_hz, h.width_hz, h.rms_dps});
      break;
    case ModelEffect::Unexplained: break;
  }
  return h;
}

void HiddenEffectGenerator::removeGapRows(GeneratedRecording& g, const HiddenEffect& h) {
  std::size_t left = h.lost;
  for (std::size_t j = 0; j < h.count; ++j) {
    const std::size_t len =
        j + 1 == h.count ? left : std::max<std::size_t>(1, std::min(left - (h.count - 1 - j), integer(1, 50)));
    left -= len;
    const std::size_t at = integer(g.t.size() / 10, g.t.size() * 9 / 10);
    eraseRows(g, at, len);
  }
}

namespace {

void simulateAtOutputRate(const SimulationModel& model, std::size_t n, std::uint64_t seed, GeneratedRecording& g) {
  NoiseSimulator sim(model, static_cast<double>(n) / model.rate_hz, seed);
  for (std::size_t i = 0; i < n; ++i) {
    const SimulatedSample s = sim.next();
    for (std::size_t a = 0; a < 3; ++a) g.axes[a][i] = s.rate_dps[a];
  }
}

// Through the DLPF as gyrod records: gyrod lets the chip settle before it reads (the
// simulator starts its DLPF at the first noisy analog sample, a transient of a few output
// samples), so the noise is simulated one second early and that second dropped; the effects
// (added after the DLPF in the simulator, too) come from a model of their own on the
// recording's clock, and the sum is quantised as the chip does.
void simulateThroughDlpf(const SimulationModel& model, std::size_t n, std::uint64_t seed, GeneratedRecording& g) {
  SimulationModel noise = model, effects;
  noise.fs_sel.reset();
  effects.rate_hz = model.rate_hz;
  for (std::size_t a = 0; a < 3; ++a) {
    noise.axes[a].extra = {};
    effects.axes[a].extra = model.axes[a].extra;
  }
  const auto lead = static_cast<std::size_t>(std::ceil(model.rate_hz));
  NoiseSimulator noise_sim(noise, static_cast<double>(n + lead) / model.rate_hz, seed);
  NoiseSimulator effect_sim(effects, static_cast<double>(n) / model.rate_hz, seed);
  for (std::size_t i = 0; i < lead; ++i) noise_sim.next();
  const double lsb = model.fs_sel ? gyroSensitivityLsbPerDps(*model.fs_sel) : 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const SimulatedSample s = noise_sim.next(), e = effect_sim.next();
    for (std::size_t a = 0; a < 3; ++a) {
      const double v = s.rate_dps[a] + e.rate_dps[a];
      g.axes[a][i] = lsb > 0.0 ? std::round(v * lsb) / lsb : v;
    }
  }
}

}  // namespace

GeneratedRecording HiddenEffectGenerator::generate(double duration_s, double rate_hz,
                                                   const std::vector<ModelEffect>& effects) {
  GeneratedRecording g;
  g.rate_hz = rate_hz;
  const auto n = static_cast<std::size_t>(std::floor(duration_s * rate_hz + 1e-9));
  SimulationModel model;
  model.rate_hz = rate_hz;
  model.fs_sel = 0;  // 131 LSB per deg/s, as the MPU6050 at ±250 deg/s
  model.dlpf_cfg = dlpf_cfg;
  std::array<double, 3> white_std{}, flat_adev{};
  for (std::size_t a = 0; a < 3; ++a) {
    NoiseTerms& t = g.terms[a];
    t.quantization_urad = uniform(0.0, 5.0);
    t.arw_deg_per_sqrt_h = uniform(0.25, 0.8);
    t.bias_instability_deg_per_h = uniform(3.0, 20.0);
    t.rrw_deg_per_h_sqrt_h = uniform(0.0, 10.0);
    model.axes[a].terms = t;
    model.axes[a].bias_dps = uniform(-2.0, 2.0);
    white_std[a] = t.arw_deg_per_sqrt_h / 60.0 * std::sqrt(rate_hz);
    flat_adev[a] = kBiasInstabilityFactor * t.bias_instability_deg_per_h / 3600.0;
  }
  // Temperature: warm-up of ΔW over τw from room temperature, a room cycle, sensor noise.
  const double room = uniform(18.0, 28.0), warm = uniform(3.0, 12.0), tau_w = uniform(200.0, 900.0);
  const double cycle_amp = uniform(0.3, 1.5), cycle_period = uniform(1200.0, 5400.0);
  const double cycle_phase = uniform(0.0, 6.283);
  std::vector<double> true_temp(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / rate_hz;
    true_temp[i] = room + warm * (1.0 - std::exp(-t / tau_w)) +
                   cycle_amp * std::sin(2.0 * std::numbers::pi * t / cycle_period + cycle_phase);
  }
  const double temp_residual_std = detrendedStd(true_temp);

  std::vector<HiddenEffect> gaps;
  for (ModelEffect e : effects) {
    const HiddenEffect h = drawEffect(e, duration_s, rate_hz, temp_residual_std, white_std, flat_adev, g.terms, model);
    if (e == ModelEffect::SampleGaps) gaps.push_back(h);
    g.hidden.push_back(h);
  }

  const std::uint64_t sim_seed = next64();
  for (auto& axis : g.axes) axis.resize(n);
  if (dlpf_cfg)
    simulateThroughDlpf(model, n, sim_seed, g);
  else
    simulateAtOutputRate(model, n, sim_seed, g);
  g.temp.resize(n);
  g.t.resize(n);
  NormalGenerator temp_noise(next64());
  double temp_mean = 0.0;
  for (double v : true_temp) temp_mean += v / static_cast<double>(n);
  for (std::size_t i = 0; i < n; ++i) {
    g.t[i] = static_cast<double>(i) / rate_hz;
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
  for (const HiddenEffect& h : gaps) removeGapRows(g, h);
  return g;
}

}  // namespace gyrod::processing
