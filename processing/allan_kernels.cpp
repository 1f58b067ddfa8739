#include "processing/allan_kernels.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

#include "processing/parallel_share.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

// One clone per ISA where the compiler can dispatch at load time (x86-64 ELF); elsewhere
// (arm64, armhf, sanitizer builds that lack ifunc) the one portable build.
#if defined(__x86_64__) && defined(__ELF__) && defined(__has_attribute) && !defined(GYROD_NO_TARGET_CLONES)
#if __has_attribute(target_clones)
#define GYROD_ISA_CLONES __attribute__((target_clones("avx2", "default")))
#endif
#endif
#ifndef GYROD_ISA_CLONES
#define GYROD_ISA_CLONES
#endif

// The four-lane helpers below take and give vectors by reference only, so no vector crosses
// an ABI boundary and GCC's note that a 32-byte vector would change the ABI without AVX does
// not apply.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace gyrod::processing::allan_kernels {
namespace {

// Four doubles (floats) operated on lane by lane: one AVX2 register, or two SSE2/NEON ones.
// Each lane is IEEE arithmetic in the written order, the same as a scalar chain.
using Doubles4 = double __attribute__((vector_size(4 * sizeof(double))));
using Floats4 = float __attribute__((vector_size(4 * sizeof(float))));

// Vectors leave the helpers by reference only: a 32-byte vector passed or returned by value
// would have a different ABI in the AVX2 clone and the baseline (Clang refuses it).
inline void loadDoubles(const double* p, Doubles4& v) { std::memcpy(&v, p, sizeof v); }
inline void loadWidened(const float* p, Doubles4& v) {
  Floats4 f;
  std::memcpy(&f, p, sizeof f);
  v = __builtin_convertvector(f, Doubles4);
}

inline double secondDifference(const double* h, const float* l, std::size_t i, std::size_t m) {
  const double la = l[i], lb = l[i + m], lc = l[i + 2 * m];
  return ((h[i + 2 * m] - h[i + m]) - (h[i + m] - h[i])) + ((lc - lb) - (lb - la));
}

inline void squaredSecondDifferences(const double* h, const float* l, std::size_t i, std::size_t m, Doubles4& out) {
  Doubles4 ha, hb, hc, la, lb, lc;
  loadDoubles(h + i, ha);
  loadDoubles(h + i + m, hb);
  loadDoubles(h + i + 2 * m, hc);
  loadWidened(l + i, la);
  loadWidened(l + i + m, lb);
  loadWidened(l + i + 2 * m, lc);
  const Doubles4 d = ((hc - hb) - (hb - ha)) + ((lc - lb) - (lb - la));
  out = d * d;
}

// One step of the double-double running sum: TwoSum(s_hi, v), then FastTwoSum renormalisation.
template <typename T>
inline void accumulate(T& s_hi, T& s_lo, const T& v) {
  const T h = s_hi + v;
  const T bv = h - s_hi;
  const T e = (s_hi - (h - bv)) + (v - bv);
  const T l = s_lo + e;
  s_hi = h + l;
  s_lo = l - (s_hi - h);
}

}  // namespace

namespace {

// The clones are internal functions behind the declared one (Clang multiversions only a
// function whose every declaration carries the attribute).
GYROD_ISA_CLONES
double blockTotalLanes(const double* hi, const float* lo, std::size_t m, std::size_t k, std::size_t block_end) {
  Doubles4 acc = {0.0, 0.0, 0.0, 0.0};
  // Two groups of four per step: both are computed independently, then added in order.
  for (; k + 8 <= block_end; k += 8) {
    Doubles4 first, second;
    squaredSecondDifferences(hi, lo, k, m, first);
    squaredSecondDifferences(hi, lo, k + 4, m, second);
    acc += first;
    acc += second;
  }
  for (; k + 4 <= block_end; k += 4) {
    Doubles4 terms;
    squaredSecondDifferences(hi, lo, k, m, terms);
    acc += terms;
  }
  double p0 = acc[0];
  for (; k < block_end; ++k) {
    const double d = secondDifference(hi, lo, k, m);
    p0 += d * d;
  }
  return (p0 + acc[1]) + (acc[2] + acc[3]);
}

}  // namespace

double overlappingBlockTotal(const double* hi, const float* lo, std::size_t m, std::size_t k, std::size_t block_end) {
  return blockTotalLanes(hi, lo, m, k, block_end);
}

namespace {

struct PhaseState {
  double hi = 0.0;
  double lo = 0.0;
};
constexpr std::size_t kPhaseLanes = 4;

// The double-double running sum of (rate[i] − mean) over `count` samples of kPhaseLanes
// runs `run_stride` apart, one per lane, each from its state in `states` (updated to the
// run's end); writes hi[i] and lo[i] (rounded to float) after each sample when hi is given.
GYROD_ISA_CLONES
void integrateRuns(const double* rate, double mean, std::size_t run_stride, std::size_t count, PhaseState* states,
                   double* hi, float* lo) {
  Doubles4 s_hi = {states[0].hi, states[1].hi, states[2].hi, states[3].hi};
  Doubles4 s_lo = {states[0].lo, states[1].lo, states[2].lo, states[3].lo};
  const Doubles4 mean4 = {mean, mean, mean, mean};
  const std::size_t s1 = run_stride, s2 = 2 * run_stride, s3 = 3 * run_stride;
  for (std::size_t i = 0; i < count; ++i) {
    const Doubles4 y = {rate[i], rate[i + s1], rate[i + s2], rate[i + s3]};
    const Doubles4 v = y - mean4;
    accumulate(s_hi, s_lo, v);
    if (hi != nullptr) {
      const Floats4 low = __builtin_convertvector(s_lo, Floats4);
      hi[i] = s_hi[0];
      hi[i + s1] = s_hi[1];
      hi[i + s2] = s_hi[2];
      hi[i + s3] = s_hi[3];
      lo[i] = low[0];
      lo[i + s1] = low[1];
      lo[i + s2] = low[2];
      lo[i + s3] = low[3];
    }
  }
  for (std::size_t q = 0; q < kPhaseLanes; ++q) states[q] = {s_hi[q], s_lo[q]};
}

// The same for one run (the same operations as one lane).
void integrateRun(const double* rate, double mean, std::size_t count, PhaseState& state, double* hi, float* lo) {
  double s_hi = state.hi, s_lo = state.lo;
  for (std::size_t i = 0; i < count; ++i) {
    accumulate(s_hi, s_lo, rate[i] - mean);
    if (hi != nullptr) {
      hi[i] = s_hi;
      lo[i] = static_cast<float>(s_lo);
    }
  }
  state = {s_hi, s_lo};
}

// a + b for double-double a, b (TwoSum of the high parts, the low parts added, renormalised).
PhaseState doubleDoubleSum(PhaseState a, PhaseState b) {
  const double s = a.hi + b.hi;
  const double bb = s - a.hi;
  const double e = ((a.hi - (s - bb)) + (b.hi - bb)) + (a.lo + b.lo);
  const double hi = s + e;
  return {hi, e - (hi - s)};
}

// Runs r·kPhaseRun … of the rate from the states given (updated to the runs' ends), writing
// the phase when hi is given: groups of four full runs through the four-lane kernel, the
// others (the last, shorter run among them) one by one.
void forEachRunGroup(const double* rate, std::size_t count, double mean, std::vector<PhaseState>& states, double* hi,
                     float* lo) {
  const std::size_t groups = count / kPhaseRun / kPhaseLanes;
  const std::size_t singles = states.size() - groups * kPhaseLanes;
  forEachShare(
      groups + singles,
      [&](std::size_t first, std::size_t end) {
        for (std::size_t task = first; task < end; ++task) {
          const std::size_t run = task < groups ? task * kPhaseLanes : groups * kPhaseLanes + (task - groups);
          const std::size_t begin = run * kPhaseRun;
          double* run_hi = hi != nullptr ? hi + begin : nullptr;
          float* run_lo = hi != nullptr ? lo + begin : nullptr;
          if (task < groups)
            integrateRuns(rate + begin, mean, kPhaseRun, kPhaseRun, &states[run], run_hi, run_lo);
          else
            integrateRun(rate + begin, mean, std::min(kPhaseRun, count - begin), states[run], run_hi, run_lo);
        }
      },
      4);
}

}  // namespace

void integratePhase(const double* rate, std::size_t count, double mean, double* hi, float* lo) {
  hi[0] = 0.0;
  lo[0] = 0.0;
  const std::size_t runs = (count + kPhaseRun - 1) / kPhaseRun;
  std::vector<PhaseState> totals(runs), starts(runs);
  forEachRunGroup(rate, count, mean, totals, nullptr, nullptr);
  for (std::size_t r = 1; r < runs; ++r) starts[r] = doubleDoubleSum(starts[r - 1], totals[r - 1]);
  forEachRunGroup(rate, count, mean, starts, hi + 1, lo + 1);
}

void* allocatePhaseBytes(std::size_t bytes) {
  constexpr std::size_t kHugePage = std::size_t{2} << 20;
  bytes = std::max<std::size_t>(bytes, 1);
  if (bytes < 2 * kHugePage) {
    void* p = std::malloc(bytes);
    if (p == nullptr) throw std::bad_alloc();
    return p;
  }
  const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  void* p = std::aligned_alloc(kHugePage, rounded);
  if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  madvise(p, rounded, MADV_HUGEPAGE);  // a hint: where it is refused, ordinary pages serve
#endif
  return p;
}

}  // namespace gyrod::processing::allan_kernels
