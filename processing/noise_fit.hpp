#pragma once
// Noise-term identification from an Allan curve.
//  - fitNoiseTerms: weighted least squares of σ²(τ) = Σ cᵢ·τ^pᵢ (p = −2..2) with cᵢ ≥ 0
//    over the whole curve; weights from each point's confidence (edf). Exact NNLS by
//    active-set enumeration (2⁵ subsets).
//  - readNoiseTermsFromSlopes: the classical reading of IEEE 952: for each term the line
//    of its slope that touches the curve from below, read at the conventional τ.
#include <span>

#include "processing/allan.hpp"
#include "processing/noise_terms.hpp"

namespace gyrod::processing {

struct NoiseTermFit {
  NoiseTerms value;        // paper units
  NoiseTerms uncertainty;  // 1-σ, paper units (for a term fitted to 0: an upper bound scale)
  double reduced_chi2 = 0.0;
  std::size_t points_used = 0;
};

// Uses points with oadev_terms ≥ min_terms and finite oadev.
NoiseTermFit fitNoiseTerms(std::span<const AllanPoint> curve, std::size_t min_terms = 2);

NoiseTerms readNoiseTermsFromSlopes(std::span<const AllanPoint> curve, std::size_t min_terms = 2);

}  // namespace gyrod::processing
