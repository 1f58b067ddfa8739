#pragma once
// The sensor's sample clock, seen from CLOCK_MONOTONIC. The MPU6050 samples on its own
// oscillator, which is off by up to a few percent and drifts with temperature; the host
// sees it only through observations "sample n happened at time t" (a data-ready edge, or
// the time of a FIFO_COUNT read in polling mode). This model keeps a period estimate and
// an anchor (t_a, n_a), so that sample n is stamped t_a + (n − n_a)·P.
//
// As in the kernel's inv_sensors_timestamp: the period comes from observed intervals that
// pass a plausibility bound (|P/P_nominal − 1| ≤ max_clock_error), and each accepted
// observation pulls the anchor part of the way toward itself (easing) instead of jumping.
// The period is measured over a long baseline (first accepted observation since the last
// lock), refreshed every `baseline_window` samples from the eased anchor, so edge jitter
// averages out (error ≈ 2·jitter / span) while slow drift is still followed.
//
// Nothing here allocates; all arithmetic is on int64 ns and double.
#include <cstdint>

namespace gyrod::driver {

struct SampleClockConfig {
  double nominal_period_ns = 20e6;
  double max_clock_error = 0.10;  // plausible relative period error
  // How far (ns) an observation may be from the model and still be believed, once the
  // period is known. Edges: latency/jitter of the interrupt path; polling: half a period
  // plus margin, because the newest sample may be up to one period old.
  double observation_tolerance_ns = 5e6;
  // The observed time is this much later than the sample on average (0 for edges; half a
  // period for polling, where the newest sample is uniformly 0..P old).
  double observation_bias_ns = 0.0;
  double easing = 0.1;                    // fraction of the residual the anchor moves per observation
  int acquisition_observations = 8;       // after a lock, anchor hard on this many observations
  int rejections_before_relock = 4;       // consecutive implausible observations → hard re-anchor
  std::uint64_t baseline_window = 30000;  // samples; the period baseline is renewed after this
};

class SampleClock {
 public:
  enum class Verdict { Locked, Accepted, Rejected, Relocked };

  // Throws std::invalid_argument for a non-positive period or tolerance, easing outside
  // (0, 1], max_clock_error outside (0, 0.5), or counts below 1.
  explicit SampleClock(const SampleClockConfig& config);

  // Sample n (in the caller's sequence numbering) became available at t_ns (before the
  // bias correction). The first observation, and one after breakPhase(), locks the phase.
  Verdict observe(std::int64_t t_ns, std::uint64_t n);

  // Locks the phase from a rough placement (e.g. a read time when no edge is available):
  // timestamps follow it, but it is never a period baseline, and the next observe()
  // re-locks on its observation instead of refining this one.
  void lockApproximately(std::int64_t t_ns, std::uint64_t n);

  // Forget the phase (the chip restarted sampling); the period estimate is kept, since
  // it is the same oscillator.
  void breakPhase();
  bool locked() const { return locked_; }

  // Model time of sample n (requires locked()).
  std::int64_t timeOf(std::uint64_t n) const;
  // The sample index whose model time is nearest to an observation made at t_ns (the
  // bias is removed first, as in observe()). Requires locked(); signed, since it may lie
  // before index 0 in a caller's numbering.
  std::int64_t nearestIndexOfObservation(std::int64_t t_ns) const;

  double periodNs() const { return period_ns_; }
  // Relative uncertainty of periodNs() (max_clock_error until measured).
  double periodUncertainty() const { return period_uncertainty_; }
  std::uint64_t rejections() const { return rejections_total_; }
  std::uint64_t relocks() const { return relocks_; }

 private:
  void lock(double t, std::uint64_t n);
  bool plausiblePeriod(double p) const;

  SampleClockConfig config_;
  bool locked_ = false;
  bool approximate_ = false;
  double period_ns_;
  double period_uncertainty_;
  double anchor_t_ = 0.0;
  std::uint64_t anchor_n_ = 0;
  double baseline_t_ = 0.0;
  std::uint64_t baseline_n_ = 0;
  int observations_since_lock_ = 0;
  int consecutive_rejections_ = 0;
  std::uint64_t rejections_total_ = 0;
  std::uint64_t relocks_ = 0;
};

}  // namespace gyrod::driver
