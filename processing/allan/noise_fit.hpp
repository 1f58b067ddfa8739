#pragma once
// Noise-term identification from an Allan curve.
//  - fitNoiseTerms: weighted least squares of σ²(τ) = Σ cᵢ·τ^pᵢ (p = −2..2) with cᵢ ≥ 0
//    over the whole curve; weights from each point's confidence (edf). Exact NNLS by
//    active-set enumeration (2⁵ subsets).
//  - readNoiseTermsFromSlopes: the classical reading of IEEE 952: for each term the line
//    of its slope that touches the curve from below, read at the conventional τ.
#include <Eigen/Dense>
#include <array>
#include <span>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/base/noise_terms.hpp"

namespace gyrod::processing {

struct NoiseTermFit {
  NoiseTerms value;  // paper units
  // 1-σ, paper units. For a fitted term: the covariance of the active set scaled by
  // max(1, reduced χ²), propagated through T ∝ √c (σ_T = σ_c·T/(2c)), but never more than
  // the zero-term bound below. For a term fitted to 0: the value whose coefficient equals
  // 1 σ of c in the active set plus that term — a scale for "could be this large".
  NoiseTerms uncertainty;
  double reduced_chi2 = 0.0;  // weighted residual / (points − active terms); NaN if no dof left
  std::size_t points_used = 0;
};

// Uses points with oadev_terms ≥ min_terms and finite oadev. Weights: var(σ̂²) ≈ σ⁴·2/edf
// with σ² the model value from the previous pass (first pass: the measured value), three
// passes; the model value avoids favouring points that happened to come out low.
// Throws std::invalid_argument when no point qualifies, or a qualifying point has
// τ ≤ 0, oadev ≤ 0 or a non-finite / non-positive edf.
NoiseTermFit fitNoiseTerms(std::span<const AllanPoint> curve, std::size_t min_terms = 2);

// The same fit of σ²(τ) = Σ cᵢ·sᵢ(τ)·τ^pᵢ + k(τ): term i's basis times its shape sᵢ at each
// point of the curve (an empty shape: 1), after a known variance k per point is taken off
// (empty: none; a point keeps at least 1 % of its variance). The model check's base model
// uses it for the terms a filter in the acquisition chain shapes at short τ.
using NoiseTermShapes = std::array<std::vector<double>, kNoiseTermCount>;
NoiseTermFit fitShapedNoiseTerms(std::span<const AllanPoint> curve, const NoiseTermShapes* shapes,
                                 std::span<const double> known_variance, std::size_t min_terms = 2);

// For each term of log-log slope s: b = minᵢ(ln σᵢ − s·ln τᵢ), i.e. c = e^{2b} in σ² = c·τ^p.
// On an exact curve this is an upper bound of every term (each term's own line lies below
// the sum) and is exact for a term that dominates somewhere; on an estimated curve the
// minimum picks up downward fluctuations, so sparse, low-edf points bias it low.
NoiseTerms readNoiseTermsFromSlopes(std::span<const AllanPoint> curve, std::size_t min_terms = 2);

// Exact non-negative least squares, min ‖A·x − b‖² subject to x ≥ 0, by solving the
// unconstrained problem on every support (subset of columns; at most 16 columns) and
// keeping the feasible one of least residual — the NNLS optimum has a support with
// independent columns on which it is the unconstrained solution. Columns are scaled to unit
// norm before solving. Among supports whose residuals agree to rounding (1e-13·‖b‖²) the
// smaller one is kept, so an absent term comes out exactly 0.
struct NonNegativeLeastSquares {
  Eigen::VectorXd x;
  double residual_squared = 0.0;
};
NonNegativeLeastSquares solveNonNegativeLeastSquares(const Eigen::MatrixXd& a, const Eigen::VectorXd& b);

}  // namespace gyrod::processing
