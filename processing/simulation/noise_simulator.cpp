#include "processing/simulation/noise_simulator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "processing/base/portable_math.hpp"
#include "processing/simulation/motion_profile.hpp"

namespace gyrod::processing {
namespace {

constexpr std::array<const char*, kSimulatedAxes> kAxisNames = {"x", "y", "z"};

// Numbers in messages as the user would write them (std::to_string prints 300.000000).
std::string formatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string axisPrefix(std::size_t axis) { return std::string("axis ") + kAxisNames[axis] + ": "; }

// Accel sensitivity for AFS_SEL 0..3 (product spec §6.2): 16384, 8192, 4096, 2048 LSB per g.
double accelLsbPerG(int afs_sel) { return 16384.0 / static_cast<double>(1 << afs_sel); }

void requireFinite(double v, const std::string& what) {
  if (!std::isfinite(v)) throw std::invalid_argument(what + " must be finite, got " + formatNumber(v));
}
void requireNonNegative(double v, const std::string& what) {
  if (!std::isfinite(v) || v < 0.0)
    throw std::invalid_argument(what + " must be finite and >= 0, got " + formatNumber(v));
}
void requirePositive(double v, const std::string& what) {
  if (!std::isfinite(v) || !(v > 0.0))
    throw std::invalid_argument(what + " must be finite and > 0, got " + formatNumber(v));
}

}  // namespace

// 1 + SMPLRT_DIV for an output rate with the DLPF on: the chip's output rate is
// internal/(1 + SMPLRT_DIV) with SMPLRT_DIV an 8-bit register (register map §4.2).
std::size_t sampleRateDivisor(int dlpf_cfg, double rate_hz) {
  requirePositive(rate_hz, "rate_hz");
  const DlpfSetting& dlpf = dlpfSetting(dlpf_cfg);
  const double ratio = dlpf.internal_rate_hz / rate_hz;
  const double divisor = std::round(ratio);
  if (divisor < 1.0 || divisor > 256.0 || std::fabs(ratio - divisor) > 1e-9 * ratio)
    throw std::invalid_argument("rate_hz " + formatNumber(rate_hz) + " is not possible with DLPF_CFG " +
                                std::to_string(dlpf_cfg) + ": the output rate is the internal rate " +
                                formatNumber(dlpf.internal_rate_hz) +
                                " Hz divided by an integer 1..256 (rate = internal/(1+SMPLRT_DIV))");
  return static_cast<std::size_t>(divisor);
}

namespace {

// Step-down (inverse Levinson–Durbin) recursion: from φ = φ^(p) to the coefficients
// φ^(j) of every lower order and the reflection coefficients k_j = φ^(j)_j. The AR
// model is stationary iff every |k_j| < 1 (Schur–Cohn). Returns φ^(1..p), order j at
// index j−1.
std::vector<std::vector<double>> arStepDown(const std::vector<double>& phi, const std::string& what) {
  const std::size_t p = phi.size();
  std::vector<std::vector<double>> orders(p);
  if (p == 0) return orders;
  orders[p - 1] = phi;
  for (std::size_t j = p; j >= 1; --j) {
    const std::vector<double>& cur = orders[j - 1];
    const double k = cur[j - 1];
    if (!(std::fabs(k) < 1.0))
      throw std::invalid_argument(
          what + "ar.phi is not stationary (reflection coefficient " + std::to_string(j) + " is " + formatNumber(k) +
          ", must be in (-1, 1)): all roots of 1 - sum phi_i z^i must lie outside the unit circle");
    if (j == 1) break;
    std::vector<double>& lower = orders[j - 2];
    lower.resize(j - 1);
    // φ^(j−1)_i = (φ^(j)_i + k_j·φ^(j)_{j−i}) / (1 − k_j²)
    for (std::size_t i = 1; i <= j - 1; ++i) lower[i - 1] = (cur[i - 1] + k * cur[j - i - 1]) / (1.0 - k * k);
  }
  return orders;
}

}  // namespace

void validateArComponent(const ArComponent& ar, const std::string& prefix) {
  requireNonNegative(ar.noise_var, prefix + "ar.noise_var");
  if (ar.phi.size() > 64)
    throw std::invalid_argument(prefix + "ar.phi has " + std::to_string(ar.phi.size()) + " coefficients (at most 64)");
  for (std::size_t i = 0; i < ar.phi.size(); ++i)
    requireFinite(ar.phi[i], prefix + "ar.phi[" + std::to_string(i) + "]");
  arStepDown(ar.phi, prefix);
}

void validateExtraEffects(const AxisExtraEffects& extra, const std::string& prefix) {
  requireFinite(extra.temperature_coefficient_dps_per_c, prefix + "extra.temperature_coefficient_dps_per_c");
  requireFinite(extra.temperature_reference_c, prefix + "extra.temperature_reference_c");
  for (std::size_t i = 0; i < extra.sinusoids.size(); ++i) {
    const std::string w = prefix + "extra.sinusoid[" + std::to_string(i) + "].";
    requirePositive(extra.sinusoids[i].freq_hz, w + "freq_hz");
    requireNonNegative(extra.sinusoids[i].amp_dps, w + "amp_dps");
    requireFinite(extra.sinusoids[i].phase_rad, w + "phase_rad");
  }
  requireNonNegative(extra.gauss_markov_sigma_dps, prefix + "extra.gauss_markov_sigma_dps");
  if (extra.gauss_markov_sigma_dps > 0.0)
    requirePositive(extra.gauss_markov_tau_s, prefix + "extra.gauss_markov_tau_s");
  else
    requireNonNegative(extra.gauss_markov_tau_s, prefix + "extra.gauss_markov_tau_s");
  for (std::size_t i = 0; i < extra.bias_steps.size(); ++i) {
    const std::string w = prefix + "extra.bias_step[" + std::to_string(i) + "].";
    requireNonNegative(extra.bias_steps[i].time_s, w + "time_s");
    requireFinite(extra.bias_steps[i].size_dps, w + "size_dps");
  }
  requireNonNegative(extra.outlier_amplitude_dps, prefix + "extra.outlier_amplitude_dps");
  // centre < rate/2 needs the rate: narrowbandLineRecursionOf checks it where the rate is known.
  for (std::size_t i = 0; i < extra.narrowband_lines.size(); ++i) {
    const std::string w = prefix + "extra.narrowband_line[" + std::to_string(i) + "].";
    requirePositive(extra.narrowband_lines[i].centre_hz, w + "centre_hz");
    requirePositive(extra.narrowband_lines[i].width_hz, w + "width_hz");
    requireNonNegative(extra.narrowband_lines[i].rms_dps, w + "rms_dps");
  }
}

namespace {

// narrowbandLineRecursion with its message naming the line as the model's other keys are
// named ("axis y: extra.narrowband_line[0].centre_hz must be in (0, rate/2 = 25), got 31.4").
NarrowbandLineRecursion narrowbandLineRecursionOf(const NarrowbandLine& line, double rate_hz, const std::string& what) {
  try {
    return narrowbandLineRecursion(line, rate_hz);
  } catch (const std::invalid_argument& e) {
    std::string cause = e.what();
    const std::string generic = "narrowband line: ";
    if (cause.rfind(generic, 0) == 0) cause.erase(0, generic.size());
    throw std::invalid_argument(what + cause);
  }
}

std::string narrowbandLineName(std::size_t axis, std::size_t index) {
  return axisPrefix(axis) + "extra.narrowband_line[" + std::to_string(index) + "].";
}

}  // namespace

void validateSimulationModel(const SimulationModel& model) {
  requirePositive(model.rate_hz, "rate_hz");
  if (model.dlpf_cfg) sampleRateDivisor(*model.dlpf_cfg, model.rate_hz);
  if (model.fs_sel) gyroSensitivityLsbPerDps(*model.fs_sel);
  for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
    const AxisNoiseModel& axis = model.axes[a];
    const std::string prefix = axisPrefix(a);
    for (NoiseTerm t : kAllNoiseTerms) requireNonNegative(axis.terms.get(t), prefix + std::string(noiseTermKey(t)));
    requireFinite(axis.bias_dps, prefix + "bias_dps");
    validateArComponent(axis.ar, prefix);
    validateExtraEffects(axis.extra, prefix);
    for (std::size_t i = 0; i < axis.extra.narrowband_lines.size(); ++i)
      narrowbandLineRecursionOf(axis.extra.narrowband_lines[i], model.rate_hz, narrowbandLineName(a, i));
  }
  const TemperatureModel& temp = model.temperature;
  requireFinite(temp.start_c, "temperature.start_c");
  requireFinite(temp.final_c, "temperature.final_c");
  requirePositive(temp.time_constant_s, "temperature.time_constant_s");
  requireNonNegative(temp.noise_std_c, "temperature.noise_std_c");
  if (model.accel) {
    if (model.accel->afs_sel < 0 || model.accel->afs_sel > 3)
      throw std::invalid_argument("accel.afs_sel must be 0..3, got " + std::to_string(model.accel->afs_sel));
    for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
      const AccelAxisNoise& n = model.accel->axes[a];
      const std::string prefix = "accel " + axisPrefix(a);
      requireFinite(n.bias_g, prefix + "bias_g");
      requireNonNegative(n.velocity_random_walk_g_per_sqrt_hz, prefix + "velocity_random_walk_g_per_sqrt_hz");
      requireNonNegative(n.bias_instability_g, prefix + "bias_instability_g");
      requireNonNegative(n.acceleration_random_walk_g_per_sqrt_s, prefix + "acceleration_random_walk_g_per_sqrt_s");
    }
  }
}

TemperatureModel withWarmUp(TemperatureModel temperature, const WarmUp& warm_up) {
  requireFinite(warm_up.delta_c, "warm-up temperature rise delta_c");
  requirePositive(warm_up.time_constant_s, "warm-up time constant");
  requireNonNegative(warm_up.start_s, "warm-up start");
  temperature.final_c = temperature.start_c + warm_up.delta_c;
  temperature.time_constant_s = warm_up.time_constant_s;
  temperature.delay_s = warm_up.start_s;
  return temperature;
}

double temperatureCurveC(const TemperatureModel& temp, double t_s) {
  // Without a warm-up the curve is final + (+0)·e^{…} = final + 0.0 bit for bit: the exponential
  // is skipped (it was 8 % of a model check's time, which simulates that case).
  const double warmup = temp.start_c - temp.final_c;
  if (warmup == 0.0) return temp.final_c + 0.0;
  if (t_s < temp.delay_s) return temp.start_c;
  return temp.final_c + warmup * portable::exp(-(t_s - temp.delay_s) / temp.time_constant_s);
}

double temperatureCouplingDps(const AxisExtraEffects& extra, const TemperatureModel& temp, double t_s) {
  if (extra.temperature_coefficient_dps_per_c == 0.0) return 0.0;
  return extra.temperature_coefficient_dps_per_c * (temperatureCurveC(temp, t_s) - extra.temperature_reference_c);
}

std::vector<GaussMarkovComponent> flickerGaussMarkovBank(double flat_allan_variance, double tau0_s, double duration_s) {
  requireNonNegative(flat_allan_variance, "flicker Allan variance level");
  requirePositive(tau0_s, "tau0_s");
  requirePositive(duration_s, "duration_s");
  std::vector<GaussMarkovComponent> bank;
  if (flat_allan_variance == 0.0) return bank;
  // A 1/f spectrum is an integral of Lorentzians over ln T with constant weight; with
  // n_d processes per decade each of variance s², the two-sided PSD is s²·n_d/(2·ln10·f)
  // and the Allan variance of h/f (two-sided) is 4·ln2·h. Flat level c needs
  //   s² = c·ln10/(2·ln2·n_d).
  // The lowest T = 1.2·τ0 and the end weights were chosen with the exact discrete-time
  // Allan variance of the bank (docs/simulator.md): flat within ±1.5 % from τ0 up.
  constexpr double kPerDecade = 2.0;
  constexpr double kLowestTimeInTau0 = 1.2;
  constexpr double kHighestTimeInDurations = 5.0;
  const double lowest = kLowestTimeInTau0 * tau0_s;
  const double highest_needed = kHighestTimeInDurations * duration_s;
  std::size_t count = 2;
  if (highest_needed > lowest) {
    const double decades = portable::log(highest_needed / lowest) / std::numbers::ln10;
    count = std::max<std::size_t>(2, static_cast<std::size_t>(std::ceil(decades * kPerDecade - 1e-9)) + 1);
  }
  const double variance = flat_allan_variance * std::numbers::ln10 / (2.0 * std::numbers::ln2 * kPerDecade);
  // The processes beyond each end would add 1/(r − 1) times the end one's contribution
  // in the limit that matters there (white beyond the low end, random walk beyond the
  // high end), r = 10^{1/n_d}.
  const double ratio = portable::exp(std::numbers::ln10 / kPerDecade);
  const double end_factor = ratio / (ratio - 1.0);
  bank.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    bank[i].correlation_time_s = lowest * portable::exp(static_cast<double>(i) * std::numbers::ln10 / kPerDecade);
    bank[i].variance = variance;
  }
  bank.front().variance *= end_factor;
  bank.back().variance *= end_factor;
  return bank;
}

double aliasedWhiteNoiseFactor(int dlpf_cfg, double rate_hz) {
  const std::size_t divisor = sampleRateDivisor(dlpf_cfg, rate_hz);
  const DigitalLowPassFilter filter(dlpf_cfg);
  double sum = 0.0;
  for (std::size_t k = 0; k < divisor; ++k)
    sum += std::norm(filter.frequencyResponse(static_cast<double>(k) * rate_hz));
  return std::sqrt(sum);
}

NoiseSimulator::AxisState::AxisState(SplitMix64& seeder)
    : arw_noise(seeder), rrw_noise(seeder), flicker_noise(seeder), q_noise(seeder), ar_noise(seeder) {}

NoiseSimulator::NoiseSimulator(const SimulationModel& model, double duration_s, std::uint64_t seed,
                               MotionProfile motion)
    : NoiseSimulator(model, duration_s, seed) {
  if (!motion.atRest()) motion_ = std::move(motion);
}

NoiseSimulator::NoiseSimulator(const SimulationModel& model, double duration_s, std::uint64_t seed)
    : model_(model), seeder_(seed), temperature_noise_(seeder_) {
  validateSimulationModel(model_);
  requirePositive(duration_s, "duration_s");
  const double samples = std::floor(duration_s * model_.rate_hz + 1e-9);
  if (samples < 1.0)
    throw std::invalid_argument("duration_s " + formatNumber(duration_s) + " at rate_hz " +
                                formatNumber(model_.rate_hz) + " gives no sample");
  // 2^53: every count up to it is exact in the double it came from. The count is 64-bit on every
  // ABI: on 32-bit ARM a std::size_t would wrap long simulations (8e10 samples is 1e7 s at 8 kHz).
  constexpr double kMaxExactCount = 9007199254740992.0;
  if (samples > kMaxExactCount)
    throw std::invalid_argument("duration_s " + formatNumber(duration_s) + " at rate_hz " +
                                formatNumber(model_.rate_hz) + " gives more than 2^53 samples");
  sample_count_ = static_cast<std::uint64_t>(samples);

  if (model_.dlpf_cfg) {
    decimation_ = sampleRateDivisor(*model_.dlpf_cfg, model_.rate_hz);
    internal_rate_hz_ = dlpfSetting(*model_.dlpf_cfg).internal_rate_hz;
    dlpf_.assign(kSimulatedAxes, DigitalLowPassFilter(*model_.dlpf_cfg));
  } else {
    // Without the DLPF nothing band-limits the noise, so it is generated at the output
    // rate itself (decimating unfiltered white noise would fold all of it into the band).
    decimation_ = 1;
    internal_rate_hz_ = model_.rate_hz;
  }
  if (model_.fs_sel) lsb_per_dps_ = gyroSensitivityLsbPerDps(*model_.fs_sel);

  const double tau0 = 1.0 / internal_rate_hz_;
  axes_.reserve(kSimulatedAxes);
  for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
    axes_.emplace_back(seeder_);
    AxisState& axis = axes_.back();
    const AxisNoiseModel& m = model_.axes[a];
    // The sign of the rate ramp: one more word of the seed sequence per axis.
    const double ramp_sign = (seeder_.next() >> 63) ? -1.0 : 1.0;
    axis.bias_dps = m.bias_dps;
    // Each term from its Allan coefficient c (σ² = c·τ^p, noise_terms.hpp):
    //  ARW  σ² = c/τ: white rate of two-sided density √c → per-sample std √(c·fs).
    axis.arw_std =
        std::sqrt(allanVarianceCoefficient(NoiseTerm::AngleRandomWalk, m.terms.arw_deg_per_sqrt_h) * internal_rate_hz_);
    //  RRW  σ² = c·τ = K²τ/3: rate random walk with steps of std K·√τ0 = √(3c·τ0).
    axis.rrw_step_std =
        std::sqrt(3.0 * allanVarianceCoefficient(NoiseTerm::RateRandomWalk, m.terms.rrw_deg_per_h_sqrt_h) * tau0);
    //  R    σ² = c·τ² = R²τ²/2: the deterministic ramp R·t, R = √(2c), sign from the seed.
    axis.ramp_dps_per_s =
        ramp_sign * std::sqrt(2.0 * allanVarianceCoefficient(NoiseTerm::RateRamp, m.terms.rate_ramp_deg_per_h2));
    //  B    σ² = c flat: the Gauss–Markov bank at the internal rate.
    axis.flicker_bank = flickerGaussMarkovBank(
        allanVarianceCoefficient(NoiseTerm::BiasInstability, m.terms.bias_instability_deg_per_h), tau0, duration_s);
    axis.flicker.resize(axis.flicker_bank.size());
    for (std::size_t i = 0; i < axis.flicker_bank.size(); ++i) {
      const GaussMarkovComponent& c = axis.flicker_bank[i];
      const double h = tau0 / c.correlation_time_s;
      GaussMarkovState& s = axis.flicker[i];
      s.decay = portable::exp(-h);
      s.innovation_std = std::sqrt(c.variance * -portable::expm1(-2.0 * h));
      s.value = std::sqrt(c.variance) * axis.flicker_noise.next();  // stationary start
    }
    //  Q    σ² = c/τ² = 3Q²/τ²: white angle noise of std Q = √(c/3), differenced at the
    //       output rate (white PM); its Allan variance is exactly 3Q²/τ² at every τ = m/rate.
    axis.q_angle_std_deg =
        std::sqrt(allanVarianceCoefficient(NoiseTerm::Quantization, m.terms.quantization_urad) / 3.0);
    axis.q_previous_angle_deg = axis.q_angle_std_deg * axis.q_noise.next();
    initAr(axis, m.ar);
  }
  initExtras(seed, duration_s);
  initAccel(seed, duration_s);
}

NoiseSimulator::AccelAxisState::AccelAxisState(SplitMix64& seeder)
    : white_noise(seeder), walk_noise(seeder), flicker_noise(seeder) {}

void NoiseSimulator::initAccel(std::uint64_t seed, double duration_s) {
  if (!model_.accel) return;  // nothing drawn: the gyro stream is the one without accel
  // A generator of its own (another constant than the extras'), so the gyro's numbers never
  // depend on the accel.
  SplitMix64 accel_seeder(seed ^ 0xACCE1E20AE5EED5FULL);
  const double tau0 = 1.0 / model_.rate_hz;
  // (2·ln2/π): the flat Allan variance of bias instability per B² (IEEE 952).
  constexpr double kFlickerFloor = 2.0 * std::numbers::ln2 / std::numbers::pi;
  accel_axes_.reserve(kSimulatedAxes);
  for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
    accel_axes_.emplace_back(accel_seeder);
    AccelAxisState& axis = accel_axes_.back();
    const AccelAxisNoise& n = model_.accel->axes[a];
    axis.white_std = n.velocity_random_walk_g_per_sqrt_hz * std::sqrt(model_.rate_hz);  // σ² = N²/τ0 at τ0
    axis.walk_step_std = n.acceleration_random_walk_g_per_sqrt_s * std::sqrt(tau0);     // σ² = K²τ/3
    const std::vector<GaussMarkovComponent> bank =
        flickerGaussMarkovBank(kFlickerFloor * n.bias_instability_g * n.bias_instability_g, tau0, duration_s);
    for (const GaussMarkovComponent& c : bank) {
      const double h = tau0 / c.correlation_time_s;
      GaussMarkovState st;
      st.decay = portable::exp(-h);
      st.innovation_std = std::sqrt(c.variance * -portable::expm1(-2.0 * h));
      st.value = std::sqrt(c.variance) * axis.flicker_noise.next();  // stationary start
      axis.flicker.push_back(st);
    }
  }
}

std::array<double, kSimulatedAxes> NoiseSimulator::accelAt(const std::array<double, kSimulatedAxes>& gravity_g) {
  std::array<double, kSimulatedAxes> out{};
  const AccelModel& model = *model_.accel;
  for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
    AccelAxisState& axis = accel_axes_[a];
    double v = gravity_g[a] + model.axes[a].bias_g + axis.walk_value;
    if (axis.white_std > 0.0) v += axis.white_std * axis.white_noise.next();
    if (axis.walk_step_std > 0.0) axis.walk_value += axis.walk_step_std * axis.walk_noise.next();
    for (GaussMarkovState& st : axis.flicker) {
      v += st.value;
      st.value = st.decay * st.value + st.innovation_std * axis.flicker_noise.next();
    }
    if (lsb_per_dps_) {
      const double lsb_per_g = accelLsbPerG(model.afs_sel);
      v = quantizeToInt16(v, lsb_per_g) / lsb_per_g;  // saturates at ±range like the chip
    }
    out[a] = v;
  }
  return out;
}

void NoiseSimulator::initExtras(std::uint64_t seed, double duration_s) {
  bool any = false;
  for (const AxisNoiseModel& m : model_.axes) any = any || !m.extra.empty();
  if (!any) return;  // nothing drawn, nothing stored: the stream is the one without extras
  // A generator of their own: the golden-ratio constant keeps it apart from `seeder_`'s
  // sequence, so adding an effect never changes the realisation of the five terms.
  SplitMix64 extra_seeder(seed ^ 0x9E3779B97F4A7C15ULL);
  extra_noise_.emplace(extra_seeder);
  Xoshiro256StarStar positions(extra_seeder);
  extras_.resize(kSimulatedAxes);
  for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
    const AxisExtraEffects& e = model_.axes[a].extra;
    ExtraState& s = extras_[a];
    if (e.gauss_markov_sigma_dps > 0.0) {
      const double h = 1.0 / (model_.rate_hz * e.gauss_markov_tau_s);
      s.gm_decay = portable::exp(-h);
      s.gm_innovation_std = e.gauss_markov_sigma_dps * std::sqrt(-portable::expm1(-2.0 * h));
      s.gm_value = e.gauss_markov_sigma_dps * extra_noise_->next();  // stationary start
    }
    // Each line its own AR(2), started in its stationary distribution: (x_{−2}, x_{−1}) jointly
    // Gaussian with variance v and lag-1 covariance v·a1/(1 − a2), so the first samples are as
    // wide as the rest.
    for (std::size_t i = 0; i < e.narrowband_lines.size(); ++i) {
      const NarrowbandLineRecursion r =
          narrowbandLineRecursionOf(e.narrowband_lines[i], model_.rate_hz, narrowbandLineName(a, i));
      const double variance = r.drive_var * ar2StationaryVariancePerDrive(r.a1, r.a2);
      const double lag1_correlation = r.a1 / (1.0 - r.a2);
      NarrowbandLineState line;
      line.a1 = r.a1;
      line.a2 = r.a2;
      line.drive_std = std::sqrt(r.drive_var);
      line.before_previous = std::sqrt(variance) * extra_noise_->next();
      line.previous = lag1_correlation * line.before_previous +
                      std::sqrt(variance * (1.0 - lag1_correlation * lag1_correlation)) * extra_noise_->next();
      s.lines.push_back(line);
    }
    if (e.outlier_count > sample_count_)
      throw std::invalid_argument(axisPrefix(a) + "extra.outlier_count " + std::to_string(e.outlier_count) +
                                  " is more than the " + std::to_string(sample_count_) + " samples of " +
                                  formatNumber(duration_s) + " s");
    // Distinct positions: draw, and draw again on a repeat (count ≪ samples in practice).
    while (s.outlier_positions.size() < e.outlier_count) {
      const auto pos = static_cast<std::uint64_t>(positions.uniform() * static_cast<double>(sample_count_));
      if (std::find(s.outlier_positions.begin(), s.outlier_positions.end(), pos) == s.outlier_positions.end())
        s.outlier_positions.push_back(pos);
    }
    std::sort(s.outlier_positions.begin(), s.outlier_positions.end());
    for (std::size_t i = 0; i < s.outlier_positions.size(); ++i)
      s.outlier_values.push_back((positions.next() >> 63) ? -e.outlier_amplitude_dps : e.outlier_amplitude_dps);
  }
}

// The extra effects' sinusoids use portableSinOfCycles (processing/simulation/motion_profile.hpp).

double NoiseSimulator::extraEffectAt(std::size_t a, std::uint64_t index) {
  const AxisExtraEffects& e = model_.axes[a].extra;
  ExtraState& s = extras_[a];
  const double t = static_cast<double>(index) / model_.rate_hz;
  double v = 0.0;
  if (e.temperature_coefficient_dps_per_c != 0.0) v += temperatureCouplingDps(e, model_.temperature, t);
  for (const SinusoidEffect& sin : e.sinusoids)
    v += sin.amp_dps * portableSinOfCycles(sin.freq_hz * t + sin.phase_rad / (2.0 * std::numbers::pi));
  if (e.gauss_markov_sigma_dps > 0.0) {
    v += s.gm_value;
    s.gm_value = s.gm_decay * s.gm_value + s.gm_innovation_std * extra_noise_->next();
  }
  if (!s.lines.empty()) v += nextLinesSum(s);
  for (const BiasStepEffect& step : e.bias_steps)
    if (t >= step.time_s) v += step.size_dps;
  while (s.next_outlier < s.outlier_positions.size() && s.outlier_positions[s.next_outlier] < index) ++s.next_outlier;
  if (s.next_outlier < s.outlier_positions.size() && s.outlier_positions[s.next_outlier] == index)
    v += s.outlier_values[s.next_outlier];
  return v;
}

double NoiseSimulator::nextLinesSum(ExtraState& s) {
  double sum = 0.0;
  for (NarrowbandLineState& line : s.lines) {
    const double x = line.a1 * line.previous + line.a2 * line.before_previous + line.drive_std * extra_noise_->next();
    line.before_previous = line.previous;
    line.previous = x;
    sum += x;
  }
  return sum;
}

std::array<double, kSimulatedAxes> NoiseSimulator::nextNarrowbandLines() {
  std::array<double, kSimulatedAxes> out{};
  if (extras_.empty()) return out;
  for (std::size_t a = 0; a < kSimulatedAxes; ++a)
    if (!extras_[a].lines.empty()) out[a] = nextLinesSum(extras_[a]);
  return out;
}

void NoiseSimulator::initAr(AxisState& axis, const ArComponent& ar) {
  axis.ar_phi = ar.phi;
  axis.ar_innovation_std = std::sqrt(ar.noise_var);
  const std::size_t p = ar.phi.size();
  axis.ar_history.assign(p, 0.0);
  axis.ar_newest = p == 0 ? 0 : p - 1;
  if (p == 0 || ar.noise_var == 0.0) return;
  // Start in the stationary distribution: x_1 ~ N(0, v_0), then each x_j given the
  // previous ones is the order-(j−1) one-step prediction plus an error of variance
  // v_{j−1}, where v_p = σa² and v_{j−1} = v_j/(1 − k_j²) (Levinson–Durbin, run backward).
  const std::vector<std::vector<double>> orders = arStepDown(ar.phi, "");
  std::vector<double> prediction_var(p + 1);
  prediction_var[p] = ar.noise_var;
  for (std::size_t j = p; j >= 1; --j) {
    const double k = orders[j - 1][j - 1];
    prediction_var[j - 1] = prediction_var[j] / (1.0 - k * k);
  }
  for (std::size_t j = 1; j <= p; ++j) {  // ar_history[j−1] = x_j, oldest first
    double x = 0.0;
    if (j >= 2)
      for (std::size_t i = 1; i <= j - 1; ++i) x += orders[j - 2][i - 1] * axis.ar_history[j - 1 - i];
    x += std::sqrt(prediction_var[j - 1]) * axis.ar_noise.next();
    axis.ar_history[j - 1] = x;
  }
}

SimulatedSample NoiseSimulator::nextAnalog() {
  SimulatedSample out;
  const double t = static_cast<double>(analog_index_) / internal_rate_hz_;
  out.t_s = t;
  for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
    AxisState& axis = axes_[a];
    double v = axis.bias_dps + axis.ramp_dps_per_s * t + axis.rrw_value;
    if (axis.arw_std > 0.0) v += axis.arw_std * axis.arw_noise.next();
    if (axis.rrw_step_std > 0.0) axis.rrw_value += axis.rrw_step_std * axis.rrw_noise.next();
    for (GaussMarkovState& s : axis.flicker) {
      v += s.value;
      s.value = s.decay * s.value + s.innovation_std * axis.flicker_noise.next();
    }
    out.rate_dps[a] = v;
  }
  if (motion_) {
    // The true rotation enters with the noise, before the DLPF, as it does on the chip; no
    // motion adds nothing at all (not even + 0.0, which would turn a −0.0 into +0.0).
    out.true_rate_dps = motion_->rateAt(t);
    for (std::size_t a = 0; a < kSimulatedAxes; ++a) out.rate_dps[a] += out.true_rate_dps[a];
  }
  if (model_.accel) {
    // Gravity at this sample's attitude; then the board turns at the true rate until the next.
    out.accel_g = attitude_.gravityInBody();
    if (motion_) attitude_.step(out.true_rate_dps, 1.0 / internal_rate_hz_);
  }
  const TemperatureModel& temp = model_.temperature;
  out.temperature_c = temperatureCurveC(temp, t);
  if (temp.noise_std_c > 0.0) out.temperature_c += temp.noise_std_c * temperature_noise_.next();
  ++analog_index_;
  return out;
}

std::array<double, kSimulatedAxes> NoiseSimulator::nextOutputRateNoise() {
  std::array<double, kSimulatedAxes> out{};
  for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
    AxisState& axis = axes_[a];
    double v = 0.0;
    if (axis.q_angle_std_deg > 0.0) {
      const double angle = axis.q_angle_std_deg * axis.q_noise.next();
      v += (angle - axis.q_previous_angle_deg) * model_.rate_hz;
      axis.q_previous_angle_deg = angle;
    }
    if (axis.ar_innovation_std > 0.0) {
      const std::size_t p = axis.ar_phi.size();
      double x = axis.ar_innovation_std * axis.ar_noise.next();
      if (p > 0) {
        // ar_history[(newest − (i−1)) mod p] = x_{k−i}
        double prediction = 0.0;
        for (std::size_t i = 1; i <= p; ++i)
          prediction += axis.ar_phi[i - 1] * axis.ar_history[(axis.ar_newest + p - (i - 1)) % p];
        x = prediction + x;
        axis.ar_newest = (axis.ar_newest + 1) % p;
        axis.ar_history[axis.ar_newest] = x;
      }
      v += x;
    }
    if (!extras_.empty()) v += extraEffectAt(a, extra_index_);
    out[a] = v;
  }
  ++extra_index_;
  return out;
}

SimulatedSample NoiseSimulator::next() {
  const std::size_t steps = output_index_ == 0 ? 1 : decimation_;
  SimulatedSample analog;
  std::array<double, kSimulatedAxes> rate{};
  for (std::size_t i = 0; i < steps; ++i) {
    analog = nextAnalog();
    for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
      if (dlpf_.empty()) {
        rate[a] = analog.rate_dps[a];
      } else {
        if (output_index_ == 0) dlpf_[a].reset(analog.rate_dps[a]);
        rate[a] = dlpf_[a].update(analog.rate_dps[a]);
      }
    }
  }
  const std::array<double, kSimulatedAxes> output_noise = nextOutputRateNoise();
  SimulatedSample out;
  out.t_s = static_cast<double>(output_index_) / model_.rate_hz;
  out.temperature_c = analog.temperature_c;
  if (motion_) out.true_rate_dps = motion_->rateAt(out.t_s);
  for (std::size_t a = 0; a < kSimulatedAxes; ++a) out.rate_dps[a] = rate[a] + output_noise[a];
  if (model_.accel) out.accel_g = accelAt(analog.accel_g);
  if (lsb_per_dps_) {
    for (double& r : out.rate_dps) r = quantizeToInt16(r, *lsb_per_dps_) / *lsb_per_dps_;
    out.temperature_c =
        quantizeToInt16(out.temperature_c - kTemperatureOffsetDegC, kTemperatureLsbPerDegC) / kTemperatureLsbPerDegC +
        kTemperatureOffsetDegC;
  }
  ++output_index_;
  return out;
}

const std::vector<GaussMarkovComponent>& NoiseSimulator::flickerBank(std::size_t axis) const {
  if (axis >= kSimulatedAxes)
    throw std::invalid_argument("the simulator's flicker noise exists for axes 0..2 (x, y, z), not for axis " +
                                std::to_string(axis));
  return axes_[axis].flicker_bank;
}

}  // namespace gyrod::processing
