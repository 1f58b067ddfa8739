#include "driver/sample_clock.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gyrod::driver {

SampleClock::SampleClock(const SampleClockConfig& config) : config_(config) {
  const auto fail = [](const std::string& what) { throw std::invalid_argument("SampleClockConfig." + what); };
  if (!(config.nominal_period_ns > 0.0) || !std::isfinite(config.nominal_period_ns)) {
    fail("nominal_period_ns must be finite and > 0, got " + std::to_string(config.nominal_period_ns));
  }
  if (!(config.max_clock_error > 0.0 && config.max_clock_error < 0.5)) {
    fail("max_clock_error must be within (0, 0.5), got " + std::to_string(config.max_clock_error));
  }
  if (!(config.observation_tolerance_ns > 0.0) || !std::isfinite(config.observation_tolerance_ns)) {
    fail("observation_tolerance_ns must be finite and > 0, got " + std::to_string(config.observation_tolerance_ns));
  }
  if (!std::isfinite(config.observation_bias_ns)) fail("observation_bias_ns must be finite");
  if (!(config.easing > 0.0 && config.easing <= 1.0)) {
    fail("easing must be within (0, 1], got " + std::to_string(config.easing));
  }
  if (config.acquisition_observations < 1) fail("acquisition_observations must be >= 1");
  if (config.rejections_before_relock < 1) fail("rejections_before_relock must be >= 1");
  if (config.baseline_window < 2) fail("baseline_window must be >= 2");
  period_ns_ = config.nominal_period_ns;
  period_uncertainty_ = config.max_clock_error;
}

bool SampleClock::plausiblePeriod(double p) const {
  return std::fabs(p / config_.nominal_period_ns - 1.0) <= config_.max_clock_error;
}

void SampleClock::lock(double t, std::uint64_t n) {
  locked_ = true;
  anchor_t_ = t;
  anchor_n_ = n;
  baseline_t_ = t;
  baseline_n_ = n;
  observations_since_lock_ = 1;
  consecutive_rejections_ = 0;
  // The period may have been measured before the lock; it is the same oscillator, but the
  // new baseline has to be long enough again before it can refine the old estimate.
}

void SampleClock::lockApproximately(std::int64_t t_ns, std::uint64_t n) {
  lock(static_cast<double>(t_ns) - config_.observation_bias_ns, n);
  approximate_ = true;
}

void SampleClock::breakPhase() { locked_ = false; }

SampleClock::Verdict SampleClock::observe(std::int64_t t_ns, std::uint64_t n) {
  const double t = static_cast<double>(t_ns) - config_.observation_bias_ns;
  if (!locked_ || approximate_) {
    lock(t, n);
    approximate_ = false;
    return Verdict::Locked;
  }
  const double dn = static_cast<double>(static_cast<std::int64_t>(n - anchor_n_));
  const double residual = t - (anchor_t_ + dn * period_ns_);
  // The model's own uncertainty grows with the distance from the anchor.
  const double allowed = config_.observation_tolerance_ns + std::fabs(dn) * period_ns_ * period_uncertainty_;
  if (std::fabs(residual) > allowed) {
    ++rejections_total_;
    if (++consecutive_rejections_ >= config_.rejections_before_relock) {
      // Several observations in a row disagree with the model: the model is what is wrong
      // (e.g. a phase jump nobody announced). Start over from this observation.
      ++relocks_;
      lock(t, n);
      return Verdict::Relocked;
    }
    return Verdict::Rejected;
  }
  consecutive_rejections_ = 0;

  // Period over the baseline: (t − t_b) / (n − n_b). Used when it is plausible and either
  // more precise than what we have, or the baseline is half a window long (drift).
  const std::int64_t span = static_cast<std::int64_t>(n - baseline_n_);
  if (span > 0) {
    const double p = (t - baseline_t_) / static_cast<double>(span);
    const double uncertainty = 2.0 * config_.observation_tolerance_ns / (static_cast<double>(span) * p);
    if (plausiblePeriod(p) &&
        (uncertainty <= period_uncertainty_ || static_cast<std::uint64_t>(span) >= config_.baseline_window / 2)) {
      period_ns_ = p;
      period_uncertainty_ = std::min(uncertainty, config_.max_clock_error);
    }
  }

  // Anchor: hard during acquisition, eased afterwards (timestamps slew, never jump by more
  // than easing × tolerance).
  ++observations_since_lock_;
  const double beta = observations_since_lock_ <= config_.acquisition_observations ? 1.0 : config_.easing;
  const double predicted = anchor_t_ + dn * period_ns_;
  anchor_t_ = predicted + beta * (t - predicted);
  anchor_n_ = n;

  if (static_cast<std::uint64_t>(span) >= config_.baseline_window) {
    // Renew the baseline from the eased anchor (already averaged), not a raw observation.
    baseline_t_ = anchor_t_;
    baseline_n_ = anchor_n_;
  }
  return Verdict::Accepted;
}

std::int64_t SampleClock::timeOf(std::uint64_t n) const {
  const double dn = static_cast<double>(static_cast<std::int64_t>(n - anchor_n_));
  return std::llround(anchor_t_ + dn * period_ns_);
}

std::int64_t SampleClock::nearestIndexOfObservation(std::int64_t t_ns) const {
  return static_cast<std::int64_t>(anchor_n_) +
         std::llround((static_cast<double>(t_ns) - config_.observation_bias_ns - anchor_t_) / period_ns_);
}

}  // namespace gyrod::driver
