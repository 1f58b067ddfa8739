// The power-law noise type of each τ of an Allan table (Riley & Greenhall's lag-1 ACF
// method), and what it gives each deviation: its equivalent degrees of freedom and χ² interval
// (NIST SP 1065). Split from allan.cpp, which integrates the phase and forms the variances.
#include "processing/allan/allan_noise_type.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "processing/allan/allan.hpp"
#include "processing/allan/allan_kernels.hpp"
#include "processing/base/distributions.hpp"
#include "processing/base/parallel_share.hpp"

namespace gyrod::processing {
namespace {

using allan_detail::formatNumber;
using allan_detail::requireClusterSize;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

namespace allan_noise_type {

int clampAlpha(double alpha) { return static_cast<int>(std::clamp(std::round(alpha), -2.0, 2.0)); }

// Riley & Greenhall (2004), lag-1 ACF method for frequency data, dmax = 2: average the
// rate over m (non-overlapping), then difference d times until ρ = r1/(1 + r1) < 0.25;
// α = −2(ρ + d). The series is only mean-removed, not detrended: a rate ramp is a term of
// interest here and is classed with random-walk FM (α = −2).
// A level that is numerically constant (spread ≤ 1e-10 of the undifferenced spread:
// rounding only, e.g. the first difference of a pure ramp) has no correlation to measure;
// it is taken as ρ = 0, i.e. the series is a polynomial of degree d − 1, α = −2d (clamped).
int lag1NoiseIdOf(allan_kernels::AveragedSeries series, const double* data, double mean, double divisor, std::size_t n);

int lag1NoiseId(std::span<const double> rate, std::size_t m, double mean) {
  const std::size_t n = rate.size() / m;
  std::vector<double> z(n);
  // Four clusters at a time: four independent addition chains instead of one, each summing
  // its cluster in the same order as a cluster-by-cluster loop.
  const double md = static_cast<double>(m);
  std::size_t k = 0;
  for (; k + 4 <= n; k += 4) {
    const double* c = rate.data() + k * m;
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    for (std::size_t i = 0; i < m; ++i) {
      s0 += c[i] - mean;
      s1 += c[i + m] - mean;
      s2 += c[i + 2 * m] - mean;
      s3 += c[i + 3 * m] - mean;
    }
    z[k] = s0 / md;
    z[k + 1] = s1 / md;
    z[k + 2] = s2 / md;
    z[k + 3] = s3 / md;
  }
  for (; k < n; ++k) {
    double s = 0.0;
    for (std::size_t i = k * m; i < (k + 1) * m; ++i) s += rate[i] - mean;
    z[k] = s / md;
  }
  return lag1NoiseIdOf(allan_kernels::AveragedSeries::Sums, z.data(), 0.0, 1.0, n);  // z / 1.0 is z
}

// The lag-1 decision on the averaged series z(0 … n−1) (allan_kernels::AveragedSeries),
// read as often as needed (each difference level is formed on the fly, never stored).
int lag1NoiseIdOf(allan_kernels::AveragedSeries series, const double* data, double mean, double divisor,
                  std::size_t n) {
  constexpr int kMaxDifferences = 2;
  double level0_spread = -1.0;
  for (int d = 0;; ++d) {
    const std::size_t len = n - static_cast<std::size_t>(d);
    const allan_kernels::Lag1Correlation acf = allan_kernels::lag1OfDifference(series, data, mean, divisor, n, d);
    const double spread = std::sqrt(acf.sum_sq / static_cast<double>(len));
    if (level0_spread < 0.0) level0_spread = spread;
    if (spread <= 1e-10 * level0_spread) return clampAlpha(-2.0 * d);
    const double rho = acf.r1 / (1.0 + acf.r1);
    if (rho < 0.25 || d >= kMaxDifferences) return clampAlpha(-2.0 * (rho + d));
  }
}

// The lag-1 noise type at every m of a table, each distinct averaging computed once (every
// m too long for 30 averaged points uses the same one). The cluster sums of power-of-two
// averagings are formed pairwise from the level below, a different rounding from the
// one-by-one sum of lag1NoiseId (both within a few ε of the exact sum): the decision
// differs only for a ρ within ~10⁻¹⁵ of a rounding boundary of α. Empty for a series shorter than kMinAveragedPointsForNoiseId, whose fallback
// needs the phase. `mean` is checkedMean's, which has rejected any non-finite sample.
// `alongside`, when given, runs as one more task beside them (work that only reads the rate).
std::vector<int> noiseTypesForTable(std::span<const double> rate, std::span<const std::size_t> ms, double mean,
                                    const std::function<void()>& alongside) {
  const std::size_t count = rate.size();
  if (count < kMinAveragedPointsForNoiseId) {
    if (alongside) alongside();
    return {};
  }
  const auto averaging = [&](std::size_t m) {
    return count / m >= kMinAveragedPointsForNoiseId ? m : count / kMinAveragedPointsForNoiseId;
  };
  std::vector<std::size_t> distinct;
  for (std::size_t m : ms) distinct.push_back(averaging(m));
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  std::vector<int> distinct_alpha(distinct.size());
  // Powers of two: cluster sums by pairwise addition, level by level (2·count samples read
  // in all instead of count per averaging); the others averaged directly.
  const auto isPowerOfTwo = [](std::size_t m) { return (m & (m - 1)) == 0; };
  const std::size_t top = distinct.empty() ? 0 : distinct.back();
  const auto alphaAt = [&](std::size_t m) -> int* {
    const auto at = std::lower_bound(distinct.begin(), distinct.end(), m);
    return at != distinct.end() && *at == m ? &distinct_alpha[static_cast<std::size_t>(at - distinct.begin())]
                                            : nullptr;
  };
  // The cluster sums of m = 1, 2 and 4 are read from the rate when needed (the additions of
  // the pairwise cascade, the same bits: allan_kernels::AveragedSeries, four at a time there)
  // rather than held: a copy of the series would cost 8 bytes a sample while the phase is
  // also held (allanDeviationTable forms the two at once).
  const auto sum1 = [&](std::size_t i) { return rate[i] - mean; };
  const auto sum2 = [&](std::size_t k) { return sum1(2 * k) + sum1(2 * k + 1); };
  const auto firstLevel = [&] {
    if (int* alpha = top >= 1 ? alphaAt(1) : nullptr)
      *alpha = lag1NoiseIdOf(allan_kernels::AveragedSeries::Rate, rate.data(), mean, 1.0, count);
  };
  const auto secondLevel = [&] {
    if (int* alpha = top >= 2 ? alphaAt(2) : nullptr)
      *alpha = lag1NoiseIdOf(allan_kernels::AveragedSeries::Pairs, rate.data(), mean, 2.0, count / 2);
  };
  const auto levelsFromFour = [&] {
    const auto sum4 = [&](std::size_t k) { return sum2(2 * k) + sum2(2 * k + 1); };
    if (int* alpha = top >= 4 ? alphaAt(4) : nullptr)
      *alpha = lag1NoiseIdOf(allan_kernels::AveragedSeries::Quads, rate.data(), mean, 4.0, count / 4);
    if (top < 8) return;
    // From m = 8 on, level by level in one buffer of 1 byte a sample (not zeroed first: every
    // value is written before it is read): each level's averages are read as sum / m, and the
    // next level's sums then overwrite the front half of this one's (sums[k] is written after
    // sums[2k] and sums[2k + 1] are read).
    std::size_t level_size = count / 8;
    const auto sums = std::make_unique_for_overwrite<double[]>(std::max<std::size_t>(level_size, 1));
    for (std::size_t k = 0; k < level_size; ++k) sums[k] = sum4(2 * k) + sum4(2 * k + 1);
    for (std::size_t m = 8; m <= top; m *= 2) {
      if (int* alpha = alphaAt(m)) {
        const double md = static_cast<double>(m);
        *alpha = lag1NoiseIdOf(allan_kernels::AveragedSeries::Sums, sums.get(), 0.0, md, level_size);
      }
      level_size /= 2;
      for (std::size_t k = 0; k < level_size; ++k) sums[k] = sums[2 * k] + sums[2 * k + 1];
    }
  };
  // Tasks, about the longest first, taken in turn by both cores (each a few passes over the
  // rate; a correlated level, one that must be differenced, takes two more a difference):
  // m = 4 with the levels from 8 on, m = 1, the caller's work, m = 2, then the averagings that
  // are not powers of two. Each writes only its own types: the same bits for any thread count.
  std::vector<std::function<void()>> tasks = {levelsFromFour, firstLevel};
  if (alongside) tasks.emplace_back(alongside);
  tasks.emplace_back(secondLevel);
  for (std::size_t i = 0; i < distinct.size(); ++i)
    if (!isPowerOfTwo(distinct[i]))
      tasks.emplace_back([&, i] { distinct_alpha[i] = lag1NoiseId(rate, distinct[i], mean); });
  runTasksOnBothCores(std::span(tasks));
  std::vector<int> alphas;
  alphas.reserve(ms.size());
  for (std::size_t m : ms) {
    const auto at = std::lower_bound(distinct.begin(), distinct.end(), averaging(m));
    alphas.push_back(distinct_alpha[static_cast<std::size_t>(at - distinct.begin())]);
  }
  return alphas;
}

}  // namespace allan_noise_type

double overlappingAllanEdf(int alpha, std::size_t phase_points, std::size_t m) {
  requireClusterSize(m, "the Allan deviation's degrees of freedom");
  if (phase_points < 2 * m + 1) {
    throw std::invalid_argument("the Allan deviation's degrees of freedom need at least 2m + 1 phase points (N = " +
                                std::to_string(phase_points) + ", m = " + std::to_string(m) + ")");
  }
  const double N = static_cast<double>(phase_points);
  const double md = static_cast<double>(m);
  switch (alpha) {
    case 2:  // white PM
      return (N + 1.0) * (N - 2.0 * md) / (2.0 * (N - md));
    case 1:  // flicker PM
      return std::exp(std::sqrt(std::log((N - 1.0) / (2.0 * md)) * std::log((2.0 * md + 1.0) * (N - 1.0) / 4.0)));
    case 0:  // white FM
      return (3.0 * (N - 1.0) / (2.0 * md) - 2.0 * (N - 2.0) / N) * (4.0 * md * md / (4.0 * md * md + 5.0));
    case -1:  // flicker FM
      return m == 1 ? 2.0 * (N - 2.0) / (2.3 * N - 4.9) : 5.0 * N * N / (4.0 * md * (N + 3.0 * md));
    case -2: {  // random-walk FM; singular at N = 3 (one second difference): one degree of freedom
      if (phase_points == 3) return 1.0;
      const double n1 = N - 1.0;
      return (N - 2.0) / md * (n1 * n1 - 3.0 * md * n1 + 4.0 * md * md) / ((N - 3.0) * (N - 3.0));
    }
    default:
      throw std::invalid_argument(
          "the Allan deviation's degrees of freedom need a noise type alpha that is an integer in [-2, 2] (got " +
          std::to_string(alpha) + ")");
  }
}

DeviationInterval allanDeviationConfidenceInterval(double deviation, double edf, double confidence) {
  if (!(confidence > 0.0 && confidence < 1.0)) {
    throw std::invalid_argument("the Allan deviation's confidence interval needs a confidence in (0, 1) (got " +
                                formatNumber(confidence) + ")");
  }
  if (std::isnan(deviation)) return {kNaN, kNaN};
  if (!(std::isfinite(edf) && edf > 0.0)) {
    throw std::invalid_argument(
        "the Allan deviation's confidence interval needs degrees of freedom that are finite and > 0 (got " +
        formatNumber(edf) + ")");
  }
  // NIST SP 1065 eq. 45: σ²·edf/σ̂² ~ χ²(edf).
  return {deviation * std::sqrt(edf / chiSquareQuantile(0.5 * (1.0 + confidence), edf)),
          deviation * std::sqrt(edf / chiSquareQuantile(0.5 * (1.0 - confidence), edf))};
}

}  // namespace gyrod::processing
