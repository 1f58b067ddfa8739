#include "processing/portable_random.hpp"

#include <cmath>
#include <stdexcept>

#include "processing/portable_math.hpp"

namespace gyrod::processing {
namespace {
constexpr std::uint64_t rotateLeft(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
}  // namespace

std::uint64_t SplitMix64::next() {
  std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

Xoshiro256StarStar::Xoshiro256StarStar(std::uint64_t seed) {
  SplitMix64 seeder(seed);
  for (auto& word : s_) word = seeder.next();
}

Xoshiro256StarStar::Xoshiro256StarStar(SplitMix64& seeder) {
  for (auto& word : s_) word = seeder.next();
}

Xoshiro256StarStar::Xoshiro256StarStar(const std::array<std::uint64_t, 4>& state) : s_(state) {
  if (s_[0] == 0 && s_[1] == 0 && s_[2] == 0 && s_[3] == 0)
    throw std::invalid_argument("xoshiro256** state must not be all zero");
}

std::uint64_t Xoshiro256StarStar::next() {
  const std::uint64_t result = rotateLeft(s_[1] * 5, 7) * 9;
  const std::uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = rotateLeft(s_[3], 45);
  return result;
}

double Xoshiro256StarStar::uniform() {
  return static_cast<double>(next() >> 11) * 0x1.0p-53;
}

double NormalGenerator::next() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double v1 = 0.0, v2 = 0.0, s = 0.0;
  do {
    v1 = 2.0 * uniform_.uniform() - 1.0;  // exact: a 53-bit grid on [−1, 1)
    v2 = 2.0 * uniform_.uniform() - 1.0;
    s = v1 * v1 + v2 * v2;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * portable::log(s) / s);
  spare_ = v2 * factor;
  has_spare_ = true;
  return v1 * factor;
}

}  // namespace gyrod::processing
