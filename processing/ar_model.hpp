#pragma once
// AR(p) model x_k = φ1·x_{k−1} + … + φp·x_{k−p} + a_k, a ~ N(0, σa²) (paper eq. 5),
// estimated by Yule–Walker (biased autocovariance) solved by Levinson–Durbin.
// AIC(p) = N·ln σa² + 2p (paper eq. 6); BIC(p) = N·ln σa² + p·ln N.
#include <cstddef>
#include <span>
#include <vector>

namespace gyrod::processing {

struct ArModel {
  std::vector<double> phi;          // φ1..φp
  std::vector<double> phi_std_error;  // asymptotic standard errors of φ
  double noise_var = 0.0;           // σa²
  double aic = 0.0;
  double bic = 0.0;
  std::size_t order() const { return phi.size(); }
};

// Biased sample autocovariance γ(0..max_lag) of x after removing its mean.
std::vector<double> autocovariance(std::span<const double> x, std::size_t max_lag);

// Models of order 1..max_order from one Levinson–Durbin recursion.
// Throws std::invalid_argument if x has ≤ max_order samples or zero variance.
std::vector<ArModel> yuleWalker(std::span<const double> x, std::size_t max_order);

// Order (1-based) with the smallest AIC / BIC among `models`.
std::size_t orderByAic(std::span<const ArModel> models);
std::size_t orderByBic(std::span<const ArModel> models);

}  // namespace gyrod::processing
