#pragma once
// GYROD_ISA_CLONES before a function: one clone of it per ISA, chosen at load time, where the
// compiler can dispatch (x86-64 ELF: an AVX2 clone beside the baseline); elsewhere (arm64,
// armhf, Clang without ifunc) the one portable build. Only for functions whose four-lane
// arithmetic (`Doubles4`) is the same lane by lane on every ISA, so that every clone gives
// the same bits: a vector is one AVX2 register, or two SSE2/NEON ones, never a reordering.
#if defined(__x86_64__) && defined(__ELF__) && defined(__has_attribute) && !defined(GYROD_NO_TARGET_CLONES)
#if __has_attribute(target_clones)
#define GYROD_ISA_CLONES __attribute__((target_clones("avx2", "default")))
#endif
#endif
#ifndef GYROD_ISA_CLONES
#define GYROD_ISA_CLONES
#endif

// A 32-byte vector passed or returned by value would have a different ABI in the AVX2 clone
// and in the baseline (Clang refuses it; GCC warns, -Wpsabi): the cloned functions keep their
// vectors inside, or pass them by reference, so the note does not apply.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace gyrod::processing {

// Four doubles operated on lane by lane, each lane IEEE arithmetic in the written order (the
// same as a scalar chain), and the lane masks their comparisons give.
using Doubles4 = double __attribute__((vector_size(4 * sizeof(double))));
using Floats4 = float __attribute__((vector_size(4 * sizeof(float))));
using LaneMask4 = long long __attribute__((vector_size(4 * sizeof(long long))));

}  // namespace gyrod::processing
