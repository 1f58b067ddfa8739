#include "processing/base/portable_random.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "processing/base/portable_math.hpp"

namespace gyrod::processing {
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

namespace gyrod::processing {
namespace {

using Layers = NormalZigguratLayers;

double halfNormalDensity(double x) { return portable::exp(-0.5 * x * x); }  // unnormalised
double inverseHalfNormalDensity(double y) { return std::sqrt(-2.0 * portable::log(y)); }

// ∫_r^∞ e^{−x²/2} dx = e^{−r²/2}·M(r), M the Mills ratio, by its continued fraction
// M(r) = 1/(r + 1/(r + 2/(r + 3/(r + …)))) evaluated from the inside out; 400 terms are
// far more than double precision needs at r ≈ 3.6 (tests compare with √(π/2)·erfc(r/√2)).
double halfNormalTailArea(double r) {
  double t = r;
  for (int k = 400; k >= 1; --k) t = r + static_cast<double>(k) / t;
  return halfNormalDensity(r) / t;
}

double layerArea(double r) { return r * halfNormalDensity(r) + halfNormalTailArea(r); }

// For a trial tail start r: the top layer's area minus v, or −1 when the layers reach
// the top of the density before the last one (r too small). Increasing in r.
double topLayerExcess(double r) {
  const double v = layerArea(r);
  double x = r, fx = halfNormalDensity(r);
  for (int i = 1; i <= Layers::kLayers - 2; ++i) {
    const double f_next = fx + v / x;
    if (f_next >= 1.0) return -1.0;
    x = inverseHalfNormalDensity(f_next);
    fx = f_next;
  }
  return x * (1.0 - fx) - v;
}

Layers buildNormalZigguratLayers() {
  // Bisection on [3, 4.5] (the root for 256 layers is near 3.654) to adjacent doubles.
  double lo = 3.0, hi = 4.5;
  if (!(topLayerExcess(lo) < 0.0) || !(topLayerExcess(hi) > 0.0))
    throw std::logic_error("ziggurat: tail start not bracketed by [3, 4.5]");
  for (;;) {
    const double mid = 0.5 * (lo + hi);
    if (!(mid > lo && mid < hi)) break;
    (topLayerExcess(mid) < 0.0 ? lo : hi) = mid;
  }
  Layers z;
  z.r = hi;  // the side where all 255 recursions stay below the top of the density
  z.v = layerArea(z.r);
  z.x[0] = z.v / halfNormalDensity(z.r);
  z.f[0] = 0.0;
  z.x[1] = z.r;
  z.f[1] = halfNormalDensity(z.r);
  for (int i = 1; i <= Layers::kLayers - 2; ++i) {
    z.f[i + 1] = z.f[i] + z.v / z.x[i];
    z.x[i + 1] = inverseHalfNormalDensity(z.f[i + 1]);
  }
  z.x[Layers::kLayers] = 0.0;
  z.f[Layers::kLayers] = 1.0;
  return z;
}

// Where a wedge's point (x, y) lies against the density without computing it: the density is
// concave below x = 1, so there it lies above the chord through the layer's corners and below
// both tangents there, and convex above x = 1, where chord and tangents swap (Marsaglia &
// Tsang 2000 note such squeezes; f' = −x·f). Decided only beyond a margin of 1e-9 of the
// layer's height, far above the rounding of the bounds and of the density itself, so every
// decision is the one the density would give: the deviates are the same, bit for bit
// (ZigguratNormalGenerator.SqueezedWedgesDecideAsTheDensity). Half or more of the wedge
// points are decided so, and the exponential was ~5 % of a model check's time.
enum class WedgeSqueeze { Below, Above, Unsure };
WedgeSqueeze wedgeSqueeze(const Layers& z, std::size_t i, double x, double y) {
  const double x_in = z.x[i + 1], x_out = z.x[i];  // x_in < x ≤ x_out
  const double f_in = z.f[i + 1], f_out = z.f[i];  // the density there: f_in > f_out
  const double chord = f_in + (f_out - f_in) * (x - x_in) / (x_out - x_in);
  const double tangent_in = f_in * (1.0 - x_in * (x - x_in));
  const double tangent_out = f_out * (1.0 - x_out * (x - x_out));
  const double margin = 1e-9 * f_in;
  if (x_out <= 1.0) {  // concave: chord ≤ f ≤ min(tangents)
    if (y < chord - margin) return WedgeSqueeze::Below;
    if (y > std::min(tangent_in, tangent_out) + margin) return WedgeSqueeze::Above;
  } else if (x_in >= 1.0) {  // convex: max(tangents) ≤ f ≤ chord
    if (y < std::max(tangent_in, tangent_out) - margin) return WedgeSqueeze::Below;
    if (y > chord + margin) return WedgeSqueeze::Above;
  }
  return WedgeSqueeze::Unsure;
}

}  // namespace

const NormalZigguratLayers& normalZigguratLayers() {
  static const NormalZigguratLayers layers = buildNormalZigguratLayers();
  return layers;
}

double ZigguratNormalGenerator::nextOutsideTheCore(std::uint64_t u) {
  const Layers& z = *layers_;
  for (;;) {
    const std::size_t i = u & 0xFF;
    const bool negative = (u & 0x100) != 0;
    const double x = static_cast<double>(u >> 11) * 0x1.0p-53 * z.x[i];
    if (x < z.x[i + 1]) return negative ? -x : x;  // (a fresh word after a rejection)
    if (i == 0) {
      // The tail x > r, density ∝ e^{−x²/2} there: x = r + a, a ~ Exp(r), accepted with
      // probability e^{−a²/2}, i.e. when an Exp(1) deviate b has 2b > a² (Marsaglia 1964).
      // 1 − U is in (0, 1], so the logarithms are finite.
      double a = 0.0, b = 0.0;
      do {
        a = -portable::log(1.0 - uniform_.uniform()) / z.r;
        b = -portable::log(1.0 - uniform_.uniform());
      } while (!(b + b > a * a));
      return negative ? -(z.r + a) : z.r + a;
    }
    // A wedge: a uniform height inside layer i, accepted under the density.
    const double y = z.f[i] + uniform_.uniform() * (z.f[i + 1] - z.f[i]);
    const WedgeSqueeze squeeze = wedgeSqueeze(z, i, x, y);
    if (squeeze == WedgeSqueeze::Below || (squeeze == WedgeSqueeze::Unsure && y < halfNormalDensity(x)))
      return negative ? -x : x;
    u = uniform_.next();
  }
}

}  // namespace gyrod::processing
