#pragma once
// Streaming overlapping Allan variance, as the daemon keeps it per stream at the sample rate:
// over a sliding window of the last W samples and, separately, over everything since start.
//
// Conventions of NIST SP 1065, as the batch overlappingAllanVariance (allan.hpp): M rate
// samples are M + 1 phase points x₀ = 0, x_{k+1} = x_k + y_k; at averaging factor m the
// estimator is σ²(mτ₀) = Σ_j d_j² / (2 m² (M − 2m + 1)) over the M − 2m + 1 second
// differences d_j = x_{j+2m} − 2x_{j+m} + x_j. The numbers equal the batch estimator on the
// same samples to rounding (≤ 2e-14 relative in the tests), at every push, for any run
// length:
//  - Phase: a ring of the last W + 1 phase points of (y − y_first), held as a double-double
//    (hi + lo) running sum. Subtracting the first sample removes a constant bias; the
//    double-double keeps the absolute error of x at ~2⁻¹⁰⁴·|x|, so even a phase that grows
//    without bound (a bias that moves away from the first sample: 1000 °/s for a week at
//    50 Hz gives |x| ≈ 3·10¹⁰) leaves second differences accurate to ~10⁻²¹ — far below any
//    gyro quantum. d_j is formed from exact differences of the hi parts, so a large
//    residual offset does not cancel away digits. No re-anchoring is needed, and none is
//    done: it would change stored points and break the exact removal below.
//  - Sums that cannot drift: for each m the squares d_j² are added into (and, when their
//    term leaves the window, subtracted from) an exact fixed-point accumulator that spans
//    the whole double range (a Kulisch accumulator, 68 limbs of 32 bits). A term leaving
//    the window is recomputed from the same stored phase points by the same code (which
//    has no multiplication that FP contraction could fuse differently), so it is the same
//    double that was added, and it is removed exactly: the window sum is at every
//    moment exactly Σ of the (rounded) d_j² of the terms in the window, with no memory of
//    terms that left and no error growing with the number of updates. The since-start sum
//    is a second accumulator that only adds.
//  - Since start: the term d_j needs x_j … x_{j+2m}, which the window ring holds for every
//    m ≤ W/2, so the since-start overlapping variance is exact (same as batch on the whole
//    history) for every configured m — all of which are ≤ W/2 — in bounded memory.
//
// Cost: push() is O(number of m), allocates nothing (the ring and accumulators are sized
// at construction) and throws only on bad input. Memory is fixed at construction and does
// not grow with run time: kBytesPerWindowSample = 16 bytes per sample of window (a 1 h
// window at 50 Hz, W = 180 000: 2.9 MB) plus kBytesPerClusterSize ≈ 1.1 kB per m; see
// stateBytes(). A week-long run uses exactly what an hour uses.
//
// snapshot() turns the sums into AllanPoints with noise type, edf and χ² bounds; it
// reconstructs the window's rates from the phase ring (allocates, O(W) per m) to identify
// the noise type by the lag-1 method, so call it at a display rate, not per sample.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "processing/allan/allan.hpp"

namespace gyrod::processing {

// Exact sum of non-negative finite doubles with exact removal of a value added before:
// fixed-point over the whole double range, bit 0 = 2⁻¹⁰⁷⁴ (the least subnormal), 68 digits
// of 32 bits (2176 bits: up to 2¹¹⁰² — any 2⁶⁴ doubles below 2¹⁰²⁴ fit). add/subtract are
// exact integer operations, so any sequence of them leaves exactly the sum of the values
// added and not yet subtracted; value() rounds that to double (relative error ≤ 2⁻⁵²).
// Each operation touches three digits and propagates no carry: the digits are int64 and
// could absorb 2³⁰ operations (each moves a digit by < 2³³); carries are propagated every
// 2¹⁶ (68 digit steps, negligible per operation) and on reading.
class ExactNonNegativeSum {
 public:
  static constexpr std::size_t kLimbs = 68;

  // A value split into the three 32-bit digits it occupies, so that one value can go into
  // several sums for the price of one split.
  struct Digits {
    std::size_t limb = 0;  // index of the lowest digit
    std::array<std::int64_t, 3> digit{};
  };
  // v must be finite and ≥ 0 (checked by the caller; not re-checked per sample).
  static Digits digitsOf(double v);

  void add(const Digits& v) { addScaled(v, 1); }
  // v must have been added before and not yet subtracted, so the sum stays ≥ 0.
  void subtract(const Digits& v) { addScaled(v, -1); }
  void add(double v) { add(digitsOf(v)); }
  void subtract(double v) { subtract(digitsOf(v)); }
  double value() const;
  void clear() {
    limbs_.fill(0);
    pending_ = 0;
  }

 private:
  static constexpr std::uint32_t kOperationsBetweenCarries = std::uint32_t{1} << 16;
  void addScaled(const Digits& v, std::int64_t sign) {
    limbs_[v.limb] += sign * v.digit[0];
    limbs_[v.limb + 1] += sign * v.digit[1];
    limbs_[v.limb + 2] += sign * v.digit[2];
    if (++pending_ == kOperationsBetweenCarries) propagateCarries();
  }
  void propagateCarries();
  // Σ limbs_[k]·2^(32k − 1074); a digit may lie outside [0, 2³²) until carries are propagated.
  std::array<std::int64_t, kLimbs> limbs_{};
  std::uint32_t pending_ = 0;  // operations since the last carry propagation
};

// Overlapping Allan variance over a sliding window of the last `window_samples` rate samples
// and since start, at averaging factors m (τ = m·τ₀). One instance per stream.
class RollingOverlappingAllan {
 public:
  // A rate sample's magnitude must not exceed this: it keeps phase, second differences and
  // their squares finite for any run length up to 2⁶⁴ samples (a gyro reads ≤ 2000 °/s).
  static constexpr double kMaxAbsRate = 1e100;
  static constexpr std::size_t kBytesPerWindowSample = 16;  // one double-double phase point
  static constexpr std::size_t kBytesPerClusterSize = 2 * sizeof(ExactNonNegativeSum) + sizeof(std::size_t);

  // Octave factors m = 1, 2, 4, … ≤ window_samples / 2 (the largest with a term in a full
  // window). Throws std::invalid_argument if window_samples < 2.
  explicit RollingOverlappingAllan(std::size_t window_samples);
  // Explicit factors: strictly increasing, each m ≥ 1 and 2m ≤ window_samples (else
  // std::invalid_argument naming the offending m); at least one.
  RollingOverlappingAllan(std::size_t window_samples, std::span<const std::size_t> cluster_sizes);

  // One rate sample. O(cluster sizes), no allocation. Throws std::invalid_argument (state
  // unchanged) for a non-finite sample or |rate| > kMaxAbsRate.
  void push(double rate);
  // Back to the freshly constructed state (same window and m), keeping the memory.
  void reset();

  std::size_t windowCapacity() const { return window_capacity_; }
  // Samples now in the window: min(total, capacity).
  std::size_t windowCount() const;
  std::uint64_t totalCount() const { return total_count_; }
  std::span<const std::size_t> clusterSizes() const { return cluster_sizes_; }

  // Overlapping Allan variance (σ², unit²) of the window / since start at clusterSizes()[index],
  // NaN while it has no term (fewer than 2m samples); O(1) (reads one accumulator).
  // Throws std::out_of_range for a bad index.
  double windowVariance(std::size_t index) const;
  double sinceStartVariance(std::size_t index) const;
  // Number of second differences behind it: count − 2m + 1, or 0.
  std::size_t windowTerms(std::size_t index) const;
  std::uint64_t sinceStartTerms(std::size_t index) const;

  // Bytes held by this object (members and heap), constant from construction on.
  std::size_t stateBytes() const;

  struct Snapshot {
    std::vector<AllanPoint> window;
    std::vector<AllanPoint> since_start;
  };
  // AllanPoints (tau_s, m, oadev, oadev_terms, noise_alpha, edf, oadev_lo/hi) for every
  // configured m, window and since start, as allanDeviationTable fills them: the noise type
  // by identifyPowerLawNoise on the window's rates (reconstructed from the phase ring), edf
  // by overlappingAllanEdf, bounds by allanDeviationConfidenceInterval. Since-start points
  // use the noise type identified on the window (the recent W samples stand for the sensor's
  // noise at that τ; the whole history is not kept) with N = total + 1 phase points.
  // The non-overlapping estimator is not kept: adev = NaN, adev_terms = 0.
  // While the window holds fewer than 4 samples the noise type cannot be identified
  // (identifyPowerLawNoise's slope method needs two factors m ≤ M/2): noise_alpha = 0 and
  // edf, oadev_lo, oadev_hi are NaN. edf and bounds are NaN where oadev is.
  // Throws std::invalid_argument for τ₀ not finite and > 0 or confidence outside (0, 1).
  Snapshot snapshot(double tau0_s, const AllanOptions& options = {}) const;

  // Copying in steps: this object becomes `source` as it was at beginCopyFrom, copied over
  // several calls while `source` goes on taking samples, so that no single call copies the
  // whole window (58 MB at one hour of 1 kHz). beginCopyFrom takes the small state (sums,
  // counts, the newest point's slot); each continueCopyFrom copies at most `points` phase
  // points of the ring, oldest first. A push overwrites the source's oldest point, which the
  // copy has taken by then while it stays ahead of the pushes; the result is then bit for bit
  // the source at beginCopyFrom. Overrun: the source overwrote a point not yet copied, or was
  // reset; begin again. Throws std::invalid_argument when `source` has another window or
  // other cluster sizes, and std::logic_error when no copy was begun from it.
  enum class CopyStep { Copying, Done, Overrun };
  void beginCopyFrom(const RollingOverlappingAllan& source);
  CopyStep continueCopyFrom(const RollingOverlappingAllan& source, std::size_t points);

 private:
  struct PhasePoint {  // x = hi + lo, unevaluated
    double hi = 0.0;
    double lo = 0.0;
  };
  // Ring slot of the phase point `back` places before the newest one (back ≤ capacity).
  std::size_t slotBack(std::size_t back) const { return head_ >= back ? head_ - back : head_ + ring_.size() - back; }
  // d = x_{j+2m} − 2x_{j+m} + x_j with x_{j+2m} `back` places before the newest phase
  // point, in double-double, rounded once. Deterministic: the same stored points give the
  // same double, which is what lets the window sum remove a leaving term exactly.
  double secondDifference(std::size_t back, std::size_t m) const;
  void requireIndex(std::size_t index, const char* where) const;

  std::size_t window_capacity_;
  std::vector<std::size_t> cluster_sizes_;
  std::vector<ExactNonNegativeSum> window_sums_;
  std::vector<ExactNonNegativeSum> since_start_sums_;
  std::vector<PhasePoint> ring_;  // window_capacity_ + 1 phase points
  std::size_t head_ = 0;          // slot of the newest phase point, x_total
  std::uint64_t total_count_ = 0;
  double reference_ = 0.0;  // the first sample, subtracted from every sample
  std::uint64_t resets_ = 0;
  // A copy in steps: the source's resets_ at its beginning, and the ring points copied so far
  // (counted from the oldest at the beginning).
  std::optional<std::uint64_t> copy_source_resets_;
  std::size_t copy_next_ = 0;
};

}  // namespace gyrod::processing
