#pragma once
// Internal: the stages of checkAxisModel (processing/model_check/model_check.cpp) and what they share.
// Each detector tests the measured series against the replicas' null of its statistic, names
// its effect in the result and removes it from the working series. Not a stable interface.
//
// Files: series.cpp (what every series is measured by), replicas.cpp
// (replicas, their thread pool, the Allan band), timing.cpp, outliers.cpp,
// sinusoids.cpp, steps.cpp (temperature against steps), gauss_markov.cpp, and
// extension.cpp (the extended model, what it leaves unexplained, the gain).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/allan/noise_fit.hpp"
#include "processing/model_check/detail.hpp"
#include "processing/model_check/model_check.hpp"
#include "processing/simulation/narrowband_line.hpp"
#include "processing/simulation/noise_simulator.hpp"

namespace gyrod::processing::model_check_detail {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr std::size_t kOutlierHalfWindow = 10;

// ---- the acquisition chain (chain.cpp) --------------------------------------

struct ChainModel {
  std::optional<int> dlpf_cfg, fs_sel;
  std::vector<double> white_shape;    // s(m) per Allan point (1 without a DLPF)
  std::vector<double> white_ma;       // MA coefficients of unit long-τ white coefficient (empty: no DLPF)
  std::vector<double> flicker_shape;  // s_B(m): the flicker (bias instability) term's, 1 without a DLPF
  std::vector<double> flicker_ma;     // output-rate filter of the chain's gain for flicker (empty: no DLPF)
  double lsb_dps = 0.0;               // 0: no quantisation
  double quantisation_white = 0.0;    // white coefficient the rounding adds: LSB²·τ0/12
};

// ---- what every replica (and the measured series) is measured by ----------------------

// The narrowband scan's grid over one half of the record: a line whose power changes over
// the record (it comes and goes with the board's surroundings) stands out in the half that
// holds it and is diluted over the whole.
struct LineScanSegment {
  std::size_t offset = 0, length = 0;  // samples of the record
  std::size_t k_lo = 0, k_hi = 0;      // bins of the segment's own periodogram
  std::vector<std::size_t> scales;
  std::size_t background_block = 0;
};

struct Context {
  std::size_t n = 0;
  double rate = 0.0, tau0 = 0.0;
  std::vector<std::size_t> ms;
  std::vector<double> taus, edf;
  std::vector<double> t_grid;                // Gauss–Markov correlation times tried
  std::size_t block = 1, blocks = 0;         // block length [samples], number of blocks
  std::vector<double> temp_blocks;           // detrended block means of temperature (empty: none)
  std::vector<std::size_t> scales;           // Haar scales [blocks]
  std::size_t k_lo = 0, k_hi = 0;            // periodogram bins searched for a sinusoid or a line
  std::vector<std::size_t> line_scales;      // widths [bins] of the narrowband scan (narrowband.cpp)
  std::size_t line_background_block = 0;     // bins per median of its background
  std::vector<LineScanSegment> line_halves;  // the same scan on each half (empty: too short)
  std::vector<double> psd_edges;
  ChainModel chain;
};

ChainModel makeChainModel(const AcquisitionChain& chain, double rate_hz, std::span<const std::size_t> ms);
// The white coefficient c (σ² = c/τ) of a set of terms.
double whiteCoefficientOf(const NoiseTerms& terms);
// Allan variances with the white and flicker power the DLPF took at short τ added back (for
// the white and bias-instability terms given; the quantisation's white share is not
// filtered): what the five terms describe.
std::vector<double> chainCorrectedVariances(std::span<const double> variance, const Context& c,
                                            const NoiseTerms& terms);
// The five terms of an Allan curve made through c.chain (fitNoiseTerms when there is no DLPF).
NoiseTermFit fitChainTerms(const std::vector<AllanPoint>& curve, const Context& c);
// The chain's white noise of coefficient c (less the quantisation's) added to x, its own stream.
void addChainWhiteNoise(std::vector<double>& x, const ChainModel& chain, double white_coefficient, std::uint64_t seed);
// n samples of x filtered by the chain's flicker filter (x has n + flicker_ma.size() − 1
// samples: the first ones only fill the filter).
std::vector<double> filterChainFlicker(std::span<const double> x, const ChainModel& chain, std::size_t n);
// Rounded to the chain's LSB at a random offset (nothing without FS_SEL).
void quantiseLikeTheChip(std::vector<double>& x, const ChainModel& chain, std::uint64_t seed);

// The Allan grid, Gauss–Markov grid, blocks, Haar scales, sinusoid bins and PSD bands of the
// detrended series xd; `curve` gets its Allan deviation table.
// The periodogram bins searched for a sinusoid or a line in a series of n samples.
struct SearchedBins {
  std::size_t nfft = 0, k_lo = 0, k_hi = 0;
};
SearchedBins searchedBins(std::size_t n);

Context makeContext(const AxisModelCheckInput& in, std::span<const double> xd, std::vector<AllanPoint>& curve);

enum StatMask : unsigned {
  kStatAllan = 1u,
  kStatOutliers = 2u,
  kStatSpectrum = 4u,
  kStatTemperature = 8u,
  kStatSteps = 16u,
  kStatGaussMarkov = 32u,
  kStatPsd = 64u,
  kStatWhiteness = 128u,
  kStatAll = 255u,
};

struct SeriesStats {
  std::vector<double> log_adev;  // ln σ per m
  double outlier_max_z = kNaN;
  double spectral_log_ratio = kNaN;
  std::size_t spectral_bin = 0;
  double line_scan = kNaN;  // the narrowband scan's statistic (narrowband.cpp)
  double temp_slope = kNaN;
  // Per Haar scale of c.scales: the largest |D_W| of the low-passed residual and the mean of
  // D_W² over its positions (the replicas' pooled mean square standardises the scan).
  std::vector<double> step_scale_max, step_scale_ms;
  double gm_statistic = kNaN;
  std::vector<double> psd, psd_max;
  double whiteness_q = kNaN;                                   // Ljung–Box Q of heldOutWhiteness (the misfit's null)
  double halves_colour_q = kNaN, halves_spectrum_stat = kNaN;  // halvesChange (the misfit's null)
};

SeriesStats measureSeries(std::span<const double> xd, const Context& c, unsigned mask);

// Least-squares slope of the low-passed residual y on the temperature blocks tb (no intercept).
double temperatureSlope(const std::vector<double>& y, const std::vector<double>& tb);
// √(χ² gain) of the Allan fit with a Gauss–Markov term.
double gaussMarkovStatistic(const GaussMarkovCurveFit& fit);
// Block means of x with their least-squares line removed.
std::vector<double> lowPassedResidual(std::span<const double> x, const Context& c);
// The step scan's per-scale measures of y (steps.cpp) into s.step_scale_*.
void measureStepScales(const std::vector<double>& y, const Context& c, SeriesStats& s);

// ---- nulls and what the result reports of a statistic ----------------------------------

std::vector<double> column(const std::vector<SeriesStats>& reps, double SeriesStats::*field);
double medianOf(std::vector<double> v);
CheckStatistic makeStatistic(const std::string& name, double value, const NullSummary& null);
// The evidence of a statistic that fired: its value, threshold and null.
EffectEvidence nullEvidence(double value, const NullSummary& null, std::size_t replicas);

// ---- replicas ------------------------------------------------------------------------------

SimulationModel pureModel(double rate, const NoiseTerms& terms);
// The 1-σ uncertainty of a fit without noise_fit's reduced-χ² scale.
NoiseTerms statisticalUncertainty(const NoiseTermFit& fit);
// o.replicas replicas of `model` (terms perturbed by `uncertainty`) plus `added`, measured by
// `mask`; replica i of `round` is seeded from (o.seed, round, i) alone. `per_series`, when
// given, also sees each replica series (with its index; called from the pool's threads).
using ReplicaSeriesHook = std::function<void(std::size_t, std::span<const double>)>;
std::vector<SeriesStats> runReplicas(const SimulationModel& model, const NoiseTerms& uncertainty, const Context& c,
                                     std::span<const double> added, const ModelCheckOptions& o, std::uint64_t round,
                                     unsigned mask, const ReplicaSeriesHook& per_series = {});

// The Allan band of the replicas around the measured curve and the null of its largest |z|.
struct AllanNull {
  AllanBand band;
  std::vector<double> median_log, spread_log;
  NullSummary max_z;
  std::vector<double> whiteness_q;                            // the replicas' held-out Ljung–Box Q (when measured)
  std::vector<double> halves_colour_q, halves_spectrum_stat;  // the replicas' halvesChange
};
AllanNull allanNull(const std::vector<SeriesStats>& reps, const std::vector<double>& measured_log, const Context& c,
                    double alpha);
double maxAbsZ(const std::vector<double>& log_adev, const std::vector<double>& med, const std::vector<double>& spread,
               std::vector<double>* z_out = nullptr);

// ---- effects found, removed from the working series -----------------------------------------

struct Removal {
  std::vector<SinusoidFit> sinusoids;
  std::vector<NarrowbandLine> lines;  // shrunk out of the working series, not subtracted
  double k = 0.0;
  bool temperature = false;
  std::vector<std::size_t> step_samples;
  std::vector<double> step_sizes;
};

// The deterministic part of the named effects, per sample.
std::vector<double> deterministicPart(const Removal& r, std::size_t n, double rate,
                                      const std::vector<double>& temp_detrended);

// ---- the detectors ---------------------------------------------------------------------------

// Gaps in t: no replicas needed (a regular sampler never leaves a 1.5·τ0 gap).
void checkSampleTiming(std::span<const double> time_s, AxisModelCheck& out);

struct OutliersFound {
  bool found = false;
  std::size_t count = 0;
  double median_amplitude = 0.0;
  std::vector<std::size_t> samples;  // where the named outliers are (ascending)
};
// Samples of xc beyond the null of the largest robust z, each replaced in xc by the mean of
// its neighbours in xd that are not outliers themselves.
OutliersFound checkOutliers(std::span<const double> xd, std::vector<double>& xc, const NullSummary& null,
                            std::size_t replicas, AxisModelCheck& out);

// Lines in the spectrum, one at a time until neither the single-bin peak (`null`) nor the
// narrowband scan (`scan_null`) fires: each fitted as a resonance (narrowband.cpp); one whose
// width is not resolved is a fixed sinusoid, fitted and subtracted from xc; a wider one a
// narrowband line, shrunk out of xc. Returns whether one was named.
bool checkSinusoids(std::vector<double>& xc, const Context& c, const NullSummary& null, const NullSummary& scan_null,
                    std::size_t replicas, Removal& removal, AxisModelCheck& out);

// ---- narrowband lines (narrowband.cpp) --------------------------------------------------------

// Widths [bins] of the scan: 4, 8, … up to 1 Hz and 1/16 of the bins.
std::vector<std::size_t> lineScanScales(std::size_t bins, double df);
// Bins per median block of the scan's background: four times its widest band, ≥ 256.
std::size_t lineBackgroundBlock(double df);
// The periodogram's local level from medians of blocks of `block` bins (÷ ln 2), log-linear
// between block centres.
std::vector<double> blockMedianBackground(const std::vector<double>& power, std::size_t block);
// The largest band of excess power: for each width w of `scales`, the band of w bins whose
// mean ratio to the background is largest, scored as −ln of its tail probability under no
// line (a mean of w Hann periodogram bins ~ Gamma(w/κ, κ/w)); the best over widths.
struct LineScan {
  double statistic = 0.0;
  std::size_t centre_bin = 0, width_bins = 0;
};
LineScan scanForLines(const std::vector<double>& power, const std::vector<double>& background, std::size_t k_lo,
                      std::size_t k_hi, const std::vector<std::size_t>& scales);
// The scan of each half of x (c.line_halves): the best band of either, in Hz; statistic 0
// when the halves are too short to scan. Its statistic is on the whole record's scale
// (−ln of a tail probability), and the detector reads the larger of the two.
struct HalfLineScan {
  double statistic = 0.0;
  double centre_hz = 0.0, width_hz = 0.0;
  std::size_t half = 0;  // which of c.line_halves
};
HalfLineScan scanHalvesForLines(std::span<const double> x, const Context& c);
// The grids of c.line_halves for a record of n samples at `rate`.
std::vector<LineScanSegment> lineScanHalves(std::size_t n, double rate);
// The resonance (narrowband_line.hpp) plus a log-linear background, fitted by the Whittle
// likelihood to the one-sided PSD near `centre_bin`.
struct NarrowbandFit {
  bool fitted = false;
  bool resolved = false;   // wider than a fixed sinusoid's peak: a narrowband line
  bool broadband = false;  // wider than any line (2 Hz, or half its centre): colour the catalogue does not name
  double centre_hz = 0.0, width_hz = 0.0, rms_dps = 0.0;
  double background_psd = 0.0;  // the fitted background at the centre
};
// Search: from the scan's guess (up to 1500 groups, Nelder–Mead restarted once). Refit: near a
// line already fitted, as on each replica for the intervals (groups of a quarter of its
// width, one shorter run): the intervals' cost on a 1 h record.
enum class LineFitEffort { Search, Refit };
NarrowbandFit fitNarrowbandLine(const std::vector<double>& psd, const std::vector<double>& background, double df,
                                double rate, std::size_t centre_bin, std::size_t width_bins, std::size_t k_lo,
                                std::size_t k_hi, LineFitEffort effort = LineFitEffort::Search);
// One-sided PSD [(°/s)²/Hz] of a Hann periodogram.
std::vector<double> onesidedPsd(const Periodogram& p, double rate);
// Any level on the periodogram's scale (its background) on the PSD's.
std::vector<double> onesidedPsd(const Periodogram& p, std::vector<double> level, double rate);
// x with the line's power taken out: its spectrum times √(b/(b + S_line)), b the background.
void shrinkNarrowbandLine(std::vector<double>& x, const NarrowbandLine& line, double background_psd, double rate);

// The temperature channel detrended as the rate is, and its block means.
struct TemperatureChannel {
  std::vector<double> detrended;
  std::vector<double> raw_blocks;  // block means of the measured temperature (plots)
  // `detrended` smoothed over a block (centred moving average): the regressor of the extended
  // model. The channel's own noise and its 1/340 °C steps times k would otherwise add white
  // noise to the replicas and to the Kalman filter's regressor (seen: an extension with a
  // true temperature response scored worse than the base model).
  std::vector<double> smoothed;
};

// A temperature response and bias steps on the low-passed residual of xc, told apart, fitted
// and subtracted from xc; base_reps give the first null. Returns whether one was named.
bool checkTemperatureAndSteps(const AxisModelCheckInput& input, std::vector<double>& xc, const Context& c,
                              const TemperatureChannel& temp, const std::vector<SeriesStats>& base_reps,
                              const ModelCheckOptions& o, Removal& removal, AxisModelCheck& out);

struct GaussMarkovFound {
  bool found = false;
  GaussMarkovCurveFit fit;
  NoiseTermFit clean_fit;     // five terms of the cleaned series
  NoiseTerms extended_terms;  // the model's terms: with the Gauss–Markov term's when found
};
// A bump in the Allan curve of the cleaned series xc; `curve` is the measured series' table,
// used when nothing deterministic was removed.
GaussMarkovFound checkGaussMarkov(std::span<const double> xc, const Context& c, bool deterministic_found,
                                  const std::vector<AllanPoint>& curve, const std::vector<SeriesStats>& base_reps,
                                  const ModelCheckOptions& o, AxisModelCheck& out);

// ---- the extended model --------------------------------------------------------------------

struct ExtensionInputs {
  std::span<const double> xd;  // measured series, detrended
  std::span<const double> xc;  // with the named effects removed
  const std::vector<double>* measured_log_adev = nullptr;
  const AllanNull* base_allan = nullptr;
  const Removal* removal = nullptr;
  const std::vector<double>* temp_detrended = nullptr;
  const GaussMarkovFound* gauss_markov = nullptr;
  OutliersFound outliers;
  bool deterministic_found = false;
};

// The misfit of the final model (misfit.cpp): the whiteness of what it leaves (`residual`:
// the detrended series, or the cleaned one when the extension is accepted), fitted on the
// first half and scored on the second; the share of its Allan curve in the simultaneous band.
// The whiteness p is the measured Q's tail under a Gumbel fitted to the base replicas' Q
// (`base_null`, whiteNullP), and where a misfit is stated the halves' change is read against
// the replicas' (halvesChange).
ModelMisfit judgeMisfit(std::span<const double> residual, const AllanBand& band, const AllanNull& base_null,
                        double rate_hz, const AxisModelCheck& spectra);

// Replicas of the extended model: its Allan band, what it leaves unexplained, and the gain
// (Allan band and Kalman innovations, base against extended).
void checkExtendedModel(const ExtensionInputs& in, const Context& c, const ModelCheckOptions& o, AxisModelCheck& out);

}  // namespace gyrod::processing::model_check_detail
