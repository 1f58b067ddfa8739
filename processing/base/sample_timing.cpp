#include "processing/base/sample_timing.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gyrod::processing {

SampleTimingCheck::SampleTimingCheck(std::optional<double> nominal_dt_s, SampleTimingLimits limits) {
  if (!(limits.gap_factor > 1.0 && std::isfinite(limits.gap_factor)) ||
      !(limits.jitter_tolerance > 0.0 && limits.jitter_tolerance < limits.gap_factor - 1.0))
    throw std::invalid_argument(
        "the sample timing check needs a gap factor > 1 and a jitter tolerance between 0 and the gap factor - 1");
  report_.limits = limits;
  if (nominal_dt_s) {
    if (!(std::isfinite(*nominal_dt_s) && *nominal_dt_s > 0.0))
      throw std::invalid_argument("the sample timing check needs a nominal sample interval that is finite and > 0");
    report_.nominal_dt_s = *nominal_dt_s;
    report_.nominal_given = true;
    settled_ = true;
  }
}

void SampleTimingCheck::add(double t_s, std::size_t line) {
  ++report_.samples;
  if (!settled_) {
    pending_t_s_[pending_] = t_s;
    pending_line_[pending_] = line;
    if (++pending_ == pending_t_s_.size()) settleNominal();
    return;
  }
  if (report_.samples > 1) classify(last_t_s_, t_s, line);
  last_t_s_ = t_s;
}

void SampleTimingCheck::addTimes(std::span<const double> t, const std::function<std::size_t(std::size_t)>& line_of) {
  std::size_t i = 0;
  for (; i < t.size() && (!settled_ || report_.samples == 0); ++i) add(t[i], line_of(i));
  if (i == t.size()) return;
  // An interval that is neither a gap nor irregular only adds to the jitter: done here, in
  // the same order and with the same expressions as classify(), which takes every other one.
  const double nominal = report_.nominal_dt_s;
  const double gap_limit = report_.limits.gap_factor * nominal;
  const double jitter_limit = report_.limits.jitter_tolerance * nominal;
  double last = last_t_s_, max_jitter = report_.max_jitter_s, sum_squared = sum_squared_jitter_;
  std::size_t regular = 0;
  for (; i < t.size(); ++i) {
    const double dt = t[i] - last;
    const double jitter = std::abs(dt - nominal);
    if (!(nominal > 0.0 && dt > gap_limit) && dt > 0.0 && jitter <= jitter_limit) {
      max_jitter = std::max(max_jitter, jitter);
      sum_squared += jitter * jitter;
      ++regular;
    } else {
      report_.samples += regular;
      jitter_intervals_ += regular;
      regular = 0;
      report_.max_jitter_s = max_jitter;
      sum_squared_jitter_ = sum_squared;
      ++report_.samples;
      classify(last, t[i], line_of(i));
      max_jitter = report_.max_jitter_s;
      sum_squared = sum_squared_jitter_;
    }
    last = t[i];
  }
  report_.samples += regular;
  jitter_intervals_ += regular;
  report_.max_jitter_s = max_jitter;
  sum_squared_jitter_ = sum_squared;
  last_t_s_ = last;
}

void SampleTimingCheck::settleNominal() {
  settled_ = true;
  std::array<double, kNominalIntervals> positive{};
  std::size_t count = 0;
  for (std::size_t i = 1; i < pending_; ++i) {
    const double dt = pending_t_s_[i] - pending_t_s_[i - 1];
    if (dt > 0.0 && std::isfinite(dt)) positive[count++] = dt;
  }
  if (count > 0) {
    const auto mid = positive.begin() + static_cast<std::ptrdiff_t>(count / 2);
    std::nth_element(positive.begin(), mid, positive.begin() + static_cast<std::ptrdiff_t>(count));
    report_.nominal_dt_s = *mid;
  }
  // The kept samples are classified now, in the order they came.
  const std::size_t samples = report_.samples;
  report_.samples = samples - pending_;
  for (std::size_t i = 0; i < pending_; ++i) {
    ++report_.samples;
    if (i > 0) classify(pending_t_s_[i - 1], pending_t_s_[i], pending_line_[i]);
  }
  if (pending_ > 0) last_t_s_ = pending_t_s_[pending_ - 1];
  pending_ = 0;
}

void SampleTimingCheck::classify(double start_t_s, double t_s, std::size_t line) {
  const double nominal = report_.nominal_dt_s;
  const double dt = t_s - start_t_s;
  const TimingInterval interval{start_t_s, dt, report_.samples - 1, line};
  bool offending = false;
  if (nominal > 0.0 && dt > report_.limits.gap_factor * nominal) {
    ++report_.gaps;
    const double missing = std::round(dt / nominal) - 1.0;
    // Clamped so that an absurd gap (t jumping by 1e30 s) cannot overflow the conversion.
    report_.missing_samples += static_cast<std::uint64_t>(std::clamp(missing, 0.0, 1e18));
    if (!report_.largest_gap || dt > report_.largest_gap->dt_s) report_.largest_gap = interval;
    offending = true;
  } else {
    const double jitter = std::abs(dt - nominal);
    if (std::isfinite(jitter)) {
      report_.max_jitter_s = std::max(report_.max_jitter_s, jitter);
      sum_squared_jitter_ += jitter * jitter;
      ++jitter_intervals_;
    }
    if (!(dt > 0.0) || !(jitter <= report_.limits.jitter_tolerance * nominal)) {
      ++report_.irregular;
      offending = true;
    }
  }
  if (offending && !report_.first_offending) report_.first_offending = interval;
}

SampleTimingReport SampleTimingCheck::report() const {
  if (!settled_) {
    SampleTimingCheck settled = *this;
    settled.settleNominal();
    return settled.report();
  }
  SampleTimingReport r = report_;
  if (jitter_intervals_ > 0) r.rms_jitter_s = std::sqrt(sum_squared_jitter_ / static_cast<double>(jitter_intervals_));
  return r;
}

}  // namespace gyrod::processing
