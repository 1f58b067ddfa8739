#pragma once
// What gyrod does with each sample, per axis, in order (issue: "the loop"):
//   bias removal → mean filter → Kalman (processing/filter_chain.hpp, the same code and
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
//
// The `rate` stream (issue 11, docs/motion.md), beside the paper's chain and independent of it:
//  - with a sensor model (`rate_model`, from filter.model): processing::RateEstimator on every
//    sample from the first, fed (t, raw, temp) exactly as `gyroctl filter --model` feeds it
//    from the recording, so that the two agree bit for bit;
//  - without one: raw − the bias above (the start-up estimate, the config's or the model's
//    constant), from the end of the still period; no temperature term, no still detection.
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "processing/filter_chain.hpp"
#include "processing/noise_fit.hpp"
#include "processing/rate_estimator.hpp"
#include "processing/rolling_allan.hpp"

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
  Vec3 bias_dps{};              // used unless bias_origin == Estimate
  double still_seconds = 10.0;  // estimation period (bias and/or Kalman identification)
  std::size_t mean_window = 20;
  double mean_threshold_dps = 0.3;
  processing::KalmanOverrides kalman;  // given values; the rest are identified
  std::size_t allan_window_samples = 180000;
  std::vector<std::size_t> allan_cluster_sizes;  // empty = octave up to half the window
  // The rate stream's model (RateModel::SensorModel); none = raw − bias (ConstantBias).
  std::optional<processing::RateEstimatorParameters> rate_model;
};

enum class PipelinePhase { Estimating, Running };

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
};

struct AllanStreams {
  double tau0_s = 0.0;
  double window_s = 0.0;
  std::array<processing::RollingOverlappingAllan::Snapshot, kAxes> raw, mean, kalman;
};

// The window's overlapping Allan deviation of every stream at every τ, read from the
// rolling sums in O(number of τ): the numbers of allanSnapshot()'s window points, without
// their noise identification (O(window) per τ). What the ALLAN reply carries.
struct AllanWindowDeviations {
  double tau0_s = 0.0;
  double window_s = 0.0;
  std::vector<double> tau_s;
  std::array<std::array<std::vector<double>, 3>, kAxes> oadev;  // [axis][raw, mean, kalman]
};

// One axis's noise refit: too early (fewer than 3 usable τ: keep the previous fit), or the
// fit (empty when nothing can be fitted, e.g. a constant signal).
struct NoiseRefit {
  bool too_early = true;
  std::optional<processing::NoiseTermFit> fit;
};
// The refit of refitNoiseTerms for one raw stream; a free function so that it can run on a
// copy of the stream's state, off the event loop (seconds at a 1 h window at 1 kHz).
NoiseRefit refitNoiseTerms(const processing::RollingOverlappingAllan& raw_stream, double tau0_s);

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

  // New filter parameters (SIGHUP) without losing the stream: the bias and the identified
  // values are kept unless the new settings give them; the Allan statistics continue.
  void reloadFilter(std::size_t mean_window, double mean_threshold_dps, const processing::KalmanOverrides& kalman);
  // A new rate model (SIGHUP): the estimator restarts (its residual bias from the model's, its
  // still window empty); the model's warm-up shape continues from the pipeline's first sample.
  // Validated before anything changes; throws std::invalid_argument.
  void reloadRateModel(const std::optional<processing::RateEstimatorParameters>& rate_model);
  RateModel rateModel() const { return rate_ ? RateModel::SensorModel : RateModel::ConstantBias; }
  const processing::RateEstimator* rateEstimator() const { return rate_ ? &*rate_ : nullptr; }

  // Not per sample (allocates): the Allan curves of the window and since start.
  AllanStreams allanSnapshot() const;
  AllanWindowDeviations allanWindowDeviations() const;
  // Refit the five noise terms on the window of each raw axis (fitNoiseTerms).
  void refitNoiseTerms();
  // The same in parts: the raw stream of an axis, and the result of refitNoiseTerms on it.
  const processing::RollingOverlappingAllan& rawAllan(std::size_t axis) const { return allan_raw_.at(axis); }
  void applyNoiseRefit(std::size_t axis, const NoiseRefit& refit);
  const std::array<std::optional<processing::NoiseTermFit>, kAxes>& noiseTerms() const { return noise_terms_; }

  PipelinePhase phase() const { return phase_; }
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
  void startFilters();

  PipelineSettings settings_;
  PipelinePhase phase_ = PipelinePhase::Running;
  Vec3 bias_{};
  std::size_t still_samples_ = 0;
  std::array<std::vector<double>, kAxes> still_;  // reserved once
  std::array<processing::FilterChainParameters, kAxes> params_{};
  std::vector<processing::AxisFilterChain> chains_;  // kAxes, built at start and on reload
  std::optional<processing::RateEstimator> rate_;    // with a sensor model
  std::array<processing::RollingOverlappingAllan, kAxes> allan_raw_, allan_mean_, allan_kalman_;
  std::array<std::optional<processing::NoiseTermFit>, kAxes> noise_terms_;
  std::uint64_t processed_ = 0;
  std::optional<double> first_t_s_;  // of the first sample: the warm-up shape's origin
  double last_t_s_ = 0.0;
};

}  // namespace gyrod::daemon
