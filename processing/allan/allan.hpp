#pragma once
// Allan deviation of a rate series (gyro rate in °/s, or fractional frequency).
// Conventions of NIST SP 1065 (Riley 2008), which the NBS14 reference values assume:
// M rate samples integrate to M+1 phase points (x₀ = 0); the overlapping estimator at
// averaging factor m uses M − 2m + 1 second differences; the non-overlapping one uses
// ⌊M/m⌋ cluster means and ⌊M/m⌋ − 1 differences (paper eqs. 1–2).
// Both are computed from the integrated phase of the mean-removed series (the variance is
// blind to a constant), kept as a double-double running sum, in O(M) per m.
// Non-finite rate samples are rejected with std::invalid_argument; m = 0 likewise.
#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "processing/allan/allan_kernels.hpp"

namespace gyrod::processing {

// ---- cluster sizes (averaging factors m, τ = m·τ0) --------------------------------
// m = 1, 2, 4, ... while the overlapping estimator keeps at least one term (2m ≤ M).
std::vector<std::size_t> octaveClusterSizes(std::size_t sample_count);
// Log-spaced m, `per_decade` points per decade, unique, same upper bound as octave.
std::vector<std::size_t> denseClusterSizes(std::size_t sample_count, std::size_t per_decade = 10);
// Explicit τ list in seconds → m = τ/τ0. Throws std::invalid_argument naming the τ when
// a τ is not a whole number of samples (relative tolerance 1e-9) or too long for the data.
std::vector<std::size_t> clusterSizesForTaus(std::span<const double> taus_s, double tau0_s, std::size_t sample_count);

// ---- estimators (σ², not σ; rate in any unit, result in unit²) ---------------------
// Non-overlapping Allan variance at averaging factor m (paper eq. 2). NaN if < 2 clusters.
double allanVariance(std::span<const double> rate, std::size_t m);
// Overlapping Allan variance at averaging factor m. NaN if M − 2m + 1 < 1.
double overlappingAllanVariance(std::span<const double> rate, std::size_t m);
// The same for several m, integrating the phase once (NaN where M − 2m + 1 < 1).
std::vector<double> overlappingAllanVariances(std::span<const double> rate, std::span<const std::size_t> ms);

// Fewer averaged points than this and the lag-1 method is not trusted (Riley & Greenhall).
inline constexpr std::size_t kMinAveragedPointsForNoiseId = 30;

// Noise type per NIST SP 1065 power-law exponent α of the rate PSD S(f) ∝ f^α:
// 2 white PM, 1 flicker PM, 0 white FM, −1 flicker FM, −2 random-walk FM. For a gyro:
// quantization ≈ white PM (α=2), ARW = white FM (0), bias instability = flicker FM
// (−1), RRW = random-walk FM (−2); a rate ramp is treated as random-walk FM.
// Identified by the lag-1 autocorrelation method (Riley & Greenhall 2004) on the series
// averaged over m (mean removed, not detrended, d ≤ 2); returns α rounded to an integer in
// [−2, 2]. When ⌊M/m⌋ < kMinAveragedPointsForNoiseId the method is applied at the longest
// m that still has enough points (m = ⌊M/30⌋); for M < 30 the local slope μ of the
// overlapping Allan variance gives α = −μ − 1 (clamped to [−2, 1]). Needs M ≥ 3.
int identifyPowerLawNoise(std::span<const double> rate, std::size_t m);

// Equivalent degrees of freedom of the overlapping Allan variance (NIST SP 1065 §5.2.x,
// simple approximations by noise type, Table 5). N = number of *phase* points = M + 1.
// Requires N ≥ 2m + 1 and α ∈ [−2, 2] (else std::invalid_argument). Approximations meant
// for N ≫ m; the RW FM one is singular at N = 3, where 1 is returned.
double overlappingAllanEdf(int alpha, std::size_t phase_points, std::size_t m);

struct AllanPoint {
  double tau_s = 0.0;
  std::size_t m = 0;
  double adev = 0.0;            // non-overlapping (NaN when fewer than 2 clusters)
  std::size_t adev_terms = 0;   // ⌊M/m⌋ − 1
  double oadev = 0.0;           // overlapping
  std::size_t oadev_terms = 0;  // M − 2m + 1
  int noise_alpha = 0;          // identified power-law exponent at this τ
  double edf = 0.0;             // equivalent degrees of freedom of oadev (NaN when oadev is)
  double oadev_lo = 0.0;        // χ² confidence interval of oadev (NaN when oadev is):
  double oadev_hi = 0.0;        // σ̂·√(edf/χ²_{(1±c)/2}(edf)), NIST SP 1065 eq. 45
};

// χ² confidence interval of a deviation estimate σ̂ with `edf` equivalent degrees of freedom
// at two-sided confidence c (NIST SP 1065 eq. 45: σ²·edf/σ̂² ~ χ²(edf)):
// [σ̂·√(edf/χ²_{(1+c)/2}(edf)), σ̂·√(edf/χ²_{(1−c)/2}(edf))]. NaN σ̂ gives NaN bounds.
// Throws std::invalid_argument for c outside (0, 1) or edf not finite and > 0 (σ̂ finite).
struct DeviationInterval {
  double lo = 0.0;
  double hi = 0.0;
};
DeviationInterval allanDeviationConfidenceInterval(double deviation, double edf, double confidence);

struct AllanOptions {
  double confidence = 0.683;  // two-sided, "1 σ" as is usual for Allan plots
};

// Both estimators, noise identification, edf and χ² bounds, for each m in `ms` (any order;
// m too long for an estimator gives NaN there). Throws std::invalid_argument for tau0 ≤ 0,
// confidence outside (0, 1), m = 0, fewer than 3 samples or a non-finite sample.
std::vector<AllanPoint> allanDeviationTable(std::span<const double> rate, double tau0_s,
                                            std::span<const std::size_t> ms, const AllanOptions& options = {});

// Storage for the phase of a series of up to `capacity` samples (12 bytes a sample), for
// several tables in turn: a long analysis then allocates it, and the kernel clears its
// pages, once instead of for every table. Between tables, rateSlots() (the phase's storage
// from its second point on, `capacity` doubles) may hold the next series to analyse, which
// allanDeviationTableInPlace integrates where it lies.
class AllanWorkspace {
 public:
  explicit AllanWorkspace(std::size_t capacity);
  // The phase's high parts (8 of the 12 bytes a sample) in `reused`'s memory when it can hold
  // capacity + 1 doubles (its values are lost), else in storage of their own: a column the
  // caller no longer needs (a recording's time) then serves, its pages already present.
  AllanWorkspace(std::size_t capacity, std::vector<double>&& reused);
  std::size_t capacity() const { return capacity_; }
  std::span<double> rateSlots() { return {hi_ + 1, capacity_}; }
  double* phaseHi() { return hi_; }
  float* phaseLo() { return lo_.get(); }

 private:
  std::size_t capacity_;
  std::vector<double> reused_hi_;                 // the high parts, when in a reused column
  allan_kernels::PhaseStorage<double> owned_hi_;  // else here
  double* hi_;
  allan_kernels::PhaseStorage<float> lo_;
};

// allanDeviationTable with the phase in `workspace` (rate.size() ≤ its capacity; the rate
// must not lie in it): the same table, the same bits.
std::vector<AllanPoint> allanDeviationTable(std::span<const double> rate, double tau0_s,
                                            std::span<const std::size_t> ms, const AllanOptions& options,
                                            AllanWorkspace& workspace);
// overlappingAllanVariances with the phase in `workspace` (the rate not in it): the same bits.
std::vector<double> overlappingAllanVariances(std::span<const double> rate, std::span<const std::size_t> ms,
                                              AllanWorkspace& workspace);
// The table of the first `count` samples of workspace.rateSlots(), the same bits as
// allanDeviationTable of a copy of them; the samples become the phase (they are lost).
// `alongside`, when given, runs once on one of the cores that identify the noise types, before
// the samples become the phase: work of the caller's that only reads them (their spread, say)
// fills the time those tasks leave a core idle.
std::vector<AllanPoint> allanDeviationTableInPlace(AllanWorkspace& workspace, std::size_t count, double tau0_s,
                                                   std::span<const std::size_t> ms, const AllanOptions& options = {},
                                                   const std::function<void()>& alongside = {});

}  // namespace gyrod::processing
