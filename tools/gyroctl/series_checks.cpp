#include "tools/gyroctl/series_checks.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace gyrod::gyroctl {
namespace {

const char* lostKindName(recording::LostSamples::Kind kind) {
  return kind == recording::LostSamples::Kind::Gap ? "GAP" : "DROPPED";
}

std::string nominalText(const processing::SampleTimingReport& t) {
  return t.nominal_given ? "1 / --rate" : "the median of the first intervals";
}

nlohmann::json intervalJson(const std::optional<processing::TimingInterval>& interval) {
  if (!interval) return nullptr;
  return {{"dt_s", interval->dt_s}, {"start_t_s", interval->start_t_s}, {"line", interval->line}};
}

// The first offending interval or record, as "FILE:LINE: cause" for --strict-timing.
std::string firstOffence(const std::string& path, const TimingSummary& timing) {
  const auto& t = timing.t;
  const auto& interval = t.first_offending;
  std::ostringstream s;
  s.precision(10);
  if (interval && !(timing.first_lost && timing.first_lost->line < interval->line)) {
    s << path << ':' << interval->line << ": irregular timing (--strict-timing): ";
    if (interval->dt_s > t.limits.gap_factor * t.nominal_dt_s)
      s << "a gap of " << interval->dt_s << " s after t = " << interval->start_t_s << " s (over " << t.limits.gap_factor
        << " x the nominal spacing " << t.nominal_dt_s << " s)";
    else
      s << "t = " << interval->start_t_s + interval->dt_s << " s comes " << interval->dt_s
        << " s after the previous sample, off the nominal spacing " << t.nominal_dt_s << " s by more than "
        << 100.0 * t.limits.jitter_tolerance << " %";
  } else {
    const auto& lost = *timing.first_lost;
    s << path << ':' << lost.line << ": irregular timing (--strict-timing): a '# " << lostKindName(lost.kind)
      << "' record: " << lost.count << " sample" << (lost.count == 1 ? "" : "s") << " lost (" << lost.reason << ")";
  }
  return s.str();
}

}  // namespace

void requireAnalysableValues(const recording::Recording& rec, std::size_t axis_index) {
  const auto& values = rec.axes[axis_index];
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (std::abs(values[i]) <= kLargestAnalysableRateDps) continue;
    std::ostringstream s;
    s << rec.path << ':' << rec.lineOfSample(i) << ": column '" << rec.axis_names[axis_index] << "': " << values[i]
      << " deg/s is beyond " << kLargestAnalysableRateDps
      << " deg/s, more than any gyro measures (the statistics would overflow)";
    throw recording::RecordingError(s.str());
  }
}

TimingSummary checkTiming(const recording::Recording& rec, std::optional<double> rate_hz) {
  if (rec.t.empty()) return summarizeTiming(std::nullopt, rec.lost);
  processing::SampleTimingCheck check(rate_hz ? std::optional<double>(1.0 / *rate_hz) : std::nullopt);
  check.addTimes(rec.t, [&rec](std::size_t i) { return rec.lineOfSample(i); });
  return summarizeTiming(check.report(), rec.lost);
}

TimingSummary summarizeTiming(const std::optional<processing::SampleTimingReport>& t_report,
                              const std::vector<recording::LostSamples>& lost) {
  TimingSummary summary;
  summary.has_t = t_report.has_value();
  if (t_report) summary.t = *t_report;
  summary.lost_records = lost.size();
  for (const auto& record : lost) summary.lost_samples += record.count;
  if (!lost.empty()) summary.first_lost = lost.front();
  return summary;
}

void reportTiming(const std::string& path, const TimingSummary& timing, bool strict) {
  if (timing.regular()) return;
  if (strict) throw recording::RecordingError(firstOffence(path, timing));
  const auto& t = timing.t;
  const char* head = "gyroctl: warning: ";
  if (t.gaps > 0) {
    const auto& g = *t.largest_gap;
    std::fprintf(stderr,
                 "%s%s: %zu gap%s in column 't' (intervals over %g x the nominal %g s): the largest %g s after "
                 "t = %g s (line %zu); about %llu samples missing\n",
                 head, path.c_str(), t.gaps, t.gaps == 1 ? "" : "s", t.limits.gap_factor, t.nominal_dt_s, g.dt_s,
                 g.start_t_s, g.line, static_cast<unsigned long long>(t.missing_samples));
  }
  if (t.irregular > 0) {
    const auto& f = *t.first_offending;
    std::fprintf(stderr,
                 "%s%s: %zu of %zu intervals in column 't' off the nominal %g s (%s) by more than %g %%: "
                 "largest |dt - nominal| %g s, rms %g s; the first offending interval ends at line %zu\n",
                 head, path.c_str(), t.irregular, t.samples - 1, t.nominal_dt_s, nominalText(t).c_str(),
                 100.0 * t.limits.jitter_tolerance, t.max_jitter_s, t.rms_jitter_s, f.line);
  }
  if (timing.lost_records > 0)
    std::fprintf(stderr, "%s%s: %zu '# GAP'/'# DROPPED' record%s, %llu samples lost in all; the first at line %zu\n",
                 head, path.c_str(), timing.lost_records, timing.lost_records == 1 ? "" : "s",
                 static_cast<unsigned long long>(timing.lost_samples), timing.first_lost->line);
  std::fprintf(stderr,
               "%s%s: the statistics assume equally spaced samples with none missing; --strict-timing makes "
               "this an error\n",
               head, path.c_str());
}

nlohmann::json timingJson(const TimingSummary& timing) {
  const auto& t = timing.t;
  nlohmann::json j;
  j["regular"] = timing.regular();
  j["t_column"] = timing.has_t;
  j["nominal_dt_s"] = timing.has_t && t.nominal_dt_s > 0.0 ? nlohmann::json(t.nominal_dt_s) : nlohmann::json();
  j["nominal_from"] = t.nominal_given ? "rate" : "median";
  j["gap_factor"] = t.limits.gap_factor;
  j["jitter_tolerance"] = t.limits.jitter_tolerance;
  j["intervals"] = t.samples > 0 ? t.samples - 1 : 0;
  j["gaps"] = t.gaps;
  j["missing_samples"] = t.missing_samples;
  j["largest_gap"] = intervalJson(t.largest_gap);
  j["irregular_intervals"] = t.irregular;
  j["max_jitter_s"] = t.max_jitter_s;
  j["rms_jitter_s"] = t.rms_jitter_s;
  j["first_offending"] = intervalJson(t.first_offending);
  j["lost_records"] = timing.lost_records;
  j["lost_samples"] = timing.lost_samples;
  if (timing.first_lost)
    j["first_lost_record"] = {
        {"kind", timing.first_lost->kind == recording::LostSamples::Kind::Gap ? "gap" : "dropped"},
        {"count", timing.first_lost->count},
        {"reason", timing.first_lost->reason},
        {"line", timing.first_lost->line}};
  else
    j["first_lost_record"] = nullptr;
  return j;
}

}  // namespace gyrod::gyroctl
