#pragma once
// Random numbers that are the same bits on every machine: the simulator's stream must
// be reproducible from its seed on x86_64 and aarch64 alike. The C++ <random> engines
// are portable but its distributions are implementation-defined, so the generator and
// the normal deviate are written here: xoshiro256** 1.0 (Blackman & Vigna 2018) seeded
// through splitmix64 (Steele, Lea & Flood 2014) as its authors recommend, uniform
// doubles from the top 53 bits, and normals by Marsaglia's polar method, which needs only
// + − × ÷, sqrt and a logarithm (portable::log), or by a ziggurat (Marsaglia & Tsang
// 2000) whose tables are computed at first use with portable::exp/log, so they too are
// the same bits everywhere. Compiled with -ffp-contract=off.
#include <array>
#include <cstddef>
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
  static constexpr std::uint64_t rotateLeft(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

 public:
  // State = the next four outputs of SplitMix64(seed).
  explicit Xoshiro256StarStar(std::uint64_t seed);
  // State given directly (for reference test vectors). Throws on all-zero.
  explicit Xoshiro256StarStar(const std::array<std::uint64_t, 4>& state);
  // Seeded from the next four outputs of an existing splitmix64 sequence (for several
  // independent streams derived from one seed).
  explicit Xoshiro256StarStar(SplitMix64& seeder);

  // Inline: the ziggurat's fast path calls it once per deviate (integer work only, so
  // the FMA flag does not matter where it is inlined).
  std::uint64_t next() {
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
  // Uniform on [0, 1) with 53 random bits: (next() >> 11)·2^−53, exact.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

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

// The ziggurat for the half-normal density f(x) = e^{−x²/2}, x ≥ 0 (unnormalised), with
// kLayers layers of equal area v (Marsaglia & Tsang 2000, J. Stat. Softw. 5(8)):
// layer 0 is the rectangle [0, r]×[0, f(r)] plus the tail x > r; layer i ≥ 1 is the
// rectangle [0, x[i]]×[f(x[i]), f(x[i+1])] with x[1] = r > x[2] > … > x[kLayers] = 0,
// x[i+1] = f⁻¹(f(x[i]) + v/x[i]). x[0] = v/f(r) is layer 0's width as if it were all
// rectangle. r is the root of "the top layer's area is v" for
// v(r) = r·f(r) + ∫_r^∞ f (Mills ratio by its continued fraction), found by bisection;
// everything with + − × ÷, sqrt, portable::exp/log, so the tables are the same bits on
// every IEEE-754 machine.
struct NormalZigguratLayers {
  static constexpr int kLayers = 256;
  double r = 0.0;                       // start of the tail
  double v = 0.0;                       // area of every layer
  std::array<double, kLayers + 1> x{};  // layer widths, see above
  std::array<double, kLayers + 1> f{};  // f(x[i]) for i ≥ 1 (f[kLayers] = 1); f[0] = 0
};
// Computed once, on first use (thread-safe static initialisation), immutable after.
const NormalZigguratLayers& normalZigguratLayers();

// Standard normal deviates N(0, 1) by the ziggurat above. One 64-bit word per attempt:
// bits 0–7 pick the layer, bit 8 the sign, bits 11–63 the uniform U; x = U·x[i] is
// accepted at once when x < x[i+1] (98.5 % of attempts: one multiply, one compare). Else,
// in layer 0, a tail deviate by Marsaglia's method (x = r + a with a = −ln U1/r,
// accepted when −2 ln U2 > a²); in a layer above, x is accepted when a uniform height in
// the layer lies under f(x), and otherwise everything starts again. Exact (a rejection
// sampler: up to the rounding of its tables and of f), same bits everywhere, and about
// three times faster than the polar method (bench/simulator_speed.cpp).
class ZigguratNormalGenerator {
 public:
  explicit ZigguratNormalGenerator(std::uint64_t seed) : uniform_(seed), layers_(&normalZigguratLayers()) {}
  explicit ZigguratNormalGenerator(SplitMix64& seeder) : uniform_(seeder), layers_(&normalZigguratLayers()) {}
  double next() {
    const std::uint64_t u = uniform_.next();
    const std::size_t i = u & 0xFF;
    const double x = static_cast<double>(u >> 11) * 0x1.0p-53 * layers_->x[i];
    if (x < layers_->x[i + 1]) return (u & 0x100) ? -x : x;
    return nextOutsideTheCore(u);
  }

 private:
  double nextOutsideTheCore(std::uint64_t u);  // the tail and the wedges
  Xoshiro256StarStar uniform_;
  const NormalZigguratLayers* layers_;
};

}  // namespace gyrod::processing
