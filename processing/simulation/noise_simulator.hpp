#pragma once
// A streaming simulator of the MPU6050 gyro at rest: three axes of rate (°/s) and the
// die temperature (°C), from a model made of the paper's five Allan terms (IEEE 952, in
// paper units, via processing/base/noise_terms.hpp), a constant bias and an optional AR(p)
// component per axis, a warm-up temperature curve, and the sensor's own behaviour (the
// DLPF at the internal rate, decimation by SMPLRT_DIV, 16-bit quantisation at FS_SEL).
// Method per term and the evidence that each is right: docs/simulator.md.
//
// Streaming: one sample per call, nothing proportional to the recording length is kept;
// no allocation per sample. Reproducible: the same model, duration and seed give the
// same bits on every IEEE-754 machine (own PRNG and elementary functions, compiled
// without FMA contraction; see processing/base/portable_random.hpp).
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "processing/base/noise_terms.hpp"
#include "processing/base/portable_random.hpp"
#include "processing/simulation/motion_profile.hpp"
#include "processing/simulation/narrowband_line.hpp"
#include "processing/simulation/sensor_model.hpp"

namespace gyrod::processing {

inline constexpr std::size_t kSimulatedAxes = 3;  // x, y, z

// x_k = φ1·x_{k−1} + … + φp·x_{k−p} + a_k, a ~ N(0, σa²), at the output rate (paper
// eq. 5), started in its stationary distribution. Empty φ with σa² > 0 is white noise.
struct ArComponent {
  std::vector<double> phi;
  double noise_var = 0.0;  // σa² in (°/s)²
};

// ---- optional effects beyond the paper's model (the model check's catalogue) --------
// All are added at the output rate, after the DLPF and before quantisation, in
// nextOutputRateNoise(); with none set the stream is bit for bit what it was without them
// (their random numbers come from a generator of their own, seeded apart from the rest).
struct SinusoidEffect {
  double freq_hz = 0.0;    // > 0
  double amp_dps = 0.0;    // ≥ 0, amplitude (half the peak-to-peak)
  double phase_rad = 0.0;  // amp·sin(2π·f·t + phase)
};
struct BiasStepEffect {
  double time_s = 0.0;  // the bias changes by size_dps from this time on
  double size_dps = 0.0;
};
struct AxisExtraEffects {
  // rate += k·(T_model(t) − reference), T_model the noise-free temperature curve.
  double temperature_coefficient_dps_per_c = 0.0;
  double temperature_reference_c = 25.0;
  std::vector<SinusoidEffect> sinusoids;
  // One first-order Gauss–Markov process of correlation time tau_s and stationary std
  // sigma_dps, simulated exactly at the output rate (0 = none).
  double gauss_markov_tau_s = 0.0;
  double gauss_markov_sigma_dps = 0.0;
  std::vector<BiasStepEffect> bias_steps;
  // `outlier_count` samples, at distinct positions drawn uniformly over sampleCount(),
  // get ±outlier_amplitude_dps added (sign at random).
  std::size_t outlier_count = 0;
  double outlier_amplitude_dps = 0.0;
  // Lines whose frequency wanders (narrowband_line.hpp), each its own resonance, started in
  // its stationary distribution (centre < rate/2 is checked where the rate is known:
  // validateSimulationModel and the simulator's constructor).
  std::vector<NarrowbandLine> narrowband_lines;
  bool empty() const {
    return temperature_coefficient_dps_per_c == 0.0 && sinusoids.empty() && gauss_markov_sigma_dps == 0.0 &&
           bias_steps.empty() && outlier_count == 0 && narrowband_lines.empty();
  }
};

struct AxisNoiseModel {
  NoiseTerms terms;  // paper units (µrad, °/√h, °/h, °/h^1.5, °/h²), each ≥ 0
  double bias_dps = 0.0;
  ArComponent ar;
  AxisExtraEffects extra;  // none by default
};

// T(t) = final + (start − final)·e^{−(t − delay)/time_constant} + white noise of std noise_std,
// T = start before `delay_s` (a warm-up that begins later: a motor switched on, a cold board
// brought in).
struct TemperatureModel {
  double start_c = 25.0;
  double final_c = 25.0;
  double time_constant_s = 600.0;
  double noise_std_c = 0.0;
  double delay_s = 0.0;
};

// A warm-up (docs/simulator.md "Warm-up"): the die temperature rises by delta_c from the
// model's start_c with time constant time_constant_s; through each axis's temperature coupling
// (AxisExtraEffects::temperature_coefficient_dps_per_c) the bias follows it.
struct WarmUp {
  double delta_c = 0.0;
  double time_constant_s = 0.0;
  double start_s = 0.0;  // when it begins (the temperature steady at start_c before)
};
// `temperature` warming up from its start_c: final_c = start_c + delta_c, the time constant
// and the delay replaced (the noise kept). Throws std::invalid_argument naming the value (delta finite,
// time constant finite and > 0).
TemperatureModel withWarmUp(TemperatureModel temperature, const WarmUp& warm_up);
// The noise-free temperature curve at t.
double temperatureCurveC(const TemperatureModel& temperature, double t_s);
// The temperature coupling k·(T(t) − T_ref) of one axis at t, on the noise-free curve (0 when
// k is 0): what next() adds at the output rate, and what the mock adds to the analog rate.
double temperatureCouplingDps(const AxisExtraEffects& extra, const TemperatureModel& temperature, double t_s);

// ---- the accelerometer (docs/simulator.md "Accelerometer") -------------------------------
// Per axis, in g: the reading is gravity's specific force in the body axes (the attitude
// integrated from the motion's true rates, processing/simulation/motion_profile.hpp AttitudeIntegrator;
// (0, 0, +1) g at rest) + bias + three Allan terms, generated at the output rate:
//   N  velocity random walk, white accel of density N [g/√Hz]:     σ²(τ) = N²/τ
//   B  bias instability [g], a 1/f floor (the gyro's GM bank):      σ²(τ) = (2·ln2/π)·B²
//   K  acceleration random walk [g/√s] (= g/s/√Hz):                 σ²(τ) = K²·τ/3
// (In SI: N·9.80665 m/s²/√Hz is Kalibr's accelerometer_noise_density, K·9.80665 m/s³/√Hz its
// accelerometer_random_walk; N·9.80665·60 is the VRW in m/s/√h.)
struct AccelAxisNoise {
  double bias_g = 0.0;
  double velocity_random_walk_g_per_sqrt_hz = 0.0;     // N
  double bias_instability_g = 0.0;                     // B
  double acceleration_random_walk_g_per_sqrt_s = 0.0;  // K
};
struct AccelModel {
  std::array<AccelAxisNoise, kSimulatedAxes> axes;
  // AFS_SEL 0..3 (±2, ±4, ±8, ±16 g): the accel is quantised and saturated at it whenever the
  // gyro is (SimulationModel::fs_sel set).
  int afs_sel = 0;
};

struct SimulationModel {
  std::array<AxisNoiseModel, kSimulatedAxes> axes;
  TemperatureModel temperature;
  // None: no accelerometer (SimulatedSample::accel_g NaN), and not a single number of the
  // gyro stream depends on whether it is set (its random numbers come from a stream of its own).
  std::optional<AccelModel> accel;
  double rate_hz = 50.0;        // output rate (default: the paper's 50 Hz)
  std::optional<int> dlpf_cfg;  // DLPF_CFG 0..6; none = no DLPF, generated at rate_hz
  std::optional<int> fs_sel;    // FS_SEL 0..3; none = no quantisation or saturation
  // "Pure" mode (both none) shows the Allan terms alone, for testing them.
  bool pure() const { return !dlpf_cfg && !fs_sel; }
};

// Throws std::invalid_argument naming the parameter (and axis) and its value when the
// model cannot be simulated: negative or non-finite terms, a non-stationary AR φ, a rate
// that is not internal/(1+SMPLRT_DIV) for an integer SMPLRT_DIV in 0..255 when the DLPF
// is on, DLPF_CFG/FS_SEL out of range, a bad temperature model.
void validateSimulationModel(const SimulationModel& model);
// The parts of it, for readers that want to point at the offending line: 1 + SMPLRT_DIV
// for an output rate with the DLPF on (throws as above), and the AR component alone
// (finite φ, σa² ≥ 0, stationary; messages start with `what`).
std::size_t sampleRateDivisor(int dlpf_cfg, double rate_hz);
void validateArComponent(const ArComponent& ar, const std::string& what = "");
// The extra effects of one axis: finite values, frequencies and a set Gauss–Markov's
// correlation time > 0, amplitudes ≥ 0, a narrowband line's centre and width > 0 and rms ≥ 0
// (messages start with `what`). The outlier count is checked against the recording length
// when the simulator is built, a line's centre against rate/2 by validateSimulationModel.
void validateExtraEffects(const AxisExtraEffects& extra, const std::string& what = "");

// ---- bias instability (flicker) as a bank of Gauss–Markov processes ----------------
// One first-order Gauss–Markov process x' = −x/T + w, stationary variance `variance`,
// simulated exactly at step τ0: x_k = e^{−τ0/T}·x_{k−1} + √(variance·(1 − e^{−2τ0/T}))·n_k.
struct GaussMarkovComponent {
  double correlation_time_s = 0.0;
  double variance = 0.0;  // (°/s)²
};

// The bank whose summed Allan variance is flat at `flat_allan_variance` (= (0.6643·B)²
// in (°/s)², from allanVarianceCoefficient) for τ from τ0 to duration/2: correlation
// times T_i = 1.2·τ0·10^{i/2} up to the first ≥ 5·duration, equal variances
// flat·ln10/(2·ln2·2) (a 1/f spectrum sampled twice per decade), the two end ones
// raised by √10/(√10 − 1) to stand in for the processes beyond the ends.
// Empty when flat_allan_variance is 0. Throws std::invalid_argument on bad input.
std::vector<GaussMarkovComponent> flickerGaussMarkovBank(double flat_allan_variance, double tau0_s, double duration_s);

// White rate noise of two-sided density N at the internal rate, through the DLPF and
// decimated to rate_hz, is white at low frequency with density N·F where
// F² = Σ_{k=0}^{D−1} |H(k·rate_hz)|², D = internal/rate (the aliases folded onto f = 0).
// So the ARW read from long-τ Allan deviation of the output is F·N. Same validation of
// cfg and rate as the simulator.
double aliasedWhiteNoiseFactor(int dlpf_cfg, double rate_hz);

struct SimulatedSample {
  double t_s = 0.0;                               // from 0
  std::array<double, kSimulatedAxes> rate_dps{};  // °/s
  double temperature_c = 0.0;
  // The true rotation rate at t_s (the motion profile, before the DLPF and everything the
  // sensor adds); zero without motion. For scoring a stream against the truth.
  std::array<double, kSimulatedAxes> true_rate_dps{};
  // Accelerometer x, y, z in g when the model has one, else NaN. From nextAnalog(): gravity
  // alone (the ideal reading at the sample's attitude); from next(): with bias and noise.
  std::array<double, kSimulatedAxes> accel_g{kNoAccel, kNoAccel, kNoAccel};
  static constexpr double kNoAccel = std::numeric_limits<double>::quiet_NaN();
};

class NoiseSimulator {
 public:
  // duration_s fixes the flicker bank's supported τ range (up to duration/2) and
  // sampleCount(); the stream itself may be read further. Throws std::invalid_argument
  // (see validateSimulationModel; duration must be finite and ≥ one sample).
  NoiseSimulator(const SimulationModel& model, double duration_s, std::uint64_t seed);
  // The same sensor turned by `motion`: its true rate is added to the analog rate at the
  // internal rate (nextAnalog()), so the DLPF, the decimation, the saturation at full scale
  // and the quantisation act on it as on the chip; the noise realisation is the one without
  // motion (same seed, same bits before the rotation is added). A motion at rest gives
  // exactly the stream of the constructor above.
  NoiseSimulator(const SimulationModel& model, double duration_s, std::uint64_t seed, MotionProfile motion);

  // The next output sample at rate_hz: analog rate (+ the motion's true rate) at the internal rate → DLPF (if on;
  // started in steady state at the first value) → every D-th sample (t = n/rate_hz,
  // n = 0, 1, …) → + output-rate terms (Q, AR, extra effects) → quantised to 1/sensitivity °/s and
  // saturated (if FS_SEL is set; temperature then also to 1/340 °C).
  SimulatedSample next();

  // For the mock device, which applies the DLPF, decimation and quantisation itself:
  // the analog rate at the internal rate (bias + ARW + bias instability + RRW + ramp, + the
  // motion; the truth in true_rate_dps) and temperature, one internal sample per call
  // (t = i/internal rate), and the terms
  // defined at the output rate (quantisation noise Q, AR, the extra effects), one output
  // sample per call.
  // next() is exactly these two composed as described above; use either next() or
  // these two on one instance, not both.
  SimulatedSample nextAnalog();
  std::array<double, kSimulatedAxes> nextOutputRateNoise();
  // For the mock device, whose simulator runs at the internal rate and which does not take the
  // output-rate terms: the narrowband lines alone (AxisExtraEffects::narrowband_lines, 0 on an
  // axis without), advanced one sample per call at outputRateHz(). A line's centre and width
  // are in Hz, so at the internal rate it is the same line, and the mock's DLPF acts on it as
  // on the chip. Use instead of nextOutputRateNoise(), not with it.
  std::array<double, kSimulatedAxes> nextNarrowbandLines();

  double outputRateHz() const { return model_.rate_hz; }
  double internalRateHz() const { return internal_rate_hz_; }
  std::size_t decimation() const { return decimation_; }       // 1 + SMPLRT_DIV
  std::uint64_t sampleCount() const { return sample_count_; }  // ⌊duration·rate⌋, 64-bit on every ABI
  const SimulationModel& model() const { return model_; }
  // The flicker bank in use (same for all axes up to their level; empty if B = 0).
  const std::vector<GaussMarkovComponent>& flickerBank(std::size_t axis) const;

 private:
  struct GaussMarkovState {
    double decay = 0.0;           // e^{−τ0/T}
    double innovation_std = 0.0;  // √(variance·(1 − decay²))
    double value = 0.0;
  };
  struct AxisState {
    double bias_dps = 0.0;
    double arw_std = 0.0;       // per internal sample
    double rrw_step_std = 0.0;  // per internal sample
    double rrw_value = 0.0;
    double ramp_dps_per_s = 0.0;  // signed
    std::vector<GaussMarkovComponent> flicker_bank;
    std::vector<GaussMarkovState> flicker;
    double q_angle_std_deg = 0.0;  // white angle noise, per output sample
    double q_previous_angle_deg = 0.0;
    std::vector<double> ar_phi;
    double ar_innovation_std = 0.0;
    std::vector<double> ar_history;  // ring buffer of the last p values
    std::size_t ar_newest = 0;
    ZigguratNormalGenerator arw_noise, rrw_noise, flicker_noise, q_noise, ar_noise;
    explicit AxisState(SplitMix64& seeder);
  };

  void initAr(AxisState& axis, const ArComponent& ar);

  // State of the extra effects of one axis (empty when the axis has none).
  struct NarrowbandLineState {
    double a1 = 0.0, a2 = 0.0, drive_std = 0.0;
    double previous = 0.0, before_previous = 0.0;  // x_{k−1}, x_{k−2}
  };
  struct ExtraState {
    double gm_decay = 0.0, gm_innovation_std = 0.0, gm_value = 0.0;
    std::vector<NarrowbandLineState> lines;
    std::vector<std::uint64_t> outlier_positions;  // sorted output-sample indices
    std::vector<double> outlier_values;            // signed, same order
    std::size_t next_outlier = 0;
  };
  void initExtras(std::uint64_t seed, double duration_s);
  double extraEffectAt(std::size_t axis, std::uint64_t index);
  double nextLinesSum(ExtraState& state);  // the axis's lines advanced one sample, summed

  SimulationModel model_;
  SplitMix64 seeder_;  // expands the seed into one xoshiro stream per term and axis
  ZigguratNormalGenerator temperature_noise_;
  double internal_rate_hz_ = 0.0;
  std::size_t decimation_ = 1;
  std::uint64_t sample_count_ = 0;
  std::optional<double> lsb_per_dps_;
  std::vector<AxisState> axes_;
  std::vector<DigitalLowPassFilter> dlpf_;
  std::uint64_t analog_index_ = 0;
  std::uint64_t output_index_ = 0;
  std::vector<ExtraState> extras_;  // empty when no axis has extra effects
  std::optional<ZigguratNormalGenerator> extra_noise_;
  std::uint64_t extra_index_ = 0;        // output samples produced by nextOutputRateNoise()
  std::optional<MotionProfile> motion_;  // none: at rest

  // The accelerometer (only with model_.accel).
  struct AccelAxisState {
    double white_std = 0.0;      // per output sample
    double walk_step_std = 0.0;  // per output sample
    double walk_value = 0.0;
    std::vector<GaussMarkovState> flicker;
    ZigguratNormalGenerator white_noise, walk_noise, flicker_noise;
    explicit AccelAxisState(SplitMix64& seeder);
  };
  void initAccel(std::uint64_t seed, double duration_s);
  std::array<double, kSimulatedAxes> accelAt(const std::array<double, kSimulatedAxes>& gravity_g);
  std::vector<AccelAxisState> accel_axes_;  // empty without model_.accel
  AttitudeIntegrator attitude_;
};

}  // namespace gyrod::processing
