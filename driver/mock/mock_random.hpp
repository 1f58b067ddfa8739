#pragma once
// The mock's random numbers come from the project's splitmix64 (processing/
// portable_random.hpp): uniform doubles from its top 53 bits, normals by Box–Muller.
// Seeded, so a mock run is reproducible from its config.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>

#include "processing/base/portable_random.hpp"

namespace gyrod::driver::mock {

// Uniform on [0, 1): (next() >> 11)·2^−53.
inline double uniform01(processing::SplitMix64& rng) { return static_cast<double>(rng.next() >> 11) * 0x1.0p-53; }

// Standard normal deviates by Box–Muller, two per pair of uniforms (the second is kept for
// the next call).
class BoxMullerNormal {
 public:
  explicit BoxMullerNormal(std::uint64_t seed) : rng_(seed) {}
  double next() {
    if (spare_) {
      const double v = *spare_;
      spare_.reset();
      return v;
    }
    const double u1 = 1.0 - uniform01(rng_);  // (0, 1]
    const double u2 = uniform01(rng_);
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * std::numbers::pi * u2);
    return r * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  processing::SplitMix64 rng_;
  std::optional<double> spare_;
};

}  // namespace gyrod::driver::mock
