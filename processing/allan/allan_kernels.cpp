#include "processing/allan/allan_kernels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <vector>

#include "processing/base/isa_clones.hpp"
#include "processing/base/parallel_share.hpp"

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

inline void loadLo(const float* p, Doubles4& v) { loadWidened(p, v); }
inline void loadLo(const double* p, Doubles4& v) { loadDoubles(p, v); }

// The second differences of four consecutive start indices: `high` from the hi parts alone,
// `full` with the lo corrections added (full = high + lo combination, the same rounding as
// the scalar secondDifference). The lo parts are the stored floats, or the same values
// already widened to double (exact): the same bits either way.
template <typename Lo>
inline void secondDifferences(const double* h, const Lo* l, std::size_t i, std::size_t m, Doubles4& high,
                              Doubles4& full) {
  Doubles4 ha, hb, hc, la, lb, lc;
  loadDoubles(h + i, ha);
  loadDoubles(h + i + m, hb);
  loadDoubles(h + i + 2 * m, hc);
  loadLo(l + i, la);
  loadLo(l + i + m, lb);
  loadLo(l + i + 2 * m, lc);
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
// function whose every declaration carries the attribute, and no template). Both kernels add
// the squares of the hi-only differences in the same lanes and order, so the hi-only total is
// the same bits from either.
template <typename Lo>
[[gnu::always_inline]] inline void blockTotalLanesOf(const double* hi, const Lo* lo, std::size_t m, std::size_t k,
                                                     std::size_t block_end, double& full_total, double& high_total) {
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
void blockTotalLanes(const double* hi, const float* lo, std::size_t m, std::size_t k, std::size_t block_end,
                     double& full_total, double& high_total) {
  blockTotalLanesOf(hi, lo, m, k, block_end, full_total, high_total);
}

GYROD_ISA_CLONES
void blockTotalLanesWide(const double* hi, const double* lo, std::size_t m, std::size_t k, std::size_t block_end,
                         double& full_total, double& high_total) {
  blockTotalLanesOf(hi, lo, m, k, block_end, full_total, high_total);
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

// z_k … z_{k+3} of the series (AveragedSeries), and z_k alone: the same operations, so the
// same bits, lane by lane.
template <AveragedSeries S>
[[gnu::always_inline]] inline double seriesPoint(const double* data, double mean, double divisor, std::size_t k) {
  if constexpr (S == AveragedSeries::Rate) {
    return data[k] - mean;
  } else if constexpr (S == AveragedSeries::Pairs) {
    return ((data[2 * k] - mean) + (data[2 * k + 1] - mean)) / 2.0;
  } else if constexpr (S == AveragedSeries::Quads) {
    const double* q = data + 4 * k;
    return (((q[0] - mean) + (q[1] - mean)) + ((q[2] - mean) + (q[3] - mean))) / 4.0;
  } else {
    return data[k] / divisor;
  }
}

// The four pair sums s2_{j} … s2_{j+3} (rate[2j … 2j+7]).
[[gnu::always_inline]] inline void pairSums(const double* data, const Doubles4& mean4, std::size_t j, Doubles4& out) {
  Doubles4 p, q;
  loadDoubles(data + 2 * j, p);
  loadDoubles(data + 2 * j + 4, q);
  p -= mean4;
  q -= mean4;
  out = __builtin_shufflevector(p, q, 0, 2, 4, 6) + __builtin_shufflevector(p, q, 1, 3, 5, 7);
}

template <AveragedSeries S>
[[gnu::always_inline]] inline void seriesPoints(const double* data, const Doubles4& mean4, const Doubles4& divisor4,
                                                std::size_t k, Doubles4& out) {
  if constexpr (S == AveragedSeries::Rate) {
    loadDoubles(data + k, out);
    out -= mean4;
  } else if constexpr (S == AveragedSeries::Pairs) {
    pairSums(data, mean4, k, out);
    out /= Doubles4{2.0, 2.0, 2.0, 2.0};
  } else if constexpr (S == AveragedSeries::Quads) {
    Doubles4 low, high;
    pairSums(data, mean4, 2 * k, low);
    pairSums(data, mean4, 2 * k + 4, high);
    out = __builtin_shufflevector(low, high, 0, 2, 4, 6) + __builtin_shufflevector(low, high, 1, 3, 5, 7);
    out /= Doubles4{4.0, 4.0, 4.0, 4.0};
  } else {
    loadDoubles(data + k, out);
    out /= divisor4;
  }
}

// The d-th difference at i: z_i, z_{i+1} − z_i, or (z_{i+2} − z_{i+1}) − (z_{i+1} − z_i).
template <int D, AveragedSeries S>
[[gnu::always_inline]] inline double differencePoint(const double* data, double mean, double divisor, std::size_t i) {
  const double z0 = seriesPoint<S>(data, mean, divisor, i);
  if constexpr (D == 0) {
    return z0;
  } else if constexpr (D == 1) {
    return seriesPoint<S>(data, mean, divisor, i + 1) - z0;
  } else {
    const double z1 = seriesPoint<S>(data, mean, divisor, i + 1);
    return (seriesPoint<S>(data, mean, divisor, i + 2) - z1) - (z1 - z0);
  }
}

template <int D, AveragedSeries S>
[[gnu::always_inline]] inline void differencePoints(const double* data, const Doubles4& mean4, const Doubles4& divisor4,
                                                    std::size_t i, Doubles4& out) {
  Doubles4 z0;
  seriesPoints<S>(data, mean4, divisor4, i, z0);
  if constexpr (D == 0) {
    out = z0;
  } else if constexpr (D == 1) {
    seriesPoints<S>(data, mean4, divisor4, i + 1, out);
    out -= z0;
  } else {
    Doubles4 z1, z2;
    seriesPoints<S>(data, mean4, divisor4, i + 1, z1);
    seriesPoints<S>(data, mean4, divisor4, i + 2, z2);
    out = (z2 - z1) - (z1 - z0);
  }
}

template <int D, AveragedSeries S>
[[gnu::always_inline]] inline Lag1Correlation lag1OfDifferenceLanes(const double* data, double series_mean,
                                                                    double divisor, std::size_t len) {
  const std::size_t n = len - static_cast<std::size_t>(D);
  const Doubles4 mean4 = {series_mean, series_mean, series_mean, series_mean};
  const Doubles4 divisor4 = {divisor, divisor, divisor, divisor};
  // The mean of the differences.
  Doubles4 lanes = {0.0, 0.0, 0.0, 0.0};
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    Doubles4 v;
    differencePoints<D, S>(data, mean4, divisor4, i, v);
    lanes += v;
  }
  double mean = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
  for (; i < n; ++i) mean += differencePoint<D, S>(data, series_mean, divisor, i);
  mean /= static_cast<double>(n);
  // den over all n values, num over the n − 1 neighbouring pairs (a_i, a_{i+1}).
  const Doubles4 centre = {mean, mean, mean, mean};
  Doubles4 num_lanes = {0.0, 0.0, 0.0, 0.0}, den_lanes = {0.0, 0.0, 0.0, 0.0};
  i = 0;
  for (; i + 4 < n; i += 4) {
    Doubles4 a, b;
    differencePoints<D, S>(data, mean4, divisor4, i, a);
    differencePoints<D, S>(data, mean4, divisor4, i + 1, b);
    a -= centre;
    b -= centre;
    den_lanes += a * a;
    num_lanes += a * b;
  }
  double num = (num_lanes[0] + num_lanes[1]) + (num_lanes[2] + num_lanes[3]);
  double den = (den_lanes[0] + den_lanes[1]) + (den_lanes[2] + den_lanes[3]);
  double a = differencePoint<D, S>(data, series_mean, divisor, i) - mean;
  for (; i < n; ++i) {
    den += a * a;
    if (i + 1 < n) {
      const double next = differencePoint<D, S>(data, series_mean, divisor, i + 1) - mean;
      num += a * next;
      a = next;
    }
  }
  return {den > 0.0 ? num / den : 0.0, den};
}

template <AveragedSeries S>
[[gnu::always_inline]] inline Lag1Correlation lag1OfSeries(const double* data, double mean, double divisor,
                                                           std::size_t len, int d) {
  if (d == 0) return lag1OfDifferenceLanes<0, S>(data, mean, divisor, len);
  if (d == 1) return lag1OfDifferenceLanes<1, S>(data, mean, divisor, len);
  return lag1OfDifferenceLanes<2, S>(data, mean, divisor, len);
}

GYROD_ISA_CLONES
Lag1Correlation lag1OfDifferenceClones(AveragedSeries series, const double* data, double mean, double divisor,
                                       std::size_t len, int d) {
  switch (series) {
    case AveragedSeries::Rate: return lag1OfSeries<AveragedSeries::Rate>(data, mean, divisor, len, d);
    case AveragedSeries::Pairs: return lag1OfSeries<AveragedSeries::Pairs>(data, mean, divisor, len, d);
    case AveragedSeries::Quads: return lag1OfSeries<AveragedSeries::Quads>(data, mean, divisor, len, d);
    case AveragedSeries::Sums: break;
  }
  return lag1OfSeries<AveragedSeries::Sums>(data, mean, divisor, len, d);
}

}  // namespace

Lag1Correlation lag1OfDifference(AveragedSeries series, const double* data, double mean, double divisor,
                                 std::size_t len, int d) {
  return lag1OfDifferenceClones(series, data, mean, divisor, len, d);
}

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

BlockTotals overlappingBlockTotals(const double* hi, const double* lo, std::size_t m, std::size_t k,
                                   std::size_t block_end) {
  BlockTotals t;
  blockTotalLanesWide(hi, lo, m, k, block_end, t.full, t.high);
  return t;
}

namespace {

GYROD_ISA_CLONES
void widenLanes(const float* lo, std::size_t count, double* wide) {
  std::size_t i = 0;
  for (; i + 4 <= count; i += 4) {
    Doubles4 v;
    loadWidened(lo + i, v);
    std::memcpy(wide + i, &v, sizeof v);
  }
  for (; i < count; ++i) wide[i] = lo[i];
}

}  // namespace

void widenLo(const float* lo, std::size_t count, double* wide) { widenLanes(lo, count, wide); }

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
// run's end); writes hi[i] and lo[i] (rounded to float) after each sample.
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
  for (std::size_t q = 0; q < kPhaseLanes; ++q) states[q] = {s_hi[q], s_lo[q], max_abs[q]};
}

// The same for one run (the same operations as one lane).
void integrateRun(const double* rate, double mean, std::size_t count, PhaseState& state, double* hi, float* lo) {
  double s_hi = state.hi, s_lo = state.lo;
  float max_abs = 0.0F;
  for (std::size_t i = 0; i < count; ++i) {
    accumulate(s_hi, s_lo, rate[i] - mean);
    hi[i] = s_hi;
    lo[i] = static_cast<float>(s_lo);
    max_abs = std::max(max_abs, std::abs(lo[i]));
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

// The double-double total of (rate[i] − shift) over `count` samples (one run): the last
// count mod 4·kTotalChains samples serially, then kTotalChains chains of four lanes, chain c's
// lane q taking the samples i ≡ 4c + q (mod 4·kTotalChains), added to it by double-double
// addition lane by lane, chain by chain. Independent chains keep the pipes busy where one
// running sum waits on its own latency (seven dependent additions a sample); the order is
// fixed, so the total is the same bits on every ISA and for any number of threads. Also the
// smallest and the largest sample (for a finite run).
constexpr std::size_t kTotalChains = 4;
constexpr std::size_t kTotalStep = kPhaseLanes * kTotalChains;
static_assert(kPhaseRun % kTotalStep == 0, "a full run is whole steps of the chains");
GYROD_ISA_CLONES
RunSum runTotal(const double* rate, double shift, std::size_t count) {
  const Doubles4 shift4 = {shift, shift, shift, shift};
  Doubles4 chain_hi[kTotalChains] = {};
  Doubles4 chain_lo[kTotalChains] = {};
  const double first = count > 0 ? rate[0] : 0.0;
  Doubles4 low = {first, first, first, first};
  Doubles4 high = low;
  const std::size_t whole = count - count % kTotalStep;
  for (std::size_t i = 0; i < whole; i += kTotalStep) {
    for (std::size_t c = 0; c < kTotalChains; ++c) {
      Doubles4 y;
      loadDoubles(rate + i + kPhaseLanes * c, y);
      low = y < low ? y : low;
      high = high < y ? y : high;
      accumulate(chain_hi[c], chain_lo[c], y - shift4);
    }
  }
  double tail_hi = 0.0, tail_lo = 0.0;
  double smallest = std::min(std::min(low[0], low[1]), std::min(low[2], low[3]));
  double largest = std::max(std::max(high[0], high[1]), std::max(high[2], high[3]));
  for (std::size_t i = whole; i < count; ++i) {
    accumulate(tail_hi, tail_lo, rate[i] - shift);
    smallest = std::min(smallest, rate[i]);
    largest = std::max(largest, rate[i]);
  }
  PhaseState total{tail_hi, tail_lo, 0.0F};
  for (std::size_t c = 0; c < kTotalChains; ++c)
    for (std::size_t q = 0; q < kPhaseLanes; ++q)
      total = doubleDoubleSum(total, {chain_hi[c][q], chain_lo[c][q], 0.0F});
  return {total.hi, total.lo, smallest, largest};
}

// Whether rate[i] − mean is exact for every sample in [smallest, largest]: Sterbenz's lemma
// (y − μ is a double when μ/2 ≤ y ≤ 2μ, or 2μ ≤ y ≤ μ/2 for μ < 0). μ/2 and 2μ are exact
// away from the ends of the range, which the bounds on |μ| keep.
bool differencesFromMeanAreExact(double smallest, double largest, double mean) {
  const double magnitude = std::abs(mean);
  if (!(magnitude >= 4.0 * std::numeric_limits<double>::min() && magnitude <= std::numeric_limits<double>::max() / 4.0))
    return false;
  if (mean > 0.0) return smallest >= mean / 2.0 && largest <= 2.0 * mean;
  return largest <= mean / 2.0 && smallest >= 2.0 * mean;
}

// Runs r·kPhaseRun … of the rate from the states given (updated to the runs' ends), writing
// the phase: groups of four full runs through the four-lane kernel, the others (the last,
// shorter run among them) one by one.
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
          if (task < groups)
            integrateRuns(rate + begin, mean, kPhaseRun, kPhaseRun, &states[run], hi + begin, lo + begin);
          else
            integrateRun(rate + begin, mean, std::min(kPhaseRun, count - begin), states[run], hi + begin, lo + begin);
        }
      },
      4);
}

}  // namespace

float integratePhase(const double* rate, std::size_t count, double mean, std::span<const RunSum> sums, double* hi,
                     float* lo) {
  hi[0] = 0.0;
  lo[0] = 0.0;
  const std::size_t runs = (count + kPhaseRun - 1) / kPhaseRun;
  const bool have_sums = sums.size() == runs;
  std::vector<PhaseState> totals(runs), starts(runs);
  // Every run but the last is full, and only those runs' totals start another. Where every
  // rate[i] − mean of a run is exact, its total is the run's sample sum less kPhaseRun·mean
  // (exact: kPhaseRun is a power of two), without reading the run again.
  forEachShare(
      runs > 0 ? runs - 1 : 0,
      [&](std::size_t first, std::size_t end) {
        for (std::size_t r = first; r < end; ++r) {
          if (have_sums && differencesFromMeanAreExact(sums[r].min, sums[r].max, mean)) {
            totals[r] =
                doubleDoubleSum({sums[r].hi, sums[r].lo, 0.0F}, {-static_cast<double>(kPhaseRun) * mean, 0.0, 0.0F});
          } else {
            const RunSum t = runTotal(rate + r * kPhaseRun, mean, kPhaseRun);
            totals[r] = {t.hi, t.lo, 0.0F};
          }
        }
      },
      4);
  for (std::size_t r = 1; r < runs; ++r) starts[r] = doubleDoubleSum(starts[r - 1], totals[r - 1]);
  forEachRunGroup(rate, count, mean, starts, hi + 1, lo + 1);
  float max_abs_lo = 0.0F;
  for (const PhaseState& s : starts) max_abs_lo = std::max(max_abs_lo, s.max_abs_lo);
  return max_abs_lo;
}

std::vector<RunSum> sumRuns(const double* rate, std::size_t count) {
  const std::size_t runs = (count + kPhaseRun - 1) / kPhaseRun;
  std::vector<RunSum> sums(runs);
  forEachShare(
      runs,
      [&](std::size_t first, std::size_t end) {
        for (std::size_t r = first; r < end; ++r)
          sums[r] = runTotal(rate + r * kPhaseRun, 0.0, std::min(kPhaseRun, count - r * kPhaseRun));
      },
      4);
  return sums;
}

double totalOfRuns(std::span<const RunSum> sums) {
  PhaseState total;
  for (const RunSum& s : sums) total = doubleDoubleSum(total, {s.hi, s.lo, 0.0F});
  return total.hi;
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
