#pragma once
// Exact (Clopper–Pearson) bounds of a binomial proportion for the model-check benches: the
// false-discovery table (one-sided upper bound) and the coverage table (two-sided interval).
#include <cmath>
#include <cstddef>

namespace gyrod::bench {

// P(X ≤ k) for X ~ Binomial(n, p).
inline double binomialCdf(std::size_t k, std::size_t n, double p) {
  if (p <= 0.0) return 1.0;
  if (p >= 1.0) return k >= n ? 1.0 : 0.0;
  double sum = 0.0;
  const auto nn = static_cast<double>(n);
  for (std::size_t i = 0; i <= k && i <= n; ++i) {
    const auto ii = static_cast<double>(i);
    sum += std::exp(std::lgamma(nn + 1.0) - std::lgamma(ii + 1.0) - std::lgamma(nn - ii + 1.0) + ii * std::log(p) +
                    (nn - ii) * std::log1p(-p));
  }
  return std::fmin(sum, 1.0);
}

// The p at which P(X ≤ k) (upper = true) or P(X ≥ k) (upper = false) equals tail, by bisection.
inline double clopperPearsonBound(std::size_t k, std::size_t n, double tail, bool upper) {
  if (n == 0) return upper ? 1.0 : 0.0;
  if (upper && k >= n) return 1.0;
  if (!upper && k == 0) return 0.0;
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    // P(X ≤ k) falls as p grows; P(X ≥ k) = 1 − P(X ≤ k − 1) rises.
    const double value = upper ? binomialCdf(k, n, mid) : 1.0 - binomialCdf(k - 1, n, mid);
    if (upper ? value > tail : value < tail)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

// One-sided 95 % upper bound (0 of 300 gives 1.0 %).
inline double clopperPearsonUpper95(std::size_t k, std::size_t n) { return clopperPearsonBound(k, n, 0.05, true); }

// Two-sided 95 % interval.
struct ProportionInterval {
  double lo = 0.0, hi = 1.0;
};
inline ProportionInterval clopperPearson95(std::size_t k, std::size_t n) {
  return {clopperPearsonBound(k, n, 0.025, false), clopperPearsonBound(k, n, 0.025, true)};
}

}  // namespace gyrod::bench
