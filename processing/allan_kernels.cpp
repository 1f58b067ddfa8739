#include "processing/allan_kernels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

#include "processing/isa_clones.hpp"
#include "processing/parallel_share.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace gyrod::processing::allan_kernels {
namespace {

// Vectors leave the helpers by reference only: a 32-byte vector passed or returned by value
// would have a different ABI in the AVX2 clone and the baseline (Clang refuses it).
inline void loadDoubles(const double* p, Doubles4& v) { std::memcpy(&v, p, sizeof v); }
inline void loadWidened(const float* p, Doubles4& v) {
  Floats4 f;
  std::memcpy(&f, p, sizeof f);
  v = __builtin_convertvector(f, Doubles4);
}

// The second differences of four consecutive start indices: `high` from the hi parts alone,
// `full` with the lo corrections added (full = high + lo combination, the same rounding as
// the scalar secondDifference).
inline void secondDifferences(const double* h, const float* l, std::size_t i, std::size_t m, Doubles4& high,
                              Doubles4& full) {
  Doubles4 ha, hb, hc, la, lb, lc;
  loadDoubles(h + i, ha);
  loadDoubles(h + i + m, hb);
  loadDoubles(h + i + 2 * m, hc);
  loadWidened(l + i, la);
  loadWidened(l + i + m, lb);
  loadWidened(l + i + 2 * m, lc);
  high = (hc - hb) - (hb - ha);
  full = high + ((lc - lb) - (lb - la));
}

inline void highSecondDifferences(const double* h, std::size_t i, std::size_t m, Doubles4& high) {
  Doubles4 ha, hb, hc;
  loadDoubles(h + i, ha);
  loadDoubles(h + i + m, hb);
  loadDoubles(h + i + 2 * m, hc);
  high = (hc - hb) - (hb - ha);
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
// function whose every declaration carries the attribute). Both kernels add the squares of
// the hi-only differences in the same lanes and order, so the hi-only total is the same bits
// from either.
GYROD_ISA_CLONES
void blockTotalLanes(const double* hi, const float* lo, std::size_t m, std::size_t k, std::size_t block_end,
                     double& full_total, double& high_total) {
  Doubles4 acc = {0.0, 0.0, 0.0, 0.0};
  Doubles4 acc_high = {0.0, 0.0, 0.0, 0.0};
  // Two groups of four per step: both are computed independently, then added in order.
  for (; k + 8 <= block_end; k += 8) {
    Doubles4 first_high, first, second_high, second;
    secondDifferences(hi, lo, k, m, first_high, first);
    secondDifferences(hi, lo, k + 4, m, second_high, second);
    acc += first * first;
    acc += second * second;
    acc_high += first_high * first_high;
    acc_high += second_high * second_high;
  }
  for (; k + 4 <= block_end; k += 4) {
    Doubles4 high, full;
    secondDifferences(hi, lo, k, m, high, full);
    acc += full * full;
    acc_high += high * high;
  }
  double p0 = acc[0];
  double q0 = acc_high[0];
  for (; k < block_end; ++k) {
    const double la = lo[k], lb = lo[k + m], lc = lo[k + 2 * m];
    const double high = (hi[k + 2 * m] - hi[k + m]) - (hi[k + m] - hi[k]);
    const double d = high + ((lc - lb) - (lb - la));
    p0 += d * d;
    q0 += high * high;
  }
  full_total = (p0 + acc[1]) + (acc[2] + acc[3]);
  high_total = (q0 + acc_high[1]) + (acc_high[2] + acc_high[3]);
}

GYROD_ISA_CLONES
double highTotalLanes(const double* hi, std::size_t m, std::size_t k, std::size_t block_end) {
  Doubles4 acc_high = {0.0, 0.0, 0.0, 0.0};
  for (; k + 8 <= block_end; k += 8) {
    Doubles4 first_high, second_high;
    highSecondDifferences(hi, k, m, first_high);
    highSecondDifferences(hi, k + 4, m, second_high);
    acc_high += first_high * first_high;
    acc_high += second_high * second_high;
  }
  for (; k + 4 <= block_end; k += 4) {
    Doubles4 high;
    highSecondDifferences(hi, k, m, high);
    acc_high += high * high;
  }
  double q0 = acc_high[0];
  for (; k < block_end; ++k) {
    const double high = (hi[k + 2 * m] - hi[k + m]) - (hi[k + m] - hi[k]);
    q0 += high * high;
  }
  return (q0 + acc_high[1]) + (acc_high[2] + acc_high[3]);
}

}  // namespace

namespace {

// One Neumaier step, s + v with the lost low part added to c; branch-free so that lanes can
// take it at once (each lane the scalar operations in the scalar order).
template <typename T>
inline void neumaierStep(T& s, T& c, const T& v) {
  const T t = s + v;
  const T abs_s = s < 0.0 ? -s : s;
  const T abs_v = v < 0.0 ? -v : v;
  c += abs_s >= abs_v ? (s - t) + v : (v - t) + s;
  s = t;
}

GYROD_ISA_CLONES
double compensatedSumLanes(const double* rate, std::size_t count) {
  Doubles4 s = {0.0, 0.0, 0.0, 0.0};
  Doubles4 c = {0.0, 0.0, 0.0, 0.0};
  std::size_t i = 0;
  for (; i + 4 <= count; i += 4) {
    Doubles4 v;
    loadDoubles(rate + i, v);
    neumaierStep(s, c, v);
  }
  double s0 = s[0], c0 = c[0];
  for (; i < count; ++i) neumaierStep(s0, c0, rate[i]);
  double total = s0, compensation = 0.0;
  neumaierStep(total, compensation, s[1]);
  neumaierStep(total, compensation, s[2]);
  neumaierStep(total, compensation, s[3]);
  return total + (compensation + ((c0 + c[1]) + (c[2] + c[3])));
}

}  // namespace

double compensatedSum(const double* rate, std::size_t count) { return compensatedSumLanes(rate, count); }

double overlappingBlockTotal(const double* hi, const float* lo, std::size_t m, std::size_t k, std::size_t block_end) {
  double full = 0.0, high = 0.0;
  blockTotalLanes(hi, lo, m, k, block_end, full, high);
  return full;
}

BlockTotals overlappingBlockTotals(const double* hi, const float* lo, std::size_t m, std::size_t k,
                                   std::size_t block_end) {
  BlockTotals t;
  blockTotalLanes(hi, lo, m, k, block_end, t.full, t.high);
  return t;
}

double overlappingHighTotal(const double* hi, std::size_t m, std::size_t k, std::size_t block_end) {
  return highTotalLanes(hi, m, k, block_end);
}

namespace {

struct PhaseState {
  double hi = 0.0;
  double lo = 0.0;
  float max_abs_lo = 0.0F;  // the largest |lo| written from this state on (pass 3)
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
  Floats4 max_abs = {0.0F, 0.0F, 0.0F, 0.0F};
  for (std::size_t i = 0; i < count; ++i) {
    const Doubles4 y = {rate[i], rate[i + s1], rate[i + s2], rate[i + s3]};
    const Doubles4 v = y - mean4;
    accumulate(s_hi, s_lo, v);
    if (hi != nullptr) {
      const Floats4 low = __builtin_convertvector(s_lo, Floats4);
      const Floats4 abs_low = low < 0.0F ? -low : low;
      max_abs = max_abs < abs_low ? abs_low : max_abs;
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
  for (std::size_t q = 0; q < kPhaseLanes; ++q) states[q] = {s_hi[q], s_lo[q], max_abs[q]};
}

// The same for one run (the same operations as one lane).
void integrateRun(const double* rate, double mean, std::size_t count, PhaseState& state, double* hi, float* lo) {
  double s_hi = state.hi, s_lo = state.lo;
  float max_abs = 0.0F;
  for (std::size_t i = 0; i < count; ++i) {
    accumulate(s_hi, s_lo, rate[i] - mean);
    if (hi != nullptr) {
      hi[i] = s_hi;
      lo[i] = static_cast<float>(s_lo);
      max_abs = std::max(max_abs, std::abs(lo[i]));
    }
  }
  state = {s_hi, s_lo, max_abs};
}

// a + b for double-double a, b (TwoSum of the high parts, the low parts added, renormalised).
PhaseState doubleDoubleSum(PhaseState a, PhaseState b) {
  const double s = a.hi + b.hi;
  const double bb = s - a.hi;
  const double e = ((a.hi - (s - bb)) + (b.hi - bb)) + (a.lo + b.lo);
  const double hi = s + e;
  return {hi, e - (hi - s), 0.0F};
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

float integratePhase(const double* rate, std::size_t count, double mean, double* hi, float* lo) {
  hi[0] = 0.0;
  lo[0] = 0.0;
  const std::size_t runs = (count + kPhaseRun - 1) / kPhaseRun;
  std::vector<PhaseState> totals(runs), starts(runs);
  forEachRunGroup(rate, count, mean, totals, nullptr, nullptr);
  for (std::size_t r = 1; r < runs; ++r) starts[r] = doubleDoubleSum(starts[r - 1], totals[r - 1]);
  forEachRunGroup(rate, count, mean, starts, hi + 1, lo + 1);
  float max_abs_lo = 0.0F;
  for (const PhaseState& s : starts) max_abs_lo = std::max(max_abs_lo, s.max_abs_lo);
  return max_abs_lo;
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
