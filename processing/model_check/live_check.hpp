#pragma once
// The live check: what is new on a running board against its own baseline (docs/live-check.md).
// gyrod hands it one interval of still samples at a time (data time; a few minutes); the
// first `baseline_s` of them become the board's baseline, and every later interval is
// compared with it:
//  - a line: the Hann periodogram of the last interval and of the last two, at every Fourier
//    bin, over the baseline's Welch level there (a bin over a Welch estimate of ν degrees of
//    freedom is F(2, ν), ν = 36K²/(19K − 1) for K Hann segments at 50 % overlap, Percival &
//    Walden eq. 292b). A whole-window periodogram, not a Welch average, because a weak steady
//    line gains power over the noise with every sample it spans (a line of amplitude 0.1 σ
//    stands 25 × the noise in 300 s at 50 Hz; Welch's 512-sample segments hold it at 1.9 ×).
//    A run of bins above the family threshold is a line, with its centre, width and rms, and
//    its onset from the power at its centre in 10 s blocks;
//  - an outlier burst: samples whose robust z against their neighbours (localOutlierScores)
//    exceeds kLiveOutlierZ, counted against the baseline's rate (Poisson);
//  - a bias step: in 10 s block means of the last two intervals, the difference of the means
//    s blocks after and s blocks before each block boundary of the window's middle, over
//    √2·σA(s), the board's own overlapping Allan deviation at that scale pooled over its still
//    data so far (Student's t with the pool's degrees of freedom: a young pool asks for more);
//  - a temperature coupling that is not the board's: when the temperature moved between the
//    last two intervals, their means' difference less what the known coupling explains, over
//    √2·σA(one interval), named when the temperature's shape fits the blocks better than any
//    one step does.
// Each detector's threshold is set from a false-alarm budget per board-week
// (LiveCheckSettings::false_alarms_per_week, shared by the detectors and the axes) and the
// number of intervals in a week. An effect is reported once when first named ("new") and
// once when an interval no longer shows it ("gone").
// Pure: no clock, no I/O; the caller supplies data time.
#include <array>
#include <cmath>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace gyrod::processing {

inline constexpr double kLiveOutlierZ = 8.0;
// The caller's rule for motion: a still detector's verdicts flicker at rest (on gyrod's mock,
// 2 % of the samples called moving, in stretches up to 0.5 s), so only a stretch of moving
// verdicts this long breaks the run of still data (the interval it falls in is left out);
// shorter ones stay in.
inline constexpr double kLiveMotionBreakS = 1.0;

// That rule, per sample at `rate_hz`: Keep a still sample or one of a short moving stretch,
// Break at the sample that makes the stretch kLiveMotionBreakS long (the run of still data
// ends), Skip the moving samples after it.
class LiveMotionRule {
 public:
  enum class Verdict { Keep, Break, Skip };
  explicit LiveMotionRule(double rate_hz);
  Verdict next(bool still);

 private:
  std::size_t moving_ = 0, limit_ = 1;
};
inline constexpr double kLiveLineGrowth = 2.0;

struct LiveCheckSettings {
  double rate_hz = 0.0;
  double interval_s = 300.0;   // one examination per interval of still data
  double baseline_s = 1800.0;  // the first still data, rounded up to whole intervals
  // Expected false EFFECT lines per week of clean data, all detectors and axes together.
  double false_alarms_per_week = 0.25;
  // The bias's temperature coupling the board is known to have, per axis (a model file's): the
  // check names a coupling that differs from it.
  std::array<double, 3> temperature_coefficient_dps_per_c{};
};

// The block of the step and coupling detectors, in seconds of data.
inline constexpr double kLiveBlockS = 10.0;
// The temperature must move at least this much between two intervals for the coupling to be
// judged (below it no slope can be told from the noise on a board's usual scale).
inline constexpr double kLiveMinTemperatureChangeC = 0.2;

enum class LiveEffectKind { Line, OutlierBurst, BiasStep, TemperatureBias };
// "line", "outlier_burst", "bias_step", "temperature_bias"
const char* liveEffectName(LiveEffectKind kind);

struct LiveInterval95 {
  double lo = 0.0, hi = 0.0;
};

struct LiveEffect {
  LiveEffectKind kind = LiveEffectKind::Line;
  std::size_t axis = 0;
  bool gone = false;  // false: newly named; true: no longer seen
  double t = 0.0;     // data time of the interval's end
  double onset_t = 0.0;
  LiveInterval95 onset_95;
  // Line: centre_hz, width_hz (the run of bins above the lower threshold, the window's own
  // spread of about two bins included), rms_dps (the power above the baseline's over that
  // run), power_ratio (interval/baseline at the peak bin).
  // Outlier burst: count, expected (the baseline's rate times the interval), largest_z.
  double centre_hz = 0.0, width_hz = 0.0, rms_dps = 0.0, power_ratio = 0.0;
  LiveInterval95 centre_hz_95, rms_dps_95;
  double baseline_rms_dps = 0.0;  // a line the baseline had, grown: its rms there (else 0)
  std::size_t count = 0;
  double expected = 0.0, largest_z = 0.0;
  // Bias step: size_dps (after − before) at the scale that showed it, scale_s (the data on
  // each side), z (size over √2·σA there).
  double size_dps = 0.0, scale_s = 0.0, z = 0.0;
  LiveInterval95 size_dps_95;
  // Temperature bias: the coupling now (regression of the blocks on temperature) and the one
  // the board was known to have, and the temperature change that showed it.
  double coefficient_dps_per_c = 0.0, baseline_coefficient_dps_per_c = 0.0, temperature_change_c = 0.0;
  LiveInterval95 coefficient_dps_per_c_95;
  std::string evidence;  // one sentence: the statistic against its threshold
};

class LiveCheck {
 public:
  // Throws std::invalid_argument naming the setting when a value is out of range (rate and
  // interval > 0, an interval of at least 8 segments of 64 samples, baseline ≥ interval,
  // budget > 0).
  explicit LiveCheck(const LiveCheckSettings& settings);

  // One interval: per axis the still samples (°/s) at the settings' rate, the interval's
  // data time [t0, t0 + n/rate). Intervals of other lengths are refused (returns nothing).
  // `temperature_c`: the die temperature at the same samples, or empty (then no coupling is
  // judged). Returns what changed: effects newly named and effects gone.
  std::vector<LiveEffect> examine(const std::array<std::span<const double>, 3>& axes,
                                  std::span<const double> temperature_c, double t0);
  std::vector<LiveEffect> examine(const std::array<std::vector<double>, 3>& axes, std::span<const double> temperature_c,
                                  double t0) {
    return examine(
        {std::span<const double>(axes[0]), std::span<const double>(axes[1]), std::span<const double>(axes[2])},
        temperature_c, t0);
  }
  std::vector<LiveEffect> examine(const std::array<std::vector<double>, 3>& axes, double t0) {
    return examine(axes, {}, t0);
  }

  bool baselineReady() const { return baseline_intervals_ >= baseline_needed_; }
  const std::vector<LiveEffect>& current() const { return current_; }
  std::size_t samplesPerInterval() const { return interval_samples_; }
  std::size_t segment() const { return segment_; }
  // The per-interval, per-axis false-alarm probability each detector runs at.
  double alphaPerTest() const { return alpha_; }

 private:
  // A line the board had all through its baseline (the chip's own, a fan that was running):
  // not new; named only when it grows past kLiveLineGrowth times its rms.
  struct BaselineLine {
    double centre_hz = 0.0, width_hz = 0.0, rms_dps = 0.0;
  };
  struct AxisBaseline {
    std::vector<double> power;  // summed Welch periodograms (bins 0..L/2)
    std::size_t segments = 0;
    // Welch's level per segment with the lines taken out: a running median over 9 bins.
    std::vector<double> background;
    std::vector<BaselineLine> lines;
    std::vector<std::vector<double>> intervals;  // the baseline's own (cleaned), until it is ready
    double outliers = 0.0, samples = 0.0;
  };
  // One axis's interval: outliers replaced by their neighbours' mean (for the spectrum), its
  // scores and its Welch power (mean over segments).
  struct AxisInterval {
    std::vector<double> cleaned, scores, power;
    std::size_t segments = 0;
  };

  AxisInterval prepare(std::span<const double> x) const;
  double baselineLevel(std::size_t axis, double f_hz, double sum_w2) const;
  // At the end of the baseline: its background, and the lines in its own intervals.
  void finishBaseline();
  const BaselineLine* baselineLine(std::size_t axis, const LiveEffect& e) const;
  // Lines in the periodogram of `window` (data time t0 at its first sample) at family alpha;
  // `earliest_t`: the start of the interval examined before the window (the earliest onset).
  std::vector<LiveEffect> findLines(std::size_t axis, std::span<const double> window, double t0, double earliest_t,
                                    double alpha) const;
  // `contiguous`: the interval before ended at t0 (its outliers may be the burst's start).
  std::optional<LiveEffect> findOutlierBurst(std::size_t axis, const AxisInterval& in, double t0,
                                             bool contiguous) const;
  // Whether an effect named before still shows in this interval (`both`: the last two
  // intervals, when contiguous).
  bool stillShows(const LiveEffect& e, const AxisInterval& in, const std::vector<double>* both) const;
  bool lineShowsIn(const LiveEffect& e, std::span<const double> x) const;
  double outlierRate(std::size_t axis) const;
  // The overlapping Allan variance of 10 s block means at each scale, pooled over the board's
  // contiguous still windows with nothing named in them: Σ d²/2, their number, and the degrees
  // of freedom they are worth.
  struct AllanPool {
    std::vector<double> sum_half_d2, terms, dof;
    // Whether scale i has a variance to judge by (a degree of freedom or more).
    bool ready(std::size_t i) const { return dof[i] >= 1.0 && sum_half_d2[i] > 0.0; }
    // The standard deviation of one difference at scale i: √2·σA.
    double differenceSd(std::size_t i) const { return std::sqrt(2.0 * sum_half_d2[i] / terms[i]); }
  };
  // The differences (after − before, s blocks each side) at the window's middle boundaries c
  // whose s blocks before start at `first` or later: (c, d) pairs.
  std::vector<std::pair<std::size_t, double>> middleDifferences(const std::vector<double>& y, std::size_t first,
                                                                std::size_t s) const;
  // Block means of a window `y` (2 intervals, corrected for the known coupling): adds its
  // differences at the window's middle boundaries to the pool; `first` the earliest block
  // that may be used (after a step named in the window).
  void addToPool(std::size_t axis, const std::vector<double>& y, std::size_t first);
  std::optional<LiveEffect> findStep(std::size_t axis, const std::vector<double>& y, std::size_t first,
                                     double window_t0) const;
  std::optional<LiveEffect> findCoupling(std::size_t axis, const std::vector<double>& y,
                                         const std::vector<double>& temp, double window_t0) const;
  // The step and coupling detectors' window: 10 s block means of the interval before and this
  // one, when contiguous (ok), and the temperature's when both intervals carry it; t0 is its start.
  struct LevelWindow {
    std::array<std::vector<double>, 3> y;
    std::vector<double> temp;
    double t0 = 0.0;
    bool ok = false;
  };
  LevelWindow levelWindow(const std::array<std::vector<double>, 3>& blocks, const std::vector<double>& temp_blocks,
                          bool contiguous) const;
  // The first block of a window starting at window_t0 after the last step named on the axis.
  std::size_t firstBlock(std::size_t axis, double window_t0) const;
  // The window's blocks of one axis less what a coupling k explains.
  static std::vector<double> corrected(const LevelWindow& w, std::size_t axis, double k);
  const LiveEffect* currentEffect(LiveEffectKind kind, std::size_t axis) const;
  // Couplings and steps on one axis of the window, appended to `found`.
  void findLevelChanges(std::size_t axis, const LevelWindow& w, std::vector<LiveEffect>& found);
  // Whether a named coupling still differs from the known one (false when the window shows
  // the known coupling again; true when the temperature did not move enough to tell).
  bool couplingStillShows(const LiveEffect& e, const std::vector<double>& y, const std::vector<double>& temp) const;
  double knownCoupling(std::size_t axis) const;

  LiveCheckSettings settings_;
  std::size_t interval_samples_ = 0, segment_ = 0;
  std::size_t baseline_needed_ = 0, baseline_intervals_ = 0;
  double alpha_ = 0.0;
  double segment_w2_ = 0.0;  // Σw² of the Welch segment's Hann window
  std::array<AxisBaseline, 3> baseline_;
  // The interval before (cleaned), for the two-interval window; its start, NaN when none.
  std::array<std::vector<double>, 3> previous_;
  double previous_t0_ = 0.0, before_previous_t0_ = 0.0;  // and the start of the one before it
  bool have_previous_ = false, have_before_previous_ = false;
  std::array<double, 3> previous_first_outlier_t_{};  // NaN: the interval before had none
  std::size_t block_ = 0, blocks_ = 0;                // samples per block, blocks per interval
  std::vector<std::size_t> scales_;                   // the step detector's scales, in blocks (1, 2, 4, …, blocks_)
  std::array<AllanPool, 3> pool_;
  // Block means of the interval before (cleaned), and of its temperature (empty: none).
  std::array<std::vector<double>, 3> previous_blocks_;
  std::vector<double> previous_temperature_blocks_;
  // The data time of the last step named per axis: no difference reaches back across it.
  std::array<double, 3> level_since_t_{};
  std::vector<LiveEffect> current_;
  // Effects said gone at the last two examinations: the two-interval window still holds the
  // interval before their end, and must not name them again from it.
  std::vector<LiveEffect> recently_gone_;
};

// Welch's power of x (Hann, 50 % overlap, each segment's mean removed), bins 0..seg/2, summed
// over segments; `segments` receives their number.
std::vector<double> welchPowerSum(std::span<const double> x, std::size_t seg, std::size_t* segments);
// P(F > f) for F ~ F(d1, d2), by Paulson's normal approximation (Abramowitz & Stegun 26.6.15).
double fUpperTail(double f, double d1, double d2);
// The f with fUpperTail(f, d1, d2) = p (bisection on ln f).
double fUpperQuantile(double p, double d1, double d2);

}  // namespace gyrod::processing
