#pragma once
// Checks of a loaded recording that analyze, filter and model-check share: values the
// statistics can carry and the series' timing (gaps, jitter, the GAP and DROPPED records).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "formats/recording_csv.hpp"
#include "processing/base/sample_timing.hpp"

namespace gyrod::gyroctl {

// Far beyond any gyro's range (the MPU-6050 tops out at 2000 °/s), and far enough below the
// largest double that sums of squares over any recording stay finite.
inline constexpr double kLargestAnalysableRateDps = 1e12;

// Throws RecordingError naming FILE:LINE and the column for a value beyond kLargestAnalysableRateDps.
void requireAnalysableValues(const recording::Recording& rec, std::size_t axis_index);

// The timing of a recording: its t column through processing::SampleTimingCheck and its
// "# GAP" / "# DROPPED" records.
struct TimingSummary {
  bool has_t = false;
  processing::SampleTimingReport t;
  std::size_t lost_records = 0;
  std::uint64_t lost_samples = 0;                    // the records' counts summed
  std::optional<recording::LostSamples> first_lost;  // the first record in the file
  bool regular() const { return t.regular() && lost_records == 0; }
};

// rate_hz: --rate when given (then τ0 = 1 / rate), else τ0 is the median of the first intervals.
TimingSummary checkTiming(const recording::Recording& rec, std::optional<double> rate_hz);
// The same from a SampleTimingCheck a reader fed while parsing (t_report: nullopt without a t
// column), with the recording's GAP and DROPPED records.
TimingSummary summarizeTiming(const std::optional<processing::SampleTimingReport>& t_report,
                              const std::vector<recording::LostSamples>& lost);

// Irregular timing: with strict, throws RecordingError "FILE:LINE: ..." naming the first
// offending interval or record; otherwise writes the warning lines to stderr. Silent when regular.
void reportTiming(const std::string& path, const TimingSummary& timing, bool strict);

// The "timing" object of --json (README "Gaps and irregular timing" lists its fields).
nlohmann::json timingJson(const TimingSummary& timing);

}  // namespace gyrod::gyroctl
