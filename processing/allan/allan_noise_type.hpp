#pragma once
// Inside the Allan statistics (not for the layers above, which call allan.hpp): the lag-1
// noise identification that allan.cpp's tables and identifyPowerLawNoise share, and the
// two files' message helpers.
#include <cstddef>
#include <functional>
#include <iomanip>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace gyrod::processing::allan_detail {

// A value as the messages of the Allan statistics quote it.
inline std::string formatNumber(double v) {
  std::ostringstream os;
  os << std::setprecision(12) << v;
  return os.str();
}

inline void requireClusterSize(std::size_t m, const char* where) {
  if (m == 0) throw std::invalid_argument(std::string(where) + " needs an averaging factor m of at least 1 (got 0)");
}

}  // namespace gyrod::processing::allan_detail

namespace gyrod::processing::allan_noise_type {

// The power-law noise type α ∈ [−2, 2] at averaging m by the lag-1 ACF method, for a series
// of at least m · kMinAveragedPointsForNoiseId finite samples whose mean is `mean`.
int lag1NoiseId(std::span<const double> rate, std::size_t m, double mean);

// The lag-1 noise type at every m of a table, each distinct averaging computed once (every
// m too long for 30 averaged points uses the same one). Empty for a series shorter than
// kMinAveragedPointsForNoiseId. `alongside`, when given, runs as one more task beside them.
std::vector<int> noiseTypesForTable(std::span<const double> rate, std::span<const std::size_t> ms, double mean,
                                    const std::function<void()>& alongside = {});

}  // namespace gyrod::processing::allan_noise_type
