// allan_kernels::lag1OfDifference against the definition written out plainly: the averaged
// series formed point by point, differenced d times, its mean and the two sums in four lanes
// (lane j the values 4q + j) added as (0 + 1) + (2 + 3), the tails serially. The kernel forms
// four points at once (AVX2 where the machine has it); it must give these bits exactly, for
// every series, every d ≤ 2 and lengths that leave every tail.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <random>
#include <tuple>
#include <vector>

#include "processing/allan/allan_kernels.hpp"

using namespace gyrod::processing::allan_kernels;

namespace {

std::vector<double> averaged(AveragedSeries series, const std::vector<double>& data, double mean, double divisor,
                             std::size_t len) {
  std::vector<double> z(len);
  const auto s1 = [&](std::size_t i) { return data[i] - mean; };
  const auto s2 = [&](std::size_t k) { return s1(2 * k) + s1(2 * k + 1); };
  for (std::size_t k = 0; k < len; ++k) {
    switch (series) {
      case AveragedSeries::Rate: z[k] = s1(k); break;
      case AveragedSeries::Pairs: z[k] = s2(k) / 2.0; break;
      case AveragedSeries::Quads: z[k] = (s2(2 * k) + s2(2 * k + 1)) / 4.0; break;
      case AveragedSeries::Sums: z[k] = data[k] / divisor; break;
    }
  }
  return z;
}

Lag1Correlation plainLag1(std::vector<double> z, int d) {
  for (int r = 0; r < d; ++r) {
    for (std::size_t i = 0; i + 1 < z.size(); ++i) z[i] = z[i + 1] - z[i];
    z.pop_back();
  }
  const std::size_t n = z.size();
  double lanes[4] = {0.0, 0.0, 0.0, 0.0};
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4)
    for (std::size_t j = 0; j < 4; ++j) lanes[j] += z[i + j];
  double mean = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
  for (; i < n; ++i) mean += z[i];
  mean /= static_cast<double>(n);
  double num_lanes[4] = {0.0, 0.0, 0.0, 0.0}, den_lanes[4] = {0.0, 0.0, 0.0, 0.0};
  for (i = 0; i + 4 < n; i += 4)
    for (std::size_t j = 0; j < 4; ++j) {
      den_lanes[j] += (z[i + j] - mean) * (z[i + j] - mean);
      num_lanes[j] += (z[i + j] - mean) * (z[i + j + 1] - mean);
    }
  double num = (num_lanes[0] + num_lanes[1]) + (num_lanes[2] + num_lanes[3]);
  double den = (den_lanes[0] + den_lanes[1]) + (den_lanes[2] + den_lanes[3]);
  for (; i < n; ++i) {
    den += (z[i] - mean) * (z[i] - mean);
    if (i + 1 < n) num += (z[i] - mean) * (z[i + 1] - mean);
  }
  return {den > 0.0 ? num / den : 0.0, den};
}

}  // namespace

TEST(Lag1Kernel, EverySeriesAndDifferenceIsTheDefinitionBitForBit) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> white(0.0, 1.0);
  for (std::size_t count : {37u, 64u, 101u, 1000u, 4099u}) {
    std::vector<double> data(count);
    double walk = 0.0;
    for (double& v : data) {
      walk += 0.05 * white(rng);
      v = 3.0 + walk + white(rng);  // correlated enough to need differences at long averagings
    }
    const double mean = 3.1;
    for (const auto& [series, divisor, len] :
         {std::tuple{AveragedSeries::Rate, 1.0, count}, std::tuple{AveragedSeries::Pairs, 2.0, count / 2},
          std::tuple{AveragedSeries::Quads, 4.0, count / 4}, std::tuple{AveragedSeries::Sums, 8.0, count}}) {
      const std::vector<double> z = averaged(series, data, mean, divisor, len);
      for (int d = 0; d <= 2; ++d) {
        const Lag1Correlation want = plainLag1(z, d);
        const Lag1Correlation got = lag1OfDifference(series, data.data(), mean, divisor, len, d);
        EXPECT_EQ(std::bit_cast<std::uint64_t>(got.r1), std::bit_cast<std::uint64_t>(want.r1))
            << "series " << static_cast<int>(series) << ", " << count << " samples, d = " << d;
        EXPECT_EQ(std::bit_cast<std::uint64_t>(got.sum_sq), std::bit_cast<std::uint64_t>(want.sum_sq))
            << "series " << static_cast<int>(series) << ", " << count << " samples, d = " << d;
      }
    }
  }
}
