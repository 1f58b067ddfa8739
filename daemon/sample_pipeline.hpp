#pragma once
// What gyrod does with each sample, per axis, in order (issue: "the loop"):
//   bias removal → mean filter → Kalman (processing/paper/filter_chain.hpp, the same code and
//   numbers as `gyroctl filter`) → rolling Allan update of the raw, mean and Kalman streams.
// Pure computation: no I/O, no logging, no clock. process() allocates nothing.
//
// Where the bias and the Kalman parameters come from (said in STATUS):
//  - bias: from the config (`bias.source = "config"`), from a model file written by
//    `gyroctl analyze --write-model` ("model"), or estimated as the mean of the first
//    `still_seconds` of samples ("estimate");
//  - A, Q, R: each from the config when given there, else identified over the same still
//    period, exactly as `gyroctl filter` identifies them from a file (identifyFilterChain).
// While a still period is needed, samples are published raw only; the filters start on the
// first sample after it.
// The end of a still window (the motion check, the bias, the filter's identification: tens of
// milliseconds at 8 kHz) runs in process() by default. With PipelineSettings::
// still_window_off_loop, process() instead hands the window over (takeStillWindow), the
// caller evaluates it elsewhere (evaluateStillWindow) and gives the outcome back
// (finishStillWindow); the samples that come meanwhile are held (ProcessedSample::held) and
// released then, with exactly the values process() would have given them in order.
//
// The `rate` stream (issue 11, docs/motion.md), beside the paper's chain and independent of it:
//  - with a sensor model (`rate_model`, from filter.model): processing::RateEstimator on every
//    sample from the first, fed (t, raw, temp) exactly as `gyroctl filter --model` feeds it
//    from the recording, so that the two agree bit for bit;
//  - without one: raw − the bias above (the start-up estimate, the config's or the model's
//    constant), from the end of the still period; no temperature term, no still detection.
// With a sensor model, the orientation (processing/attitude) from the rate stream and the
// accel, sample by sample, as `gyroctl attitude --model` computes it from a recording.
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "processing/allan/noise_fit.hpp"
#include "processing/allan/rolling_allan.hpp"
#include "processing/attitude/attitude_estimator.hpp"
#include "processing/motion/rate_estimator.hpp"
#include "processing/motion/still_period_check.hpp"
#include "processing/paper/filter_chain.hpp"

namespace gyrod::daemon {

inline constexpr std::size_t kAxes = 3;
using Vec3 = std::array<double, kAxes>;
inline constexpr Vec3 kNoAccel = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                                  std::numeric_limits<double>::quiet_NaN()};

enum class BiasOrigin { Config, Model, Estimate };
std::string_view toString(BiasOrigin origin);

// What the `rate` stream subtracts from raw (STATUS rate_model).
enum class RateModel { SensorModel, ConstantBias };
std::string_view toString(RateModel model);

struct PipelineSettings {
  double rate_hz = 50.0;
  BiasOrigin bias_origin = BiasOrigin::Estimate;
  Vec3 bias_dps{};                     // used unless bias_origin == Estimate
  double still_seconds = 10.0;         // estimation period (bias and/or Kalman identification)
  double low_pass_bandwidth_hz = 0.0;  // the chip's DLPF bandwidth, for the still check; 0: none
  std::size_t mean_window = 20;
  double mean_threshold_dps = 0.3;
  processing::KalmanOverrides kalman;  // given values; the rest are identified
  std::size_t allan_window_samples = 180000;
  std::vector<std::size_t> allan_cluster_sizes;  // empty = octave up to half the window
  // The rate stream's model (RateModel::SensorModel); none = raw − bias (ConstantBias).
  std::optional<processing::RateEstimatorParameters> rate_model;
  // The end of a still window is evaluated by the caller, off the loop (see above).
  bool still_window_off_loop = false;
};

enum class PipelinePhase {
  Estimating,   // collecting the still window
  Identifying,  // the full window is evaluated off the loop; samples are held
  Running,      // the filters run
};

// The motion check of the start-up still period (processing/motion/still_period_check.hpp). A window
// in which the board moved is discarded and collected again, up to kMaxStillAttempts windows;
// if the last one moved too it is used (gyrod cannot wait for ever on a board that never
// rests) and the state says its bias is suspect.
enum class StillPeriodState {
  None,           // no still period (bias and filter configured)
  Collecting,     // the first window is being collected
  MovedRetrying,  // a window moved; the next is being collected
  Still,          // the window used passed the check
  MovedKept,      // every window moved; the last one was used
};
inline constexpr std::size_t kMaxStillAttempts = 3;
struct StillPeriodReport {
  StillPeriodState state = StillPeriodState::None;
  std::size_t attempts = 0;                // windows checked so far
  processing::StillPeriodVerdict verdict;  // of the last window checked
  std::uint64_t verdicts = 0;              // +1 per window checked (gyrod logs each)
};

struct ProcessedSample {
  std::uint64_t seq = 0;
  double t_s = 0.0;
  double temp_c = 0.0;
  Vec3 raw{};                 // as measured (bias not removed)
  Vec3 mean{};                // mean filter output on raw − bias
  Vec3 kalman{};              // Kalman output
  bool filtered = false;      // false while estimating: mean/kalman not set
  Vec3 rate{};                // the rate stream: raw − rate_bias (then the optional low-pass)
  Vec3 rate_bias{};           // b̂ subtracted from raw for rate
  bool has_rate = false;      // false while a constant bias is still being estimated
  std::optional<bool> still;  // the still detector's verdict (sensor model only)
  // The orientation from `rate` and the accel (sensor model and accel only; docs/attitude.md).
  std::optional<processing::attitude::AttitudeSample> attitude;
  bool held = false;  // off-loop still window: released later by finishStillWindow
};

// A full still window and what its evaluation needs, handed off the loop.
struct StillWindow {
  std::array<std::vector<double>, kAxes> samples;
  PipelineSettings settings;
  Vec3 bias{};
  std::array<processing::FilterChainParameters, kAxes> params{};
  bool identify_even_if_moved = false;  // the last window allowed: it is used whatever it shows
};
// Its evaluation: the motion verdict, and unless the window is to be collected again, the bias
// and the filter's parameters, or why they cannot be identified.
struct StillWindowOutcome {
  processing::StillPeriodVerdict verdict;
  bool identified = false;
  Vec3 bias{};
  std::array<processing::FilterChainParameters, kAxes> params{};
  std::string error;                               // identification failed: the message (the window is collected again)
  std::array<std::vector<double>, kAxes> samples;  // the window's memory, handed back
};
// Pure, may run on any thread.
StillWindowOutcome evaluateStillWindow(StillWindow window);

struct AllanStreams {
  double tau0_s = 0.0;
  double window_s = 0.0;
  std::array<processing::RollingOverlappingAllan::Snapshot, kAxes> raw, mean, kalman;
};

// identifyFilterChain fits AR(1) on the mean-filtered still period: fewer samples than
// this give a φ1 too uncertain to run a filter on (standard error ≈ 1/√n ≈ 0.1).
inline constexpr std::size_t kMinimumIdentificationSamples = 100;

inline constexpr std::size_t kStreams = 3;  // raw, mean, kalman
enum class AllanStream { Raw = 0, Mean, Kalman };

// The window's overlapping Allan deviation of every stream at every τ, read from the
// rolling sums in O(number of τ): the numbers of allanSnapshot()'s window points. Their noise
// type (O(window) per τ to identify) is the one the last noise refit identified on that
// stream; edf and the χ² interval are then computed as allanSnapshot() does, for the samples
// in the window now (NaN until a refit has identified the type). What the ALLAN reply carries.
struct AllanWindowDeviations {
  double tau0_s = 0.0;
  double window_s = 0.0;      // configured
  std::uint64_t samples = 0;  // in the raw window now
  std::vector<double> tau_s;
  std::array<std::array<std::vector<double>, kStreams>, kAxes> oadev;  // [axis][raw, mean, kalman]
  std::array<std::array<std::vector<processing::AllanPoint>, kStreams>, kAxes> points;
};

// One stream's noise refit: too early (fewer than 3 usable τ: keep the previous fit), or the
// fit (empty when nothing can be fitted, e.g. a constant signal), and the noise type found at
// each τ (lag-1 method; empty while too early).
struct NoiseRefit {
  bool too_early = true;
  std::optional<processing::NoiseTermFit> fit;
  std::vector<int> noise_alpha;
};
// The refit of refitNoiseTerms for one raw stream; a free function so that it can run on a
// copy of the stream's state, off the event loop (seconds at a 1 h window at 1 kHz). With
// fit_terms false only the noise types are identified (the mean and Kalman streams).
NoiseRefit refitNoiseTerms(const processing::RollingOverlappingAllan& stream, double tau0_s, bool fit_terms = true);

class SamplePipeline {
 public:
  // Throws std::invalid_argument for settings that cannot work (rate ≤ 0, still period
  // shorter than needed to identify the filter when something must be identified, ...).
  explicit SamplePipeline(const PipelineSettings& settings);

  // `accel_g` (x, y, z in g, NaN when the device has none) feeds the still detector only.
  ProcessedSample process(std::uint64_t seq, double t_s, const Vec3& raw_dps, double temp_c,
                          const Vec3& accel_g = kNoAccel);

  // After samples were lost: the filters restart on the next sample (their history is no
  // longer contiguous). The Allan statistics continue over the delivered samples.
  void discontinuity();

  // Off-loop still windows (PipelineSettings::still_window_off_loop): a full window waits to be
  // taken; the outcome of evaluateStillWindow on it ends the Identifying phase and releases the
  // held samples, in order, completed (valid until the next call on the pipeline). Samples that
  // end up held again (a new window filled from them) stay held. Throws std::logic_error when
  // no window was taken.
  bool stillWindowWaiting() const { return phase_ == PipelinePhase::Identifying && !still_window_taken_; }
  StillWindow takeStillWindow();
  std::span<const ProcessedSample> finishStillWindow(StillWindowOutcome outcome);
  // The identification failed (finishStillWindow's outcome carried an error): its message.
  const std::string& lastStillWindowError() const { return still_window_error_; }

  // New filter parameters (SIGHUP) without losing the stream: the bias and the identified
  // values are kept unless the new settings give them; the Allan statistics continue.
  void reloadFilter(std::size_t mean_window, double mean_threshold_dps, const processing::KalmanOverrides& kalman);
  // A new rate model (SIGHUP): the estimator restarts (its residual bias from the model's, its
  // still window empty); the model's warm-up shape continues from the pipeline's first sample.
  // Validated before anything changes; throws std::invalid_argument.
  void reloadRateModel(const std::optional<processing::RateEstimatorParameters>& rate_model);
  RateModel rateModel() const { return rate_ ? RateModel::SensorModel : RateModel::ConstantBias; }
  // The rate estimator begins from what an earlier run learned (processing::RateEstimator::
  // startFrom), before the first sample; false without a sensor model or after a sample.
  bool startRateFrom(const processing::LearnedResidual& learned, double elapsed_s);
  const processing::RateEstimator* rateEstimator() const { return rate_ ? &*rate_ : nullptr; }

  // Not per sample (allocates): the Allan curves of the window and since start.
  AllanStreams allanSnapshot() const;
  AllanWindowDeviations allanWindowDeviations() const;
  // Refit the five noise terms on the window of each raw axis (fitNoiseTerms), and identify
  // the noise type of every stream (for the ALLAN reply's intervals).
  void refitNoiseTerms();
  // The same in parts: the raw stream of an axis, and the result of refitNoiseTerms on it.
  const processing::RollingOverlappingAllan& rawAllan(std::size_t axis) const { return allan_raw_.at(axis); }
  const processing::RollingOverlappingAllan& allanStream(std::size_t axis, AllanStream stream) const;
  void applyNoiseRefit(std::size_t axis, const NoiseRefit& refit) { applyNoiseRefit(axis, AllanStream::Raw, refit); }
  void applyNoiseRefit(std::size_t axis, AllanStream stream, const NoiseRefit& refit);
  const std::array<std::optional<processing::NoiseTermFit>, kAxes>& noiseTerms() const { return noise_terms_; }

  PipelinePhase phase() const { return phase_; }
  const StillPeriodReport& stillPeriod() const { return still_period_; }
  const Vec3& bias() const { return bias_; }
  BiasOrigin biasOrigin() const { return settings_.bias_origin; }
  // Parameters the filters run with (valid once Running).
  const std::array<processing::FilterChainParameters, kAxes>& filterParameters() const { return params_; }
  // Which of A, Q, R were identified from the still period rather than configured.
  bool kalmanIdentified() const;
  std::uint64_t samplesProcessed() const { return processed_; }
  double stillSecondsNeeded() const;

 private:
  bool needsStillPeriod() const;
  void finishEstimation();
  // Applies a window's outcome; false: the window is being collected again (moved, or the
  // identification failed: then still_window_error_ says why).
  bool applyStillWindow(StillWindowOutcome&& outcome);
  StillWindow stillWindowJob();
  // The phase-dependent part of process() for a sample whose raw Allan and rate are done.
  void advance(ProcessedSample& out, bool discontinuity_before);
  void startFilters();

  PipelineSettings settings_;
  PipelinePhase phase_ = PipelinePhase::Running;
  Vec3 bias_{};
  std::size_t still_samples_ = 0;
  std::array<std::vector<double>, kAxes> still_;  // reserved once
  StillPeriodReport still_period_;
  std::array<processing::FilterChainParameters, kAxes> params_{};
  std::vector<processing::AxisFilterChain> chains_;                  // kAxes, built at start and on reload
  std::optional<processing::RateEstimator> rate_;                    // with a sensor model
  std::optional<processing::attitude::AttitudeEstimator> attitude_;  // on rate_'s stream
  // Whether the device gives the accel: its first sample decides (a FIFO carries the accel in
  // every frame or in none); none before it.
  std::optional<bool> accel_device_;
  std::array<processing::RollingOverlappingAllan, kAxes> allan_raw_, allan_mean_, allan_kalman_;
  std::array<std::optional<processing::NoiseTermFit>, kAxes> noise_terms_;
  std::array<std::array<std::vector<int>, kStreams>, kAxes> noise_alpha_;  // of the last refit, per τ
  std::uint64_t processed_ = 0;
  // Off-loop still windows: the samples held while one is evaluated, and those released.
  struct HeldSample {
    ProcessedSample out;
    bool discontinuity_before = false;
  };
  std::vector<HeldSample> held_, releasing_;
  std::vector<ProcessedSample> released_;
  bool still_window_taken_ = false;
  bool discontinuity_pending_ = false;
  std::string still_window_error_;
  std::optional<double> first_t_s_;  // of the first sample: the warm-up shape's origin
  double last_t_s_ = 0.0;
};

}  // namespace gyrod::daemon
