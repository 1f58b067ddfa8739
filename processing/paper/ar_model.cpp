#include "processing/paper/ar_model.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace gyrod::processing {

namespace {
// A sample's value as a user would write it (std::to_string would show 0.000000 for 1e-9).
std::string formatValue(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}
}  // namespace

std::vector<double> autocovariance(std::span<const double> x, std::size_t max_lag) {
  if (max_lag >= x.size())
    throw std::invalid_argument("the autocovariance at lag " + std::to_string(max_lag) + " needs more than " +
                                std::to_string(max_lag) + " samples, got " + std::to_string(x.size()));
  double mean = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]))
      throw std::invalid_argument("the autocovariance cannot use sample " + std::to_string(i) + ": it is not finite");
    mean += x[i];
  }
  const double n = static_cast<double>(x.size());
  mean /= n;
  // Divisor N at every lag (the biased estimator): it keeps the Toeplitz matrix positive
  // definite, so Levinson–Durbin gives |κ| < 1 and a stationary model.
  std::vector<double> gamma(max_lag + 1, 0.0);
  for (std::size_t k = 0; k <= max_lag; ++k) {
    double s = 0.0;
    for (std::size_t i = 0; i + k < x.size(); ++i) s += (x[i] - mean) * (x[i + k] - mean);
    gamma[k] = s / n;
  }
  return gamma;
}

std::vector<ArModel> yuleWalker(std::span<const double> x, std::size_t max_order) {
  if (max_order == 0) throw std::invalid_argument("the AR model fit needs a maximum order of at least 1, got 0");
  if (x.size() <= max_order)
    throw std::invalid_argument("the AR model fit of order " + std::to_string(max_order) + " needs more than " +
                                std::to_string(max_order) + " samples, got " + std::to_string(x.size()));
  const std::vector<double> gamma = autocovariance(x, max_order);
  if (!(gamma[0] > 0.0))
    throw std::invalid_argument("the AR model fit needs a series that varies; this one is constant (all " +
                                std::to_string(x.size()) + " values are " + formatValue(x.front()) + ")");
  const double n = static_cast<double>(x.size());

  // Levinson–Durbin: from the order-(k−1) solution φ^(k−1) and σ²_(k−1),
  //   κk = (γk − Σ_{j<k} φj^(k−1) γ(k−j)) / σ²_(k−1),
  //   φj^(k) = φj^(k−1) − κk φ_(k−j)^(k−1),  φk^(k) = κk,  σ²_k = σ²_(k−1) (1 − κk²).
  std::vector<ArModel> models;
  models.reserve(max_order);
  std::vector<double> phi;
  std::vector<double> previous;
  double sigma2 = gamma[0];
  // Γp for the standard errors: the Toeplitz matrix of γ(0..p−1).
  Eigen::MatrixXd toeplitz(max_order, max_order);
  for (std::size_t i = 0; i < max_order; ++i)
    for (std::size_t j = 0; j < max_order; ++j)
      toeplitz(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = gamma[i > j ? i - j : j - i];

  for (std::size_t k = 1; k <= max_order; ++k) {
    double acc = gamma[k];
    for (std::size_t j = 1; j < k; ++j) acc -= phi[j - 1] * gamma[k - j];
    const double kappa = acc / sigma2;
    previous = phi;
    phi.push_back(kappa);
    for (std::size_t j = 1; j < k; ++j) phi[j - 1] = previous[j - 1] - kappa * previous[k - j - 1];
    sigma2 *= (1.0 - kappa * kappa);
    if (!(sigma2 > 0.0))
      throw std::invalid_argument("the AR model fit found the series perfectly predictable at order " +
                                  std::to_string(k) + " (innovation variance " + std::to_string(sigma2) + ")");

    ArModel m;
    m.phi = phi;
    m.noise_var = sigma2;
    m.reflection = kappa;
    m.aic = n * std::log(sigma2) + 2.0 * static_cast<double>(k);
    m.bic = n * std::log(sigma2) + static_cast<double>(k) * std::log(n);
    // Asymptotic covariance of √N(φ̂ − φ) is σa² Γp⁻¹ (Brockwell & Davis, Time Series: Theory and Methods, §8.1).
    const auto kk = static_cast<Eigen::Index>(k);
    const Eigen::MatrixXd gamma_inv = toeplitz.topLeftCorner(kk, kk).ldlt().solve(Eigen::MatrixXd::Identity(kk, kk));
    m.phi_std_error.resize(k);
    for (std::size_t j = 0; j < k; ++j) {
      const auto jj = static_cast<Eigen::Index>(j);
      m.phi_std_error[j] = std::sqrt(sigma2 * gamma_inv(jj, jj) / n);
    }
    models.push_back(std::move(m));
  }
  return models;
}

namespace {
template <typename Criterion>
std::size_t orderMinimising(std::span<const ArModel> models, Criterion criterion, const char* who) {
  if (models.empty()) throw std::invalid_argument(std::string(who) + " needs at least one AR model; none given");
  std::size_t best = 0;
  for (std::size_t i = 1; i < models.size(); ++i)
    if (criterion(models[i]) < criterion(models[best])) best = i;
  return models[best].order();
}
}  // namespace

std::size_t orderByAic(std::span<const ArModel> models) {
  return orderMinimising(
      models, [](const ArModel& m) { return m.aic; }, "choosing the AR order by AIC");
}

std::size_t orderByBic(std::span<const ArModel> models) {
  return orderMinimising(
      models, [](const ArModel& m) { return m.bic; }, "choosing the AR order by BIC");
}

}  // namespace gyrod::processing
