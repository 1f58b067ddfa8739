#pragma once
// Random numbers that are the same bits on every machine: the simulator's stream must
// be reproducible from its seed on x86_64 and aarch64 alike. The C++ <random> engines
// are portable but its distributions are implementation-defined, so the generator and
// the normal deviate are written here: xoshiro256** 1.0 (Blackman & Vigna 2018) seeded
// through splitmix64 (Steele, Lea & Flood 2014) as its authors recommend, uniform
// doubles from the top 53 bits, and normals by Marsaglia's polar method, which needs only
// + − × ÷, sqrt and a logarithm (portable::log). Compiled with -ffp-contract=off.
#include <array>
#include <cstdint>

namespace gyrod::processing {

// splitmix64: a 64-bit counter passed through a bijective mixer. Used to expand a seed.
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next();

 private:
  std::uint64_t state_;
};

// xoshiro256** 1.0. Period 2^256 − 1; the all-zero state is invalid and never produced
// by seeding from splitmix64 (its four outputs would all have to be zero).
class Xoshiro256StarStar {
 public:
  // State = the next four outputs of SplitMix64(seed).
  explicit Xoshiro256StarStar(std::uint64_t seed);
  // State given directly (for reference test vectors). Throws on all-zero.
  explicit Xoshiro256StarStar(const std::array<std::uint64_t, 4>& state);
  // Seeded from the next four outputs of an existing splitmix64 sequence (for several
  // independent streams derived from one seed).
  explicit Xoshiro256StarStar(SplitMix64& seeder);

  std::uint64_t next();
  // Uniform on [0, 1) with 53 random bits: (next() >> 11)·2^−53, exact.
  double uniform();

 private:
  std::array<std::uint64_t, 4> s_{};
};

// Standard normal deviates N(0, 1) by the polar method (Marsaglia & Bray 1964): draw
// (v1, v2) uniform on the square (−1, 1)², reject until 0 < s = v1² + v2² < 1, return
// v1·√(−2 ln s / s) and keep v2·√(−2 ln s / s) for the next call. Same bits everywhere.
class NormalGenerator {
 public:
  explicit NormalGenerator(std::uint64_t seed) : uniform_(seed) {}
  explicit NormalGenerator(SplitMix64& seeder) : uniform_(seeder) {}
  double next();

 private:
  Xoshiro256StarStar uniform_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace gyrod::processing
