#pragma once
// The paper's tests on the raw static series (section 3.2.1), each with its verdict at
// the 5 % level.
#include <cstddef>
#include <span>

namespace gyrod::processing {

// Zero-mean test: z = mean / (s/√n) with s the sample standard deviation (n − 1);
// the mean is taken as zero at 5 % when |z| < 1.96. Throws for fewer than 2 samples or
// non-finite samples.
struct ZeroMeanTest {
  double mean = 0.0;
  double standard_deviation = 0.0;
  double z = 0.0;          // mean / (sd/√n)
  bool zero_mean = false;  // |z| < 1.96
};
ZeroMeanTest zeroMeanTest(std::span<const double> x);

// Reverse-arrangements test (Bendat & Piersol, Random Data, §4.5.2): the series is cut
// into `segments` equal segments (a trailing remainder of size mod segments is not used);
// each segment gives one value v_i (see SegmentStatistic); A counts pairs i<j with
// v_i > v_j; u = (A − μ_A)/σ_A with μ_A = N(N−1)/4, σ_A² = N(2N+5)(N−1)/72;
// stationary if |u| < 1.96.
// Throws for segments < kMinReverseArrangementsSegments, x.size() < segments or
// non-finite samples.
inline constexpr std::size_t kMinReverseArrangementsSegments = 10;
enum class SegmentStatistic {
  // Mean square of the segment about the mean of the whole series (the default; see the
  // .cpp for why): segment variance + (segment mean − overall mean)². Sees a monotone
  // trend in the variance, and a change of the mean that is not symmetric about the
  // middle of the record; a pure linear ramp in the mean gives a symmetric U-shaped
  // profile with A ≈ μ_A, which this statistic cannot see: use Mean for that.
  MeanSquareAboutMean,
  // Segment mean: a monotone trend in the mean.
  Mean,
};
struct ReverseArrangementsTest {
  std::size_t segments = 0;
  double arrangements = 0.0;       // A
  double mean_arrangements = 0.0;  // μ_A
  double sd_arrangements = 0.0;    // σ_A
  double u = 0.0;
  bool stationary = false;
};
ReverseArrangementsTest reverseArrangementsTest(std::span<const double> x, std::size_t segments = 100,
                                                SegmentStatistic statistic = SegmentStatistic::MeanSquareAboutMean);

// The same test applied directly to a sequence of N ≥ kMinReverseArrangementsSegments
// values (e.g. mean squares computed elsewhere): N = v.size().
ReverseArrangementsTest reverseArrangementsTestOfSequence(std::span<const double> v);

// A = #{(i, j): i < j, v_i > v_j}, the number of reverse arrangements (ties do not count).
std::size_t countReverseArrangements(std::span<const double> v);

// χ² goodness-of-fit against a normal with the sample's mean and (maximum-likelihood) sd:
// `bins` equiprobable classes, dof = bins − 3, normal if χ² < χ²₀.₉₅(dof).
// bins = 0 chooses round(2·n^(2/5)) (Moore's rule for equiprobable classes), bounded to
// [5, 100] and to at most n/5 so every expected count is ≥ 5.
// Throws for fewer than 25 samples, an explicit bins < 4 or > n/5, zero variance or
// non-finite samples.
struct ChiSquareNormalityTest {
  std::size_t bins = 0;
  double chi2 = 0.0;
  std::size_t dof = 0;
  double critical = 0.0;
  double p_value = 0.0;
  bool normal = false;
};
ChiSquareNormalityTest chiSquareNormalityTest(std::span<const double> x, std::size_t bins = 0);

}  // namespace gyrod::processing
