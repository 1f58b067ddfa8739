#pragma once
// The paper's tests on the raw static series (section 3.2.1), each with its verdict at
// the 5 % level.
#include <cstddef>
#include <span>

namespace gyrod::processing {

struct ZeroMeanTest {
  double mean = 0.0;
  double standard_deviation = 0.0;
  double z = 0.0;          // mean / (sd/√n)
  bool zero_mean = false;  // |z| < 1.96
};
ZeroMeanTest zeroMeanTest(std::span<const double> x);

// Reverse-arrangements test (Bendat & Piersol, Random Data, §4.5.2): the series is cut
// into `segments` equal segments; A counts pairs i<j with v_i > v_j of the segment mean
// squares... (see .cpp for the exact statistic); u = (A − μ_A)/σ_A with
// μ_A = N(N−1)/4, σ_A² = N(2N+5)(N−1)/72; stationary if |u| < 1.96.
struct ReverseArrangementsTest {
  std::size_t segments = 0;
  double arrangements = 0.0;  // A
  double u = 0.0;
  bool stationary = false;
};
ReverseArrangementsTest reverseArrangementsTest(std::span<const double> x, std::size_t segments = 100);

// χ² goodness-of-fit against a normal with the sample's mean and sd: `bins` equiprobable
// classes (0 = choose from n), dof = bins − 3, normal if χ² < χ²₀.₉₅(dof).
struct ChiSquareNormalityTest {
  double chi2 = 0.0;
  std::size_t dof = 0;
  double critical = 0.0;
  double p_value = 0.0;
  bool normal = false;
};
ChiSquareNormalityTest chiSquareNormalityTest(std::span<const double> x, std::size_t bins = 0);

}  // namespace gyrod::processing
