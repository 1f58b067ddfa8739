#pragma once
// Quantiles and tail probabilities of the distributions the statistics need. Thin,
// named wrappers over Boost.Math so that the rest of processing/ says what it means.
namespace gyrod::processing {

// Φ⁻¹(p), the standard normal quantile.
double normalQuantile(double p);
// Φ(z).
double normalCdf(double z);
// The p-quantile of χ² with `dof` degrees of freedom (dof may be fractional, > 0).
double chiSquareQuantile(double p, double dof);
// P(X ≤ x) for X ~ χ²(dof).
double chiSquareCdf(double x, double dof);
// P(T > t) for T ~ Student's t with `dof` degrees of freedom (fractional allowed, > 0): a
// difference over a standard deviation estimated with that many degrees of freedom.
double studentTUpperTail(double t, double dof);

}  // namespace gyrod::processing
