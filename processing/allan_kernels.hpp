#pragma once
// The two inner loops of the overlapping Allan sweep (processing/allan.cpp), kept apart so
// that each is compiled for the machine it runs on: on x86-64 an AVX2 clone is chosen at
// load time when the CPU has it (GCC/Clang function multiversioning), else the baseline
// (SSE2); on ARM the one portable build (NEON on arm64). Every path does the same IEEE
// operations lane by lane in the same order, without fused multiply-adds (ISO C++ mode
// contracts nothing, and the AVX2 clone does not enable FMA), so every path gives the same
// bits: the ISA changes the speed, never a result.
#include <cstddef>

namespace gyrod::processing::allan_kernels {

// Σ over i in [k, block_end) of d_i², with d_i the second difference at averaging m of the
// phase held as hi[i] + lo[i]:
//   d_i = ((hi[i+2m] − hi[i+m]) − (hi[i+m] − hi[i])) + ((lo[i+2m] − lo[i+m]) − (lo[i+m] − lo[i])).
// Lane j of a four-lane accumulator takes the terms k + 4q + j, the tail goes to lane 0, and
// the total is (lane0 + lane1) + (lane2 + lane3).
double overlappingBlockTotal(const double* hi, const float* lo, std::size_t m, std::size_t k, std::size_t block_end);

// The double-double running sum of (rate[i] − mean) over `count` samples, starting from the
// state (s_hi, s_lo): writes hi[i] and lo[i] (rounded to float) after each sample i, and
// returns the final state. The running sums of kPhaseLanes runs, each `count` long and
// `run_stride` apart, are formed together, one per lane (independent chains: the latency of
// one is hidden by the others).
inline constexpr std::size_t kPhaseLanes = 4;
struct PhaseState {
  double hi = 0.0;
  double lo = 0.0;
};
void integrateRuns(const double* rate, double mean, std::size_t run_stride, std::size_t count, PhaseState* states,
                   double* hi, float* lo);
// The same for one run (the same operations as one lane).
void integrateRun(const double* rate, double mean, std::size_t count, PhaseState& state, double* hi, float* lo);

}  // namespace gyrod::processing::allan_kernels
