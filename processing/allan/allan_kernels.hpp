#pragma once
// The inner loops of the Allan tables (processing/allan/allan.cpp), kept apart so
// that each is compiled for the machine it runs on: on x86-64 an AVX2 clone is chosen at
// load time when the CPU has it (GCC/Clang function multiversioning), else the baseline
// (SSE2); on ARM the one portable build (NEON on arm64). Every path does the same IEEE
// operations lane by lane in the same order, without fused multiply-adds (ISO C++ mode
// contracts nothing, and the AVX2 clone does not enable FMA), so every path gives the same
// bits: the ISA changes the speed, never a result.
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <span>
#include <vector>

namespace gyrod::processing::allan_kernels {

// Σ over i in [k, block_end) of d_i², with d_i the second difference at averaging m of the
// phase held as hi[i] + lo[i]:
//   d_i = ((hi[i+2m] − hi[i+m]) − (hi[i+m] − hi[i])) + ((lo[i+2m] − lo[i+m]) − (lo[i+m] − lo[i])).
// Lane j of a four-lane accumulator takes the terms k + 4q + j, the tail goes to lane 0, and
// the total is (lane0 + lane1) + (lane2 + lane3).
double overlappingBlockTotal(const double* hi, const float* lo, std::size_t m, std::size_t k, std::size_t block_end);

// The same sum twice in one pass: `full` as overlappingBlockTotal (the same bits), `high`
// with the lo parts left out (d_i = (hi[i+2m] − hi[i+m]) − (hi[i+m] − hi[i]), the same lanes
// and order).
struct BlockTotals {
  double full = 0.0;
  double high = 0.0;
};
BlockTotals overlappingBlockTotals(const double* hi, const float* lo, std::size_t m, std::size_t k,
                                   std::size_t block_end);
// The same with the lo parts already widened to double (lo[i] the float's exact value, e.g.
// from widenLo): the same bits as from the floats. A block sweep that needs the lo parts at
// several m widens them once instead of at every m.
BlockTotals overlappingBlockTotals(const double* hi, const double* lo, std::size_t m, std::size_t k,
                                   std::size_t block_end);
void widenLo(const float* lo, std::size_t count, double* wide);
// The hi-only sum alone, reading hi only: the same bits as BlockTotals::high.
double overlappingHighTotal(const double* hi, std::size_t m, std::size_t k, std::size_t block_end);

// The length of the runs in which the sums and the phase below are formed.
inline constexpr std::size_t kPhaseRun = std::size_t{1} << 13;

// The samples in fixed runs of kPhaseRun (the phase's runs; the last may be shorter): each
// run's sum to double-double accuracy (hi + lo, formed in independent chains, as the phase's
// run totals), and its smallest and largest sample. The runs are shared among threads.
struct RunSum {
  double hi = 0.0;
  double lo = 0.0;
  double min = 0.0;
  double max = 0.0;
};
std::vector<RunSum> sumRuns(const double* rate, std::size_t count);
// Σ of the runs' sums by double-double addition in run order, rounded once: the error before
// that rounding is ~ε²·Σ|partial sums|, so the result is the correctly rounded sum but in rare
// ties. The order is fixed, so it is the same bits on every ISA and for any number of threads.
// A non-finite sample makes the result non-finite (so can an overflow).
double totalOfRuns(std::span<const RunSum> sums);

// The averaged series whose lag-1 autocorrelation the noise identification measures
// (allan.cpp's noise types), point z_k of each as the table forms it from the rate's cluster
// sums, s1_i = rate[i] − mean:
//   Rate:  z_k = s1_k                                   (m = 1)
//   Pairs: z_k = s2_k / 2,  s2_k = s1_{2k} + s1_{2k+1}  (m = 2)
//   Quads: z_k = (s2_{2k} + s2_{2k+1}) / 4              (m = 4)
//   Sums:  z_k = data[k] / divisor                      (cluster sums formed elsewhere)
enum class AveragedSeries { Rate, Pairs, Quads, Sums };
struct Lag1Correlation {
  double r1 = 0.0;      // Σ (z_i − z̄)(z_{i+1} − z̄) / Σ (z_i − z̄)², 0 when the latter is 0
  double sum_sq = 0.0;  // Σ (z_i − z̄)²
};
// The lag-1 autocorrelation of the d-th difference (d ≤ 2; z′_i = z_{i+1} − z_i, applied d
// times) of the series' first `len` points (`mean` is read by Rate, Pairs and Quads, `divisor`
// by Sums). The mean and both sums are kept in four lanes, lane j taking the values
// 4q + j, the tail lane 0 for the mean and the last values serially for the sums, the lanes
// added as (0 + 1) + (2 + 3): the same bits on every ISA.
Lag1Correlation lag1OfDifference(AveragedSeries series, const double* data, double mean, double divisor,
                                 std::size_t len, int d);

// The phase of the mean-removed rate as the unevaluated sum hi[k] + lo[k], k = 0 … count
// (hi[0] = lo[0] = 0): the double-double running sum of (rate[i] − mean), lo rounded to
// float. Formed in fixed runs of kPhaseRun samples: every run's double-double total (pass 1,
// each run in sixteen interleaved chains added at its end), the runs' starting sums by
// double-double addition of the totals before them (pass 2), then every run's running sum
// from its start (pass 3, four runs at once, one per lane). Independent chains hide the
// latency of one running sum behind the others; both passes share the runs among threads.
// The run length and every order are fixed, so the phase is the same bits for any number of
// threads and any ISA; it differs from one serial running sum only by the errors of the
// double-double additions (~ε²·|x| each, far below the float lo's 2⁻⁷⁷·|x|).
// `sums`, sumRuns of the same samples (or empty), spares pass 1 every run whose differences
// rate[i] − mean are all exact (Sterbenz: every sample within a factor 2 of the mean, as on a
// gyro whose bias outweighs its noise): its total is then its sum less kPhaseRun·mean. Its
// error is then ~ε² of the run's sample sum instead of ~ε² of Σ(rate[i] − mean): a jump of
// that size at the next run's first point, which only the second differences across it see
// (for a bias 10¹² times its noise, ~10⁻¹⁶ of such a difference). Returns the largest |lo[k]|
// written (a float, exact).
float integratePhase(const double* rate, std::size_t count, double mean, std::span<const RunSum> sums, double* hi,
                     float* lo);

// Storage for a phase array, written once in full by its owner (not zero-filled). Blocks of
// 4 MB or more are aligned to 2 MiB and, on Linux, marked for transparent huge pages: a
// 10⁷-sample phase (120 MB) otherwise costs ~30 000 page faults on first touch, each clearing
// its own page, a sizeable share of the whole sweep. Only the time changes, never a value.
struct FreeDeleter {
  void operator()(void* p) const { std::free(p); }
};
template <typename T>
using PhaseStorage = std::unique_ptr<T[], FreeDeleter>;

// `bytes` (at least 1) of uninitialised storage; throws std::bad_alloc when none is left.
void* allocatePhaseBytes(std::size_t bytes);

template <typename T>
PhaseStorage<T> allocatePhaseStorage(std::size_t count) {
  return PhaseStorage<T>(static_cast<T*>(allocatePhaseBytes(count * sizeof(T))));
}

}  // namespace gyrod::processing::allan_kernels
