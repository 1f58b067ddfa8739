#include "daemon/live_checker.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "daemon/config.hpp"
#include "protocol/effect_line.hpp"

namespace gyrod::daemon {
namespace {

std::string g4(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// One journal line: "live check: new line on y: 12.5 Hz, rms 0.0026 deg/s, onset 3600 s (...)".
std::string journalLine(const processing::LiveEffect& e) {
  std::string s = std::string("live check: ") + (e.gone ? "gone: " : "new ") + processing::liveEffectName(e.kind) +
                  " on " + "xyz"[e.axis % 3];
  if (e.kind == processing::LiveEffectKind::Line) s += (e.gone ? " at " : ": ") + g4(e.centre_hz) + " Hz";
  if (e.gone) return s + " (data time " + g4(e.t) + " s)";
  if (e.kind == processing::LiveEffectKind::Line)
    s += ", rms " + g4(e.rms_dps) + " deg/s" +
         (e.baseline_rms_dps > 0.0 ? " (the baseline had " + g4(e.baseline_rms_dps) + ")" : "");
  else if (e.kind == processing::LiveEffectKind::OutlierBurst)
    s += ": " + std::to_string(e.count) + " outliers where " + g4(e.expected) + " were expected";
  else if (e.kind == processing::LiveEffectKind::BiasStep)
    s += ": " + g4(e.size_dps) + " deg/s (" + g4(e.size_dps_95.lo) + " to " + g4(e.size_dps_95.hi) + ")";
  else
    s += ": " + g4(e.coefficient_dps_per_c) + " deg/s per C (" + g4(e.coefficient_dps_per_c_95.lo) + " to " +
         g4(e.coefficient_dps_per_c_95.hi) + ") where the model has " + g4(e.baseline_coefficient_dps_per_c);
  return s + ", onset " + g4(e.onset_t) + " s (" + g4(e.onset_95.lo) + "-" + g4(e.onset_95.hi) + "); " + e.evidence;
}

bool sameEffect(const processing::LiveEffect& a, const processing::LiveEffect& b) {
  return a.kind == b.kind && a.axis == b.axis && a.centre_hz == b.centre_hz && a.onset_t == b.onset_t;
}

}  // namespace

LiveChecker::LiveChecker(EventLoop& loop, double device_rate_hz, double interval_s, double baseline_s,
                         double false_alarms_per_week, const std::array<double, 3>& temperature_coefficient_dps_per_c,
                         OnChange on_change)
    : motion_(device_rate_hz),
      on_change_(std::move(on_change)),
      job_(
          loop, [this](std::vector<processing::LiveEffect>&& changes) { applyChanges(std::move(changes)); },
          [this](const std::string& why) {
            spdlog::warn("live check: an examination failed ({}); the interval is left out", why);
            for (auto& x : *examined_) x.clear();
          }) {
  decimation_ = static_cast<std::size_t>(std::ceil(device_rate_hz / kLiveCheckMaxRateHz - 1e-9));
  decimation_ = std::max<std::size_t>(1, decimation_);
  analysis_rate_hz_ = device_rate_hz / static_cast<double>(decimation_);
  processing::LiveCheckSettings s;
  s.rate_hz = analysis_rate_hz_;
  s.interval_s = interval_s;
  s.baseline_s = baseline_s;
  s.false_alarms_per_week = false_alarms_per_week;
  s.temperature_coefficient_dps_per_c = temperature_coefficient_dps_per_c;
  check_ = std::make_shared<processing::LiveCheck>(s);
  interval_samples_ = check_->samplesPerInterval();
  examined_ = std::make_shared<IntervalData>();
  for (auto& x : filling_) x.reserve(interval_samples_);
  for (auto& x : *examined_) x.reserve(interval_samples_);
}

void LiveChecker::breakRun() {
  for (auto& x : filling_) x.clear();
  sum_ = {};
  summed_ = 0;
  run_samples_ = 0;
}

void LiveChecker::onSample(double t_s, const std::array<double, 3>& rate_dps, double temperature_c, bool still) {
  const auto verdict = motion_.next(still);
  if (verdict != processing::LiveMotionRule::Verdict::Keep) {
    if (verdict == processing::LiveMotionRule::Verdict::Break) breakRun();
    return;
  }
  if (summed_ == 0) block_start_t_ = t_s;
  for (std::size_t a = 0; a < 3; ++a) sum_[a] += rate_dps[a];
  sum_[3] += temperature_c;
  if (++summed_ < decimation_) return;
  if (run_samples_ == 0) run_start_t_ = block_start_t_;
  for (std::size_t a = 0; a < 4; ++a) filling_[a].push_back(sum_[a] / static_cast<double>(decimation_));
  sum_ = {};
  summed_ = 0;
  ++run_samples_;
  if (filling_[0].size() >= interval_samples_) examine();
}

void LiveChecker::examine() {
  const double t0 = run_start_t_ + static_cast<double>(run_samples_ - interval_samples_) / analysis_rate_hz_;
  if (job_.running()) {  // the last one is still at work: this interval is left out
    ++skipped_;
    for (auto& x : filling_) x.clear();
    return;
  }
  std::swap(filling_, *examined_);  // no allocation: the buffers trade places
  ++intervals_;
  try {
    job_.start([check = check_, data = examined_, t0] {
      const IntervalData& d = *data;
      return check->examine(
          {std::span<const double>(d[0]), std::span<const double>(d[1]), std::span<const double>(d[2])}, d[3], t0);
    });
  } catch (const std::exception& e) {
    spdlog::warn("live check: cannot start an examination ({}); the interval is left out", e.what());
    for (auto& x : *examined_) x.clear();
  }
}

void LiveChecker::applyChanges(std::vector<processing::LiveEffect>&& changes) {
  for (auto& x : *examined_) x.clear();
  if (!baseline_ready_ && check_->baselineReady()) {  // the examination is over: the check is the loop's
    baseline_ready_ = true;
    spdlog::info(
        "live check: the baseline is complete ({} intervals of still data); later intervals are compared "
        "with it",
        intervals_);
  }
  for (const processing::LiveEffect& e : changes) {
    if (e.gone) {
      std::erase_if(current_, [&e](const processing::LiveEffect& c) { return sameEffect(c, e); });
    } else {
      current_.push_back(e);
      ++named_;
    }
    spdlog::warn("{}", journalLine(e));
    if (on_change_) on_change_(e);
  }
}

protocol::LiveCheckStatus LiveChecker::status() const {
  protocol::LiveCheckStatus s;
  s.intervals = intervals_;
  s.baseline_ready = baseline_ready_;
  s.named = named_;
  s.skipped = skipped_;
  for (const processing::LiveEffect& e : current_) s.current.push_back(protocol::effectJson(e).dump());
  return s;
}

}  // namespace gyrod::daemon
