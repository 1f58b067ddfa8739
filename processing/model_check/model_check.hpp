#pragma once
// The model check: where the paper's model (five IEEE 952 Allan terms, AR(p) for the
// Kalman filter) fails to reproduce a measured static recording, why, and by how much a
// model extended with the named cause does better. Method and measured figures:
// docs/model-check.md.
//
// For one axis: fit the base model (noise_fit), simulate replicas of the same length from
// it (noise_simulator), and compare the measured series with the replicas on statistics
// that expose a wrong model. Every decision threshold comes from the replicas (the null
// distribution of the statistic under the fitted base model); the measured temperature
// channel drives the temperature statistic of every replica. A cause is named only from
// the catalogue below, with fitted parameters; a mismatch that none of them explains is
// reported as `unexplained` with where it shows. Nothing here knows how test data are made.
//
// Pure: no I/O. Replicas may run on several threads (std::thread); replica i is seeded
// from (seed, i) alone and results are combined in index order, so the result does not
// depend on the number of threads.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/allan/noise_fit.hpp"
#include "processing/simulation/noise_simulator.hpp"

namespace gyrod::processing {

// The catalogue. Names (modelEffectName) and parameter names are fixed: they are the JSON
// of `gyroctl model-check`.
enum class ModelEffect {
  TemperatureBias,  // temperature_bias {k_dps_per_c}
  Sinusoid,         // sinusoid {freq_hz, amp_dps}
  GaussMarkov,      // gauss_markov {tau_s, sigma_dps}
  BiasSteps,        // bias_steps {count, times_s}
  Outliers,         // outliers {count}
  SampleGaps,       // sample_gaps {count, lost}
  NarrowbandLine,   // narrowband_line {centre_hz, width_hz, rms_dps}: a line whose frequency wanders
  Unexplained,      // unexplained {where: tau range or frequency}
};
std::string_view modelEffectName(ModelEffect e);

// How a slow change of the bias was told apart as a temperature response or as steps (both
// fire on the low-passed residual when either is there).
enum class LowFrequencyDecision {
  None,
  TemperatureOnly,       // follows temperature; no step once it is removed
  TemperatureThenSteps,  // follows temperature, and steps remain once it is removed
  StepsThenTemperature,  // steps, and a temperature response remains once they are removed
  StepsOnly,             // steps; no temperature response
  EachRemains,           // each remains when the other is removed
  TemperatureVanishes,   // the temperature correlation vanishes once the steps are removed
  StepsVanish,           // the steps vanish once the temperature response is removed
  ByBic,                 // each explains the other away: BIC of the low-passed residual decides
};

// A further component of a line already named: a fixed sinusoid did not take the line out.
struct LineComponent {
  double freq_hz = 0.0, amp_dps = 0.0;
  double peak_ratio = 0.0;  // its spectral peak over the local background
  bool operator==(const LineComponent&) const = default;
};

// What a named effect rests on, as numbers; the tool that prints them words them. Only the
// fields of the effect are meaningful.
struct EffectEvidence {
  double statistic = 0.0;                         // the statistic's value (unexplained: largest |z| of the Allan band)
  double threshold = 0.0;                         // its threshold (two-sided statistics: on |value − null median|)
  double null_median = 0.0;                       // median of its null
  std::size_t replicas = 0;                       // replicas per round the null comes from
  double peak_ratio = 0.0;                        // sinusoid: peak over the local background
  double freq_hz = 0.0;                           // sinusoid: frequency of the first component
  std::vector<LineComponent> further_components;  // sinusoid: the line's amplitude or phase wanders
  double chi2_gain = 0.0, chi2_base = 0.0;        // gauss_markov: weighted residual gain, and before
  LowFrequencyDecision decision = LowFrequencyDecision::None;  // temperature_bias, bias_steps
  double bic_temperature = 0.0, bic_steps = 0.0;               // when decision is ByBic
  double median_spacing_s = 0.0, jitter = 0.0;                 // sample_gaps
  bool against_extended = false;  // unexplained: against the extended model (else the base)
  bool operator==(const EffectEvidence&) const = default;
};

// A stated 95 % interval of a parameter (docs/model-check.md, "Intervals"): from the
// extended model's replicas (a parametric bootstrap under the fitted coloured noise), or
// exact for a count. `stated` false: none (the effect has no such parameter, or too few
// replicas had it).
struct ParameterInterval {
  bool stated = false;
  double lo = 0.0, hi = 0.0;
  bool contains(double v) const { return stated && v >= lo && v <= hi; }
  bool operator==(const ParameterInterval&) const = default;
};

struct DetectedEffect {
  ModelEffect effect = ModelEffect::Unexplained;
  // Parameters; only those of `effect` are meaningful.
  double k_dps_per_c = 0.0;                   // temperature_bias
  double freq_hz = 0.0, amp_dps = 0.0;        // sinusoid
  double phase_rad = 0.0;                     // sinusoid (amp·sin(2πf·t + phase), t from 0)
  double tau_s = 0.0, sigma_dps = 0.0;        // gauss_markov
  std::size_t count = 0;                      // bias_steps, outliers, sample_gaps
  std::vector<double> times_s;                // bias_steps (time of each step)
  std::vector<double> sizes_dps;              // bias_steps (size of each step)
  std::size_t lost = 0;                       // sample_gaps: samples missing in the gaps
  double outlier_median_amplitude_dps = 0.0;  // outliers: median |excursion|
  double where_lo = 0.0, where_hi = 0.0;      // unexplained: τ range [s] (Allan)
  double centre_hz = 0.0, width_hz = 0.0;     // narrowband_line (simulation/narrowband_line.hpp)
  double rms_dps = 0.0;                       // narrowband_line: its standard deviation
  EffectEvidence evidence;                    // statistic, value, threshold
  // 95 % intervals of the parameters above (only those of `effect` are stated).
  ParameterInterval k_interval;                                     // temperature_bias
  ParameterInterval amp_interval;                                   // sinusoid
  ParameterInterval tau_interval, sigma_interval;                   // gauss_markov
  std::vector<ParameterInterval> size_intervals;                    // bias_steps, one per step
  ParameterInterval count_interval;                                 // outliers
  ParameterInterval outlier_amplitude_interval;                     // outliers (of the median excursion)
  ParameterInterval centre_interval, width_interval, rms_interval;  // narrowband_line
  // false: seen (its statistic fired) but not explained: the extended model with it did not
  // gain out of sample (AxisModelCheck::verdict says which measures).
  bool explained = true;
};

// One statistic of the check: its value on the measured series, the replicas' null
// distribution summarised by its threshold, and whether it fired.
struct CheckStatistic {
  std::string name;
  double value = 0.0;
  double null_median = 0.0;
  double threshold = 0.0;
  bool fired = false;
};

// Allan deviation of the measured series against the replicas of a model, per τ.
struct AllanBand {
  std::vector<double> tau_s;
  std::vector<double> measured;  // oadev of the measured (detrended) series
  std::vector<double> median;    // median over replicas
  std::vector<double> lo, hi;    // 5 % and 95 % over replicas (the 90 % band)
  // The in-band share of each replica against the band of the other replicas (leave one
  // out), τ by τ.
  std::vector<double> replica_in_band;
  // The simultaneous 90 % band, the one a whole curve is judged by: median ± c one-sided
  // spreads in log ADEV (the 15.87–84.13 % half-widths below and above the median), c the 90 %
  // quantile of the replicas' largest |z| over τ, each replica against the others (the sup-t
  // band: Montiel Olea & Plagborg-Møller 2019). 90 % of a right model's curves lie inside it
  // at every τ; the per-τ band above leaves a right model's curve in band at only ~87 % of τ
  // on average. `replica_in_joint_band`: each replica's share against the others' band, the
  // null distribution of the measured curve's share (the misfit's band test).
  double joint_z = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> joint_lo, joint_hi;
  std::vector<double> replica_in_joint_band;
  double measured_in_joint_band = 0.0;
};

struct ModelCheckGain {
  double adev_log_error_base = 0.0, adev_log_error_extended = 0.0;
  double innovation_var_base = 0.0, innovation_var_extended = 0.0;
  double ljung_box_p_base = 0.0, ljung_box_p_extended = 0.0;
  double in_band_base = 0.0, in_band_extended = 0.0;
  // Out of sample: each Kalman model (its AR part, and the Gauss–Markov state) fitted on the
  // first half of the record, its innovations scored on the second half.
  double innovation_var_base_held_out = 0.0, innovation_var_extended_held_out = 0.0;
  double ljung_box_p_base_held_out = 0.0, ljung_box_p_extended_held_out = 0.0;
  // When outliers are named (tail_judged): the held-back half's samples beyond 5√S of the
  // extended model's Gaussian predictor, the count each model expects there (the Gaussian tail;
  // plus the first half's rate of named outliers for the extended model) and the Poisson log
  // likelihood of the count under each (docs/model-check.md, "Outliers: the held-out tail").
  bool tail_judged = false;
  std::size_t tail_count_held_out = 0;
  double tail_expected_base_held_out = 0.0, tail_expected_extended_held_out = 0.0;
  double tail_log_likelihood_base_held_out = 0.0, tail_log_likelihood_extended_held_out = 0.0;
};

// The acceptance rule (docs/model-check.md): an extension is accepted only if it gains out of
// sample: against fresh replicas of each model (ADEV log error, in-band fraction) and on the
// held-back half (innovation variance, Ljung–Box), more measures better beyond their noise
// than worse. Otherwise its effects are "seen, not explained".
struct ExtensionVerdict {
  bool judged = false;  // a model effect was named (else there is no extension to judge)
  bool accepted = true;
  // false when outliers are the only effect named: the Allan measures cannot see them (the
  // extended model's curve is the base model's), so adev_log_error and in_band do not count.
  bool allan_judged = true;
  bool adev_worse = false, band_worse = false, innovation_worse = false, ljung_box_worse = false;
  bool adev_better = false, band_better = false, innovation_better = false, ljung_box_better = false;
  bool tail_worse = false, tail_better = false;  // the held-out tail (ModelCheckGain::tail_judged)
  bool operator==(const ExtensionVerdict&) const = default;
};

// Whether the model the check ends with (the extended model when its extension is accepted,
// else the base model) passes two tests calibrated on clean records, and where it misses
// (docs/model-check.md, "Misfit"). Whiteness: the held-out prediction errors of an AR model
// (heldOutWhiteness: AIC up to kWhitenessMaxArOrder, fitted on the first half of the series
// the model leaves, scored on the second) have a Ljung–Box p ≥ kMisfitWhitenessP. Band: the
// measured Allan curve lies outside the simultaneous 90 % band of the model's replicas at no
// more τ than the replicas themselves do (each against the band of the others:
// AllanBand::replica_in_joint_band);
// it fails when it misses at more τ than every replica and a beta-binomial fitted to the
// replicas' misses puts that many or more below kMisfitBandAlpha. A named effect does not make
// a model fit; an empty `effects` does not either, unless both tests pass.
inline constexpr double kMisfitWhitenessP = 1e-3;
inline constexpr double kMisfitBandAlpha = 0.01;
// A model that passes both tests but with a held-out whiteness p below kMarginalWhitenessP or
// less than kMarginalInBand of its Allan curve in the simultaneous band is marginal: it fits,
// and the misfit still says where it is weakest (docs/model-check.md, "Misfit").
inline constexpr double kMarginalWhitenessP = 0.01;
inline constexpr double kMarginalInBand = 0.9;
struct ModelMisfit {
  bool whiteness_fails = false;       // held-out Ljung–Box p < kMisfitWhitenessP
  bool band_fails = false;            // in-band share below the replicas' (see above)
  double ljung_box_p_held_out = 0.0;  // the whiteness test's p (against the replicas' Q)
  double whiteness_q = 0.0;           // its Ljung–Box Q
  double whiteness_q_replica_median = std::numeric_limits<double>::quiet_NaN();
  std::size_t whiteness_ar_order = 0;  // the AR order the whiteness test used
  double in_band = 0.0;                // share of τ inside the final model's simultaneous band
  bool joint_band = true;              // false: too few replicas, the per-τ band instead
  // The replicas' own in-band shares (leave one out): median and lowest; and the
  // beta-binomial probability of missing the band at as many τ as the measured curve does.
  double in_band_replica_median = std::numeric_limits<double>::quiet_NaN();
  double in_band_replica_lowest = std::numeric_limits<double>::quiet_NaN();
  double band_p = std::numeric_limits<double>::quiet_NaN();
  // Where the Allan curve leaves the final model's band (stated when band_fails, or when the
  // curve is in band less often than every replica): the first
  // and last τ outside it, and measured/median at the τ outside farthest from the median
  // (> 1 above it, < 1 below). NaN when not stated.
  double tau_lo_s = std::numeric_limits<double>::quiet_NaN();
  double tau_hi_s = std::numeric_limits<double>::quiet_NaN();
  double adev_ratio = std::numeric_limits<double>::quiet_NaN();
  // Where the misfit is in frequency (looked for when a test fails): the band where the
  // held-out prediction errors carry excess power (innovationSpectralExcess; power over their
  // white level), else the run of the spectrum's log bands (48 from 2/duration to Nyquist)
  // where the record's power exceeds every base replica's, around the largest such excess
  // (power over the replicas' median). NaN when not stated.
  double freq_lo_hz = std::numeric_limits<double>::quiet_NaN();
  double freq_hi_hz = std::numeric_limits<double>::quiet_NaN();
  double power_ratio = std::numeric_limits<double>::quiet_NaN();
  bool power_against_replicas = false;  // the ratio is over the replicas' median, not white
  // Set by the caller that estimated the acquisition chain when no DLPF setting (nor none)
  // fits the short-τ Allan curve: the base model's chain is then itself a misfit.
  bool chain_fails = false;
  double chain_reduced_chi2 = std::numeric_limits<double>::quiet_NaN();  // best, per axis
  bool marginal = false;  // fits, but below kMarginalWhitenessP or kMarginalInBand (placed as a misfit is)
  // Whether the record itself changes between its halves (looked at when a misfit or a
  // marginal fit is stated; halvesChange): its colour (the halves' autocorrelation at lags
  // 1–kHalvesLags) and its spectrum bin by bin (a line that moves, grows or fades), each
  // against the same statistic of the base model's replicas, which are stationary by
  // construction. A stationary model fitted to one half cannot whiten the other half of a
  // record that changed, whatever effects it holds. NaN when not looked at.
  double halves_colour_p = std::numeric_limits<double>::quiet_NaN();
  double halves_lag1_first = std::numeric_limits<double>::quiet_NaN();
  double halves_lag1_second = std::numeric_limits<double>::quiet_NaN();
  double halves_spectrum_p = std::numeric_limits<double>::quiet_NaN();
  double halves_spectrum_hz = std::numeric_limits<double>::quiet_NaN();     // the bin that changed most
  double halves_spectrum_ratio = std::numeric_limits<double>::quiet_NaN();  // its power, second half / first
  bool halves_differ = false;  // the smaller p below kHalvesAlpha / 2 (two tests)
  bool fails() const { return whiteness_fails || band_fails || chain_fails; }
};

struct ModelCheckOptions {
  std::size_t replicas = 40;  // per round; the thresholds use robust spread, not ranks
  std::uint64_t seed = 1;
  std::size_t threads = 0;  // 0: std::thread::hardware_concurrency()
  // Nominal false-alarm probability of each statistic on one axis: a statistic fires when it
  // exceeds both the largest replica value and the (1 − α) quantile of a Gumbel (maxima) or
  // normal (signed linear statistics) fitted to the replicas' quantiles. About six statistics
  // per axis are tested, so the nominal rate per axis is ~6α; the estimated spread from a few
  // dozen replicas adds to it (measured rates: docs/model-check.md).
  double false_alarm = 1e-4;
  std::size_t ljung_box_lags = 30;
  std::size_t max_ar_order = 8;
};

// How the recording was acquired: the chip's DLPF (DLPF_CFG 0..6, at its internal rate of
// 8 kHz for cfg 0 and 1 kHz otherwise, decimated to rate_hz by 1 + SMPLRT_DIV) and the
// quantisation (FS_SEL 0..3: 1/131 … 1/16.4 °/s). The base model includes it: the white rate
// noise of the replicas has the chain's short-τ shape, and they are rounded to the LSB.
// None: no DLPF (or one whose effect is not to be modelled), no quantisation.
struct AcquisitionChain {
  std::optional<int> dlpf_cfg;
  std::optional<int> fs_sel;
  bool operator==(const AcquisitionChain&) const = default;
};

struct AxisModelCheckInput {
  std::span<const double> rate_dps;
  double rate_hz = 0.0;
  std::span<const double> temperature_c;  // empty: no temperature channel
  std::span<const double> time_s;         // empty: no t column
  AcquisitionChain chain;                 // the rate must be reachable with its DLPF
};

struct AxisModelCheck {
  std::size_t samples = 0;
  NoiseTermFit base_fit;
  NoiseTermFit extended_fit;            // five terms of the data with the named effects removed
  std::vector<DetectedEffect> effects;  // empty when the base model holds
  std::vector<CheckStatistic> statistics;
  ModelCheckGain gain;
  AllanBand allan_base, allan_extended;
  // For plots: log-binned power spectral density [(°/s)²/Hz] of the measured series and the
  // median of the base replicas, and the low-passed residual against temperature.
  std::vector<double> spectrum_freq_hz, spectrum_measured, spectrum_base_median;
  std::vector<double> spectrum_base_max;       // the largest replica's per band (the misfit's placement)
  std::vector<double> spectrum_measured_peak;  // largest single-bin PSD in each band (lines)
  std::vector<double> block_temperature_c, block_residual_dps;
  std::size_t ar_order = 0;  // AR order (AIC) of the base Kalman model
  std::size_t replicas_simulated = 0;
  AcquisitionChain chain;  // the acquisition chain in the base model
  ExtensionVerdict verdict;
  ModelMisfit misfit;  // of the model the check ends with
};

// Throws std::invalid_argument for a rate that is not finite and > 0, fewer than
// kModelCheckMinSamples samples, a non-finite sample, a temperature or time channel of
// another length, non-increasing times, or options with replicas < 8.
inline constexpr std::size_t kModelCheckMinSamples = 2000;
AxisModelCheck checkAxisModel(const AxisModelCheckInput& input, const ModelCheckOptions& options = {});

// ---- the acquisition chain -------------------------------------------------------------

// The shape s(m) of white rate noise through the chain at cluster sizes ms (τ = m/rate):
// its Allan variance is c·s(m)/τ, s → 1 at long τ (c the white coefficient the output shows
// there). All ones without a DLPF. Exact, from the DLPF's impulse response.
std::vector<double> chainWhiteNoiseShape(const AcquisitionChain& chain, double rate_hz,
                                         std::span<const std::size_t> ms);

// Estimating the DLPF of a recording that does not say: a DLPF shows as a known roll-off of
// the Allan curve at short τ. Each candidate (none, and every DLPF_CFG that can give this
// rate) is scored by the reduced χ² of the base fit with its shape; scores add over axes.
struct DlpfCandidate {
  std::optional<int> dlpf_cfg;
  double chi2 = 0.0;
  // Axes on which this DLPF fits clearly better than none on its own (χ² at most 0.8 of
  // none's): a line or a bump on one axis can lower the summed χ² of a roll-off it does not
  // have (seen: a 1.7 Hz sinusoid on one of three white-noise axes chose DLPF_CFG 5).
  std::size_t axes_preferring = 0;
};
std::vector<DlpfCandidate> dlpfCandidates(double rate_hz);
void scoreDlpfCandidates(std::span<const double> rate_dps, double rate_hz, std::vector<DlpfCandidate>& candidates);
// The estimate from candidates scored on `axes_scored` axes: the best DLPF when it fits
// clearly better than none (χ² at most 0.8 of none's, and lower by more than 3 per axis) and
// is preferred on at least half the axes, else none.
std::optional<int> chooseDlpf(const std::vector<DlpfCandidate>& scored, std::size_t axes_scored);

// ---- parts, public for the tests and the report ---------------------------------------

// Sample timing from t: gaps are intervals > 1.5 × the median spacing τ0, lost =
// Σ (round(dt/τ0) − 1) over the gaps; jitter = robust sd of the other intervals / τ0.
struct SampleTiming {
  double median_spacing_s = 0.0;
  std::size_t gaps = 0;
  std::size_t lost = 0;
  std::vector<double> gap_times_s;  // t before each gap
  double jitter = 0.0;
};
SampleTiming analyzeSampleTiming(std::span<const double> time_s);

// Allan variance of a first-order Gauss–Markov rate process of correlation time T and
// stationary std σ (continuous time): q_c·T²/τ·[1 − T/(2τ)·(3 − 4e^{−τ/T} + e^{−2τ/T})],
// q_c = 2σ²/T.
double gaussMarkovAllanVariance(double tau_s, double correlation_time_s, double sigma_dps);

// Ljung–Box Q = n(n+2)·Σ_{k=1}^{h} ρ̂_k²/(n−k) of a series (mean removed) and its p-value
// against χ²(h − fitted_parameters) (at least 1 dof).
struct LjungBox {
  double q = 0.0;
  std::size_t dof = 0;
  double p_value = 0.0;
};
LjungBox ljungBoxTest(std::span<const double> x, std::size_t lags, std::size_t fitted_parameters);

// Least-squares sinusoid a·sin(2πf·t) + b·cos(2πf·t) (t = i/rate) at a given frequency,
// as amplitude √(a² + b²) and phase atan2(b, a).
struct SinusoidFit {
  double freq_hz = 0.0, amp_dps = 0.0, phase_rad = 0.0;
};
SinusoidFit fitSinusoidAt(std::span<const double> x, double rate_hz, double freq_hz);

// Excess power in a series that should be white (the misfit's innovations): Welch's
// average of Hann-windowed periodograms (segments of L samples, the largest power of two
// ≤ n/16 within 64..1024, overlapping by half), each bin 1..L/2−1 divided by the white level
// (the bins' median over the median of χ²(ν)/ν, ν the segments' equivalent degrees of
// freedom). A bin stands out when it exceeds the (1 − family_alpha/(L/2−1)) quantile of
// χ²(ν)/ν: Bonferroni over the bins, so white noise shows a band in about
// `family_alpha` of series. The band stated is the run of adjacent bins standing out that
// holds the largest ratio: its edges (bin centres ± half a bin) and its mean ratio.
struct SpectralExcess {
  bool found = false;
  double freq_lo_hz = 0.0, freq_hi_hz = 0.0;
  double power_ratio = 0.0;  // mean power of the band over the white level
  double peak_ratio = 0.0;   // largest single bin's, anywhere
  double threshold = 0.0;    // on a bin's ratio
  std::size_t segment = 0;   // L
};
SpectralExcess innovationSpectralExcess(std::span<const double> x, double rate_hz, double family_alpha = 1e-3);

// The misfit's whiteness test (docs/model-check.md, "Misfit"): each half detrended on its own
// (constant and line), an AR(p) chosen by AIC up to `max_order` fitted on `fit` (Yule–Walker),
// its one-step prediction errors on `score` (after 100 samples), and Ljung–Box over `lags`
// lags against χ²(lags): nothing was fitted to the held-out errors, so no degree of freedom is
// taken off. Also returns the AR order used.
struct HeldOutWhiteness {
  LjungBox test;  // p against χ²(lags); the misfit's p is against the replicas' Q (whiteNullP)
  std::size_t ar_order = 0;
  std::vector<double> errors;  // the held-out prediction errors (the misfit's spectrum)
};
inline constexpr std::size_t kWhitenessMaxArOrder = 32;
inline constexpr std::size_t kWhitenessBlock = 512;
// Ljung–Box over `lags` of e with each block of `block` samples' mean removed and only lags
// within a block counted (the slow noise an AR model cannot carry from one half to the
// other is left to the Allan band test), the bias the block means give white noise
// (−(B − k)/(B(B − 1)) at lag k) taken off; against χ²(lags). Plain Ljung–Box below 2 blocks.
LjungBox blockLjungBox(std::span<const double> e, std::size_t lags, std::size_t block);
HeldOutWhiteness heldOutWhiteness(std::span<const double> fit, std::span<const double> score,
                                  std::size_t max_order = kWhitenessMaxArOrder, std::size_t lags = 30);
// The upper tail of a Ljung–Box Q under the null of `null_q` (the same test on the replicas):
// a Gumbel through the replicas' median and 90 % point, as the check's other one-sided
// statistics. Noise the AR model fitted on one half cannot carry to the other (flicker, random
// walk) inflates and widens Q alike in the record and its replicas; on white noise the Gumbel
// is a little conservative against χ²(lags) in the tail (its 1e-3 point ≈ 67 against 60 at 30
// lags). Without at least 8 replicas: χ²(lags).
double whiteNullP(double q, const std::vector<double>& null_q, std::size_t lags = 30);

// How a series changes between its halves (each half with its own line removed): the colour
// statistic (h/2)·Σ_k (r₁(k) − r₂(k))² over lags 1..kHalvesLags, h the half's length and r the
// halves' sample autocorrelations (χ²(kHalvesLags) for white noise: each difference has
// variance 2/h), and the spectrum statistic max_j |ln(P₁(j)/P₂(j))| over the Welch bins
// (Hann, 50 % overlap, the largest power of two segment up to h/16 in [64, 1024]) with the
// bin's frequency and P₂/P₁ there. The misfit reads both against the base replicas'.
inline constexpr std::size_t kHalvesLags = 10;
inline constexpr double kHalvesAlpha = 0.01;
struct HalvesChange {
  double colour_q = std::numeric_limits<double>::quiet_NaN();
  double lag1_first = std::numeric_limits<double>::quiet_NaN(), lag1_second = std::numeric_limits<double>::quiet_NaN();
  double spectrum_stat = std::numeric_limits<double>::quiet_NaN();
  double spectrum_hz = std::numeric_limits<double>::quiet_NaN();
  double spectrum_ratio = std::numeric_limits<double>::quiet_NaN();
};
HalvesChange halvesChange(std::span<const double> x, double rate_hz);
// The upper tail of `v` under a Gumbel through the median and 90 % point of `null` (as
// whiteNullP); NaN with fewer than 8 values in `null`.
double gumbelNullP(double v, const std::vector<double>& null);

// Robust z of each sample against its neighbours: (x_i − mean of the h neighbours on each
// side) / (1.4826·MAD of those differences).
std::vector<double> localOutlierScores(std::span<const double> x, std::size_t half_window = 10);

}  // namespace gyrod::processing
