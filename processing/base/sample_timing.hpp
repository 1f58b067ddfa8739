#pragma once
// Are a series' sample times regular? A streaming check fed one time at a time (O(1) memory,
// O(1) work per sample), so a reader can run it while parsing, whatever it keeps of the samples.
//
// Definitions (README "Gaps and irregular timing" states them for the user):
//   nominal spacing τ0   the spacing the caller gives (gyroctl: 1 / --rate), else the median of
//                        the first kNominalIntervals intervals (of all of them when fewer came);
//                        only positive intervals count for that median
//   gap                  an interval dt > gap_factor · τ0 (1.5: half a sample late is a missing
//                        sample, as model-check's sample_gaps counts it); it hides about
//                        round(dt / τ0) − 1 samples
//   jitter               |dt − τ0| of every interval that is not a gap
//   irregular interval   an interval that is not a gap and whose jitter exceeds
//                        jitter_tolerance · τ0 (10 %), or that is not positive (time standing
//                        still or going back)
// Allan statistics assume equally spaced samples: a series with a gap or an irregular interval
// is analysed as if it had none, and its figures are off by an amount the statistics cannot say.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>

namespace gyrod::processing {

struct SampleTimingLimits {
  double gap_factor = 1.5;
  double jitter_tolerance = 0.1;
};

// Intervals whose median makes the nominal spacing when the caller gives none.
inline constexpr std::size_t kNominalIntervals = 64;

// One interval of the series: from the sample at start_t_s to the next one, which is the
// index-th sample fed (0-based) and came with `line`.
struct TimingInterval {
  double start_t_s = 0.0;
  double dt_s = 0.0;
  std::size_t index = 0;
  std::size_t line = 0;
};

struct SampleTimingReport {
  std::size_t samples = 0;     // times fed
  double nominal_dt_s = 0.0;   // τ0; 0 with fewer than two samples (nothing to judge)
  bool nominal_given = false;  // τ0 came from the caller, not from the median
  SampleTimingLimits limits;
  std::size_t gaps = 0;
  std::uint64_t missing_samples = 0;  // Σ round(dt / τ0) − 1 over the gaps
  std::optional<TimingInterval> largest_gap;
  std::size_t irregular = 0;
  double max_jitter_s = 0.0;  // over the intervals that are not gaps
  double rms_jitter_s = 0.0;
  // The first gap or irregular interval in the order fed; nullopt when the series is regular.
  std::optional<TimingInterval> first_offending;
  bool regular() const { return gaps == 0 && irregular == 0; }
};

class SampleTimingCheck {
 public:
  // nominal_dt_s: τ0 when the caller knows it (must be finite and > 0); nullopt: the median
  // of the first kNominalIntervals intervals.
  explicit SampleTimingCheck(std::optional<double> nominal_dt_s = std::nullopt, SampleTimingLimits limits = {});

  // The next sample's time (s) and, for the report, its line in the file (0: none).
  void add(double t_s, std::size_t line = 0);
  // The same as add(t[i], line_of(i)) for each i in order (the same report, bit for bit), in
  // one tight loop: line_of is asked only for the intervals the report keeps or that settle τ0.
  void addTimes(std::span<const double> t, const std::function<std::size_t(std::size_t)>& line_of);

  // What the times fed so far show; may be called at any point (fewer than kNominalIntervals
  // intervals and no τ0 given: the median of those there are).
  SampleTimingReport report() const;

 private:
  void settleNominal();
  void classify(double start_t_s, double t_s, std::size_t line);

  SampleTimingReport report_;
  bool settled_ = false;
  double sum_squared_jitter_ = 0.0;
  std::size_t jitter_intervals_ = 0;
  double last_t_s_ = 0.0;
  // The first times and lines, kept until τ0 is known.
  std::array<double, kNominalIntervals + 1> pending_t_s_{};
  std::array<std::size_t, kNominalIntervals + 1> pending_line_{};
  std::size_t pending_ = 0;
};

}  // namespace gyrod::processing
