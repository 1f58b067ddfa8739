#include "daemon/sample_pipeline.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "formats/calibration.hpp"

namespace gyrod::daemon {
namespace {

using processing::RollingOverlappingAllan;

RollingOverlappingAllan makeAllan(const PipelineSettings& s) {
  if (s.allan_cluster_sizes.empty()) return RollingOverlappingAllan(s.allan_window_samples);
  return RollingOverlappingAllan(s.allan_window_samples, s.allan_cluster_sizes);
}

std::array<RollingOverlappingAllan, kAxes> makeAllanArray(const PipelineSettings& s) {
  return {makeAllan(s), makeAllan(s), makeAllan(s)};
}

const PipelineSettings& validated(const PipelineSettings& s) {
  if (!(s.rate_hz > 0.0) || !std::isfinite(s.rate_hz))
    throw std::invalid_argument("the sample pipeline needs a rate > 0 Hz, got " + std::to_string(s.rate_hz));
  if (!(s.still_seconds >= 0.0) || !std::isfinite(s.still_seconds))
    throw std::invalid_argument("pipeline: still period must be >= 0 s");
  for (double b : s.bias_dps)
    if (!std::isfinite(b)) throw std::invalid_argument("pipeline: bias values must be finite");
  return s;
}

}  // namespace

std::string_view toString(BiasOrigin origin) {
  switch (origin) {
    case BiasOrigin::Config: return "config";
    case BiasOrigin::Model: return "model";
    case BiasOrigin::Estimate: return "estimate";
  }
  return "?";
}

std::string_view toString(RateModel model) { return model == RateModel::SensorModel ? "model" : "bias"; }

SamplePipeline::SamplePipeline(const PipelineSettings& settings)
    : settings_(validated(settings)),
      allan_raw_(makeAllanArray(settings)),
      allan_mean_(makeAllanArray(settings)),
      allan_kalman_(makeAllanArray(settings)) {
  if (settings_.bias_origin != BiasOrigin::Estimate) bias_ = settings_.bias_dps;
  if (settings_.rate_model) {
    rate_.emplace(*settings_.rate_model);  // validates them
    attitude_.emplace(recording::rateStreamAttitudeParameters(*settings_.rate_model));
  }
  for (auto& p : params_) {
    p.mean_window = settings_.mean_window;
    p.mean_threshold_dps = settings_.mean_threshold_dps;
  }
  // Validate the filter settings now rather than at the end of the still period.
  processing::GrossErrorMeanFilter probe(settings_.mean_window, settings_.mean_threshold_dps);
  (void)probe;
  if (needsStillPeriod()) {
    still_samples_ = static_cast<std::size_t>(std::llround(settings_.still_seconds * settings_.rate_hz));
    const bool identifying = !(settings_.kalman.a && settings_.kalman.q && settings_.kalman.r);
    if (identifying && still_samples_ < kMinimumIdentificationSamples) {
      std::ostringstream msg;
      msg << "bias.still_seconds = " << settings_.still_seconds << " gives " << still_samples_ << " samples at "
          << settings_.rate_hz << " Hz; identifying the Kalman filter needs at least " << kMinimumIdentificationSamples
          << " (or give filter.kalman a, q and r)";
      throw std::invalid_argument(msg.str());
    }
    if (still_samples_ == 0)
      throw std::invalid_argument("bias.still_seconds must give at least one sample to estimate the bias");
    for (auto& v : still_) v.reserve(still_samples_);
    if (settings_.still_window_off_loop) {
      // Half a second of samples held without allocating (the evaluation takes ~50 ms at 8 kHz);
      // a slower one grows the buffers, once.
      const auto held = static_cast<std::size_t>(std::ceil(0.5 * settings_.rate_hz)) + 16;
      held_.reserve(held);
      releasing_.reserve(held);
      released_.reserve(held);
    }
    phase_ = PipelinePhase::Estimating;
    still_period_.state = StillPeriodState::Collecting;
  } else {
    for (auto& p : params_) p.kalman = {*settings_.kalman.a, *settings_.kalman.q, *settings_.kalman.r, 0.0, {}};
    startFilters();
  }
}

bool SamplePipeline::needsStillPeriod() const {
  return settings_.bias_origin == BiasOrigin::Estimate ||
         !(settings_.kalman.a && settings_.kalman.q && settings_.kalman.r);
}

double SamplePipeline::stillSecondsNeeded() const {
  return needsStillPeriod() ? static_cast<double>(still_samples_) / settings_.rate_hz : 0.0;
}

bool SamplePipeline::kalmanIdentified() const {
  return !(settings_.kalman.a && settings_.kalman.q && settings_.kalman.r);
}

void SamplePipeline::startFilters() {
  chains_.clear();
  for (std::size_t axis = 0; axis < kAxes; ++axis) chains_.emplace_back(params_[axis]);
  phase_ = PipelinePhase::Running;
}

StillWindowOutcome evaluateStillWindow(StillWindow window) {
  StillWindowOutcome outcome;
  const PipelineSettings& s = window.settings;
  auto& still = window.samples;
  processing::StillPeriodCheckParameters check;
  check.low_pass_bandwidth_hz = s.low_pass_bandwidth_hz;
  outcome.verdict = processing::checkStillPeriod({still[0], still[1], still[2]}, s.rate_hz, check);
  if (!outcome.verdict.moved || window.identify_even_if_moved) {
    // Worked on copies: a still period that cannot identify the filter (a sensor whose output
    // never changes gives zero variance) changes nothing and starts again, rather than being
    // retried and refused at every following sample with the samples piling up.
    Vec3 bias = window.bias;
    std::array<processing::FilterChainParameters, kAxes> params = window.params;
    const bool identify = !(s.kalman.a && s.kalman.q && s.kalman.r);
    std::size_t axis = 0;  // named in the message when this axis cannot be identified
    try {
      for (axis = 0; axis < kAxes; ++axis) {
        auto& x = still[axis];
        if (s.bias_origin == BiasOrigin::Estimate) {
          long double sum = 0.0L;
          for (double v : x) sum += v;
          bias[axis] = static_cast<double>(sum / static_cast<long double>(x.size()));
        }
        for (double& v : x) v -= bias[axis];
        if (identify) {
          params[axis] = processing::identifyFilterChain(x, s.mean_window, s.mean_threshold_dps, s.kalman);
        } else {
          params[axis].kalman = {*s.kalman.a, *s.kalman.q, *s.kalman.r, 0.0, {}};
        }
      }
      outcome.identified = true;
      outcome.bias = bias;
      outcome.params = params;
    } catch (const std::invalid_argument& e) {
      std::ostringstream msg;
      msg << "the still period cannot identify the filter on axis "
          << "xyz"[axis] << " (" << e.what()
          << "; a sensor whose output never changes?): estimating again over the next " << s.still_seconds << " s";
      outcome.error = msg.str();
    }
  }
  outcome.samples = std::move(still);
  return outcome;
}

StillWindow SamplePipeline::stillWindowJob() {
  StillWindow job;
  job.samples = std::move(still_);
  job.settings = settings_;
  job.settings.rate_model.reset();  // not needed, and not copied off the loop
  job.bias = bias_;
  job.params = params_;
  job.identify_even_if_moved = still_period_.attempts + 1 >= kMaxStillAttempts;
  return job;
}

bool SamplePipeline::applyStillWindow(StillWindowOutcome&& outcome) {
  still_period_.verdict = outcome.verdict;
  ++still_period_.attempts;
  ++still_period_.verdicts;
  still_ = std::move(outcome.samples);
  still_window_error_.clear();
  if (outcome.verdict.moved && still_period_.attempts < kMaxStillAttempts) {
    still_period_.state = StillPeriodState::MovedRetrying;
    for (auto& x : still_) x.clear();  // capacity kept: the next window allocates nothing
    phase_ = PipelinePhase::Estimating;
    return false;
  }
  if (!outcome.identified) {
    for (auto& x : still_) x.clear();                    // capacity kept: the next still period allocates nothing
    still_period_.state = StillPeriodState::Collecting;  // a fresh start, motion check included
    still_period_.attempts = 0;
    still_window_error_ = outcome.error;
    phase_ = PipelinePhase::Estimating;
    return false;
  }
  still_period_.state = outcome.verdict.moved ? StillPeriodState::MovedKept : StillPeriodState::Still;
  bias_ = outcome.bias;
  params_ = outcome.params;
  // A SIGHUP while the window was evaluated off the loop: its given values win, as they would
  // have over an identification made before it.
  for (auto& p : params_) {
    p.mean_window = settings_.mean_window;
    p.mean_threshold_dps = settings_.mean_threshold_dps;
    if (settings_.kalman.a) p.kalman.a = *settings_.kalman.a;
    if (settings_.kalman.q) p.kalman.q = *settings_.kalman.q;
    if (settings_.kalman.r) p.kalman.r = *settings_.kalman.r;
  }
  for (auto& x : still_) std::vector<double>().swap(x);  // the still period is over: give the memory back
  startFilters();
  return true;
}

void SamplePipeline::finishEstimation() {
  if (!applyStillWindow(evaluateStillWindow(stillWindowJob())) && !still_window_error_.empty())
    throw std::invalid_argument(still_window_error_);
}

StillWindow SamplePipeline::takeStillWindow() {
  if (!stillWindowWaiting()) throw std::logic_error("the still window was asked for before it was full");
  still_window_taken_ = true;
  return stillWindowJob();
}

std::span<const ProcessedSample> SamplePipeline::finishStillWindow(StillWindowOutcome outcome) {
  if (phase_ != PipelinePhase::Identifying || !still_window_taken_)
    throw std::logic_error("a still window outcome came without a window handed off the loop");
  still_window_taken_ = false;
  applyStillWindow(std::move(outcome));
  // The held samples, in order, as process() would have continued with them.
  releasing_.swap(held_);
  held_.clear();
  released_.clear();
  for (HeldSample& h : releasing_) {
    if (phase_ == PipelinePhase::Identifying) {  // a new window filled from them: held again
      held_.push_back(h);
      continue;
    }
    advance(h.out, h.discontinuity_before);
    if (h.out.held) {
      held_.push_back(h);  // the window filled at this one; the next are held
      continue;
    }
    released_.push_back(h.out);
  }
  releasing_.clear();
  if (discontinuity_pending_ && phase_ != PipelinePhase::Identifying) {  // a gap after the last held sample
    discontinuity_pending_ = false;
    for (auto& c : chains_) c.reset();
  }
  return released_;
}

void SamplePipeline::advance(ProcessedSample& out, bool discontinuity_before) {
  out.held = false;
  if (phase_ == PipelinePhase::Identifying) {
    held_.push_back({out, discontinuity_before || std::exchange(discontinuity_pending_, false)});
    out.held = true;
    return;
  }
  if (discontinuity_before)
    for (auto& c : chains_) c.reset();
  if (!rate_ && phase_ == PipelinePhase::Running) {
    for (std::size_t axis = 0; axis < kAxes; ++axis) out.rate[axis] = out.raw[axis] - bias_[axis];
    out.rate_bias = bias_;
    out.has_rate = true;
  }
  if (phase_ == PipelinePhase::Estimating) {
    for (std::size_t axis = 0; axis < kAxes; ++axis) still_[axis].push_back(out.raw[axis]);  // reserved: no allocation
    if (still_[0].size() >= still_samples_) {
      if (settings_.still_window_off_loop)
        phase_ = PipelinePhase::Identifying;  // the samples after this one are held
      else
        finishEstimation();
    }
    return;
  }
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    const processing::FilteredRate f = chains_[axis].update(out.raw[axis] - bias_[axis]);
    out.mean[axis] = f.mean_dps;
    out.kalman[axis] = f.kalman_dps;
    allan_mean_[axis].push(f.mean_dps);
    allan_kalman_[axis].push(f.kalman_dps);
  }
  out.filtered = true;
}

ProcessedSample SamplePipeline::process(std::uint64_t seq, double t_s, const Vec3& raw_dps, double temp_c,
                                        const Vec3& accel_g) {
  ProcessedSample out;
  out.seq = seq;
  out.t_s = t_s;
  out.temp_c = temp_c;
  out.raw = raw_dps;
  ++processed_;
  if (!first_t_s_) first_t_s_ = t_s;
  last_t_s_ = t_s;
  const bool has_accel = std::isfinite(accel_g[0]) && std::isfinite(accel_g[1]) && std::isfinite(accel_g[2]);
  if (!accel_device_) {
    accel_device_ = has_accel;
    if (!has_accel) attitude_.reset();  // a gyro-only device: no orientation to compute, ever
  }
  for (std::size_t axis = 0; axis < kAxes; ++axis) allan_raw_[axis].push(raw_dps[axis]);
  if (rate_) {
    rate_->observeAccel(accel_g);  // a tilt the gyro cannot tell from bias is not still
    const processing::RateSample r = rate_->update(t_s, raw_dps, temp_c);
    out.rate = r.rate_dps;
    out.rate_bias = r.bias_dps;
    out.still = r.still;
    out.has_rate = true;
    // The orientation from the rate stream and the accel, as `gyroctl attitude --model` computes
    // it from a recording; published only for a sample that has the accel.
    if (attitude_) {
      const processing::attitude::AttitudeSample a = attitude_->update(r.rate_dps, accel_g);
      if (has_accel) out.attitude = a;
    }
  }
  advance(out, false);
  return out;
}

void SamplePipeline::discontinuity() {
  if (phase_ == PipelinePhase::Identifying) {
    discontinuity_pending_ = true;  // at its place among the held samples
    return;
  }
  for (auto& c : chains_) c.reset();
}

void SamplePipeline::reloadFilter(std::size_t mean_window, double mean_threshold_dps,
                                  const processing::KalmanOverrides& kalman) {
  // Everything is validated on copies first, so that a bad reload changes nothing.
  processing::GrossErrorMeanFilter probe(mean_window, mean_threshold_dps);
  (void)probe;
  processing::ScalarKalmanFilter given(
      {kalman.a.value_or(0.0), kalman.q.value_or(0.0), kalman.r.value_or(1.0), 0.0, {}});
  (void)given;
  std::array<processing::FilterChainParameters, kAxes> params = params_;
  for (auto& p : params) {
    p.mean_window = mean_window;
    p.mean_threshold_dps = mean_threshold_dps;
    if (kalman.a) p.kalman.a = *kalman.a;
    if (kalman.q) p.kalman.q = *kalman.q;
    if (kalman.r) p.kalman.r = *kalman.r;
    if (phase_ == PipelinePhase::Running) processing::ScalarKalmanFilter check(p.kalman);
  }
  settings_.mean_window = mean_window;
  settings_.mean_threshold_dps = mean_threshold_dps;
  if (kalman.a) settings_.kalman.a = kalman.a;
  if (kalman.q) settings_.kalman.q = kalman.q;
  if (kalman.r) settings_.kalman.r = kalman.r;
  params_ = params;
  if (phase_ == PipelinePhase::Running) startFilters();
}

void SamplePipeline::reloadRateModel(const std::optional<processing::RateEstimatorParameters>& rate_model) {
  std::optional<processing::RateEstimatorParameters> p = rate_model;
  // The warm-up shape counts from the estimator's first sample: continue the one that began
  // at the pipeline's first sample, A·e^{−(t + Δ)/τ} = (A·e^{−Δ/τ})·e^{−t/τ}.
  if (p && first_t_s_) {
    const double elapsed = last_t_s_ - *first_t_s_ + 1.0 / p->rate_hz;
    for (auto& axis : p->axes)
      if (axis.warm_up_time_constant_s > 0.0)
        axis.warm_up_amplitude_dps *= std::exp(-elapsed / axis.warm_up_time_constant_s);
  }
  std::optional<processing::RateEstimator> fresh;
  if (p) fresh.emplace(*p);  // throws before anything changes
  settings_.rate_model = p;
  rate_ = std::move(fresh);
  // The orientation goes on through a new model (its parameters differ only in the 1σ terms):
  // a reload must not turn the heading back to 0.
  if (!p)
    attitude_.reset();
  else if (!attitude_ && accel_device_.value_or(true))
    attitude_.emplace(recording::rateStreamAttitudeParameters(*p));
}

bool SamplePipeline::startRateFrom(const processing::LearnedResidual& learned, double elapsed_s) {
  if (!rate_ || processed_ > 0) return false;
  rate_->startFrom(learned, elapsed_s);
  return true;
}

AllanStreams SamplePipeline::allanSnapshot() const {
  AllanStreams s;
  s.tau0_s = 1.0 / settings_.rate_hz;
  s.window_s = static_cast<double>(settings_.allan_window_samples) / settings_.rate_hz;
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    s.raw[axis] = allan_raw_[axis].snapshot(s.tau0_s);
    s.mean[axis] = allan_mean_[axis].snapshot(s.tau0_s);
    s.kalman[axis] = allan_kalman_[axis].snapshot(s.tau0_s);
  }
  return s;
}

const RollingOverlappingAllan& SamplePipeline::allanStream(std::size_t axis, AllanStream stream) const {
  switch (stream) {
    case AllanStream::Raw: return allan_raw_.at(axis);
    case AllanStream::Mean: return allan_mean_.at(axis);
    case AllanStream::Kalman: return allan_kalman_.at(axis);
  }
  return allan_raw_.at(axis);
}

namespace {

// The window point at cluster index i, with the noise type `alphas` found at the last refit
// (none: edf and interval NaN), computed as RollingOverlappingAllan::snapshot() does.
processing::AllanPoint windowPoint(const RollingOverlappingAllan& a, std::size_t i, double tau0_s,
                                   const std::vector<int>& alphas) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  processing::AllanPoint p;
  p.m = a.clusterSizes()[i];
  p.tau_s = static_cast<double>(p.m) * tau0_s;
  p.oadev = std::sqrt(a.windowVariance(i));
  p.oadev_terms = a.windowTerms(i);
  p.adev = kNaN;  // the non-overlapping estimator is not kept
  p.edf = p.oadev_lo = p.oadev_hi = kNaN;
  if (alphas.size() != a.clusterSizes().size() || !std::isfinite(p.oadev) || a.windowCount() < 4) return p;
  try {
    p.noise_alpha = alphas[i];
    p.edf = processing::overlappingAllanEdf(p.noise_alpha, a.windowCount() + 1, p.m);
    const auto interval =
        processing::allanDeviationConfidenceInterval(p.oadev, p.edf, processing::AllanOptions{}.confidence);
    p.oadev_lo = interval.lo;
    p.oadev_hi = interval.hi;
  } catch (const std::invalid_argument&) {
    p.noise_alpha = 0;
    p.edf = p.oadev_lo = p.oadev_hi = kNaN;
  }
  return p;
}

}  // namespace

AllanWindowDeviations SamplePipeline::allanWindowDeviations() const {
  AllanWindowDeviations d;
  d.tau0_s = 1.0 / settings_.rate_hz;
  d.window_s = static_cast<double>(settings_.allan_window_samples) / settings_.rate_hz;
  d.samples = allan_raw_[0].windowCount();
  for (const std::size_t m : allan_raw_[0].clusterSizes()) d.tau_s.push_back(static_cast<double>(m) * d.tau0_s);
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    for (std::size_t k = 0; k < kStreams; ++k) {
      const RollingOverlappingAllan& stream = allanStream(axis, static_cast<AllanStream>(k));
      for (std::size_t i = 0; i < d.tau_s.size(); ++i) {
        d.points[axis][k].push_back(windowPoint(stream, i, d.tau0_s, noise_alpha_[axis][k]));
        d.oadev[axis][k].push_back(d.points[axis][k].back().oadev);
      }
    }
  }
  return d;
}

NoiseRefit refitNoiseTerms(const RollingOverlappingAllan& stream, double tau0_s, bool fit_terms) {
  NoiseRefit refit;
  const auto snap = stream.snapshot(tau0_s);
  std::size_t usable = 0;
  for (const auto& p : snap.window) usable += (p.oadev_terms >= 2 && std::isfinite(p.oadev)) ? 1 : 0;
  if (usable < 3) return refit;  // too early for a fit of five terms to mean anything
  refit.too_early = false;
  for (const auto& p : snap.window) refit.noise_alpha.push_back(p.noise_alpha);
  if (!fit_terms) return refit;
  try {
    refit.fit = processing::fitNoiseTerms(snap.window);
  } catch (const std::exception&) {
    // e.g. a constant signal: nothing to fit
  }
  return refit;
}

void SamplePipeline::applyNoiseRefit(std::size_t axis, AllanStream stream, const NoiseRefit& refit) {
  if (refit.too_early) return;
  if (stream == AllanStream::Raw) noise_terms_.at(axis) = refit.fit;
  noise_alpha_.at(axis)[static_cast<std::size_t>(stream)] = refit.noise_alpha;
}

void SamplePipeline::refitNoiseTerms() {
  const double tau0 = 1.0 / settings_.rate_hz;
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    for (std::size_t k = 0; k < kStreams; ++k) {
      const auto stream = static_cast<AllanStream>(k);
      applyNoiseRefit(axis, stream,
                      daemon::refitNoiseTerms(allanStream(axis, stream), tau0, stream == AllanStream::Raw));
    }
}

}  // namespace gyrod::daemon
