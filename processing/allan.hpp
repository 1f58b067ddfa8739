#pragma once
// Allan deviation of a rate series (gyro rate in °/s, or fractional frequency).
// Conventions of NIST SP 1065 (Riley 2008), which the NBS14 reference values assume:
// M rate samples integrate to M+1 phase points (x₀ = 0); the overlapping estimator at
// averaging factor m uses M − 2m + 1 second differences; the non-overlapping one uses
// ⌊M/m⌋ cluster means and ⌊M/m⌋ − 1 differences (paper eqs. 1–2).
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace gyrod::processing {

// ---- cluster sizes (averaging factors m, τ = m·τ0) --------------------------------
// m = 1, 2, 4, ... while the overlapping estimator keeps at least one term (2m ≤ M).
std::vector<std::size_t> octaveClusterSizes(std::size_t sample_count);
// Log-spaced m, `per_decade` points per decade, unique, same upper bound as octave.
std::vector<std::size_t> denseClusterSizes(std::size_t sample_count, std::size_t per_decade = 10);
// Explicit τ list in seconds → m = τ/τ0. Throws std::invalid_argument naming the τ when
// a τ is not a whole number of samples (relative tolerance 1e-9) or too long for the data.
std::vector<std::size_t> clusterSizesForTaus(std::span<const double> taus_s, double tau0_s,
                                             std::size_t sample_count);

// ---- estimators (σ², not σ; rate in any unit, result in unit²) ---------------------
// Non-overlapping Allan variance at averaging factor m (paper eq. 2). NaN if < 2 clusters.
double allanVariance(std::span<const double> rate, std::size_t m);
// Overlapping Allan variance at averaging factor m. NaN if M − 2m + 1 < 1.
double overlappingAllanVariance(std::span<const double> rate, std::size_t m);

// Noise type per NIST SP 1065 power-law exponent α of the rate PSD S(f) ∝ f^α:
// 2 white PM, 1 flicker PM, 0 white FM, −1 flicker FM, −2 random-walk FM. For a gyro:
// quantization ≈ white PM (α=2), ARW = white FM (0), bias instability = flicker FM
// (−1), RRW = random-walk FM (−2); a rate ramp is treated as random-walk FM.
// Identified by the lag-1 autocorrelation method (Riley & Greenhall 2004) on the series
// averaged over m; returns α rounded to an integer in [−2, 2].
int identifyPowerLawNoise(std::span<const double> rate, std::size_t m);

// Equivalent degrees of freedom of the overlapping Allan variance (NIST SP 1065 §5.2.x,
// simple approximations by noise type). N = number of *phase* points = M + 1.
double overlappingAllanEdf(int alpha, std::size_t phase_points, std::size_t m);

struct AllanPoint {
  double tau_s = 0.0;
  std::size_t m = 0;
  double adev = 0.0;            // non-overlapping (NaN when fewer than 2 clusters)
  std::size_t adev_terms = 0;   // ⌊M/m⌋ − 1
  double oadev = 0.0;           // overlapping
  std::size_t oadev_terms = 0;  // M − 2m + 1
  int noise_alpha = 0;          // identified power-law exponent at this τ
  double edf = 0.0;             // equivalent degrees of freedom of oadev
  double oadev_lo = 0.0;        // χ² confidence interval of oadev
  double oadev_hi = 0.0;
};

struct AllanOptions {
  double confidence = 0.683;  // two-sided, "1 σ" as is usual for Allan plots
};

// Both estimators, noise identification, edf and χ² bounds, for each m in `ms`.
std::vector<AllanPoint> allanDeviationTable(std::span<const double> rate, double tau0_s,
                                            std::span<const std::size_t> ms,
                                            const AllanOptions& options = {});

}  // namespace gyrod::processing
