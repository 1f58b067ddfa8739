// Bias against temperature from block means; see temperature_bias_fit.hpp.
#include "processing/motion/temperature_bias_fit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "processing/base/golden_section.hpp"

namespace gyrod::processing {
namespace {

struct Blocks {
  std::vector<double> t, rate, temp, weight;  // means (t from the first sample) and sample counts
};

Blocks blockMeans(std::span<const double> secs, std::span<const double> rate, std::span<const double> temp,
                  double block_s) {
  Blocks b;
  const double t0 = secs.front();
  std::size_t current = 0;
  double st = 0.0, sr = 0.0, sT = 0.0, n = 0.0;
  const auto flush = [&] {
    if (n == 0.0) return;
    b.t.push_back(st / n);
    b.rate.push_back(sr / n);
    b.temp.push_back(sT / n);
    b.weight.push_back(n);
    st = sr = sT = n = 0.0;
  };
  for (std::size_t i = 0; i < secs.size(); ++i) {
    const auto index = static_cast<std::size_t>(std::floor((secs[i] - t0) / block_s));
    if (index != current) {
      flush();
      current = index;
    }
    st += secs[i] - t0;
    sr += rate[i];
    sT += temp[i];
    n += 1.0;
  }
  flush();
  return b;
}

struct WeightedFit {
  Eigen::VectorXd beta;
  Eigen::MatrixXd covariance;
  double rho = 0.0;
};

// Weighted least squares of y on the columns of X with the residual-correlation scaling of
// the header; the covariance is infinite along a direction X does not determine.
WeightedFit weightedLeastSquares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const Eigen::VectorXd& w) {
  const Eigen::Index n = x.rows(), p = x.cols();
  const Eigen::VectorXd sw = w.array().sqrt();
  const Eigen::MatrixXd xs = sw.asDiagonal() * x;
  const Eigen::VectorXd ys = sw.asDiagonal() * y;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(xs, Eigen::ComputeThinU | Eigen::ComputeThinV);
  WeightedFit f;
  f.beta = svd.solve(ys);
  const Eigen::VectorXd e = y - x * f.beta;
  const double sigma2 = (sw.asDiagonal() * e).squaredNorm() / static_cast<double>(n - p);
  double num = 0.0, den = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    den += e(i) * e(i);
    if (i > 0) num += e(i) * e(i - 1);
  }
  f.rho = den > 0.0 ? std::clamp(num / den, 0.0, 0.95) : 0.0;
  const Eigen::VectorXd& s = svd.singularValues();
  Eigen::VectorXd inv_s2(p);
  for (Eigen::Index j = 0; j < p; ++j)
    inv_s2(j) = s(j) > 1e-12 * s(0) ? 1.0 / (s(j) * s(j)) : std::numeric_limits<double>::infinity();
  const Eigen::MatrixXd& v = svd.matrixV();
  f.covariance = Eigen::MatrixXd::Zero(p, p);
  for (Eigen::Index j = 0; j < p; ++j) {
    if (!std::isfinite(inv_s2(j))) {
      f.covariance.diagonal().setConstant(std::numeric_limits<double>::infinity());
      break;
    }
    f.covariance += inv_s2(j) * v.col(j) * v.col(j).transpose();
  }
  f.covariance *= sigma2 * (1.0 + f.rho) / (1.0 - f.rho);
  return f;
}

}  // namespace

TemperatureBiasFit fitTemperatureBias(std::span<const double> secs, std::span<const double> rate_dps,
                                      std::span<const double> temp_c, double block_s) {
  if (secs.size() != rate_dps.size() || secs.size() != temp_c.size())
    throw std::invalid_argument("the temperature bias fit needs as many times as rates and temperatures; there are " +
                                std::to_string(secs.size()) + " times, " + std::to_string(rate_dps.size()) +
                                " rates and " + std::to_string(temp_c.size()) + " temperatures");
  if (!(std::isfinite(block_s) && block_s > 0.0))
    throw std::invalid_argument("the temperature bias fit needs a block length > 0 s, got " + std::to_string(block_s));
  for (std::size_t i = 0; i < secs.size(); ++i) {
    if (!std::isfinite(secs[i]) || !std::isfinite(rate_dps[i]) || !std::isfinite(temp_c[i]))
      throw std::invalid_argument("the temperature bias fit cannot use sample " + std::to_string(i) +
                                  ": it is not finite");
    if (i > 0 && secs[i] < secs[i - 1])
      throw std::invalid_argument(
          "the temperature bias fit needs times that do not decrease; the time decreases at sample " +
          std::to_string(i));
  }
  constexpr std::size_t kMinimumBlocks = 8;
  const Blocks b = secs.empty() ? Blocks{} : blockMeans(secs, rate_dps, temp_c, block_s);
  const std::size_t nb = b.t.size();
  if (nb < kMinimumBlocks)
    throw std::invalid_argument("the temperature bias fit has " + std::to_string(nb) + " blocks of " +
                                std::to_string(block_s) + " s, need at least " + std::to_string(kMinimumBlocks));
  const auto rows = static_cast<Eigen::Index>(nb);
  const Eigen::Map<const Eigen::VectorXd> y(b.rate.data(), rows), w(b.weight.data(), rows), temp(b.temp.data(), rows);
  TemperatureBiasFit out;
  out.blocks = nb;
  out.reference_c = w.dot(temp) / w.sum();
  const Eigen::VectorXd dt = temp.array() - out.reference_c;
  out.temperature_spread_c = std::sqrt(w.dot(dt.cwiseProduct(dt)) / w.sum());
  const bool with_temperature = out.temperature_spread_c >= kMinimumTemperatureSpreadC;

  Eigen::MatrixXd x(rows, with_temperature ? 2 : 1);
  x.col(0).setOnes();
  if (with_temperature) x.col(1) = dt;
  WeightedFit linear = weightedLeastSquares(x, y, w);

  // The warm-up shape: τ minimising the weighted residual of the joint fit (a log-spaced scan,
  // then golden section within one step of the best), then A's significance at that τ.
  const auto withShape = [&](double log_tau) {
    Eigen::MatrixXd xe(rows, x.cols() + 1);
    xe.leftCols(x.cols()) = x;
    for (Eigen::Index i = 0; i < rows; ++i) xe(i, x.cols()) = std::exp(-b.t[i] / std::exp(log_tau));
    return std::pair{xe, weightedLeastSquares(xe, y, w)};
  };
  const auto sse = [&](double log_tau) {
    const auto [xe, f] = withShape(log_tau);
    const Eigen::VectorXd e = y - xe * f.beta;
    return w.dot(e.cwiseProduct(e));
  };
  const double duration = b.t.back() - b.t.front();
  const double lo = std::log(duration / 100.0), hi = std::log(duration / 3.0);
  constexpr int kScan = 25;
  const double step = (hi - lo) / (kScan - 1);
  int best = 0;
  double best_sse = std::numeric_limits<double>::infinity();
  for (int j = 0; with_temperature && j < kScan; ++j) {
    const double v = sse(lo + step * j);
    if (v < best_sse) {
      best_sse = v;
      best = j;
    }
  }
  WeightedFit chosen = linear;
  if (with_temperature && std::isfinite(best_sse)) {
    const double log_tau = goldenSectionMinimum(lo + step * std::max(best - 1, 0),
                                                lo + step * std::min(best + 1, kScan - 1), {30, 0.0}, sse)
                               .midpoint();
    const WeightedFit with_shape = withShape(log_tau).second;
    const Eigen::Index a = x.cols();
    const double amplitude_std = std::sqrt(with_shape.covariance(a, a));
    if (std::isfinite(amplitude_std) && std::fabs(with_shape.beta(a)) > kWarmUpShapeSignificance * amplitude_std) {
      chosen = with_shape;
      out.warm_up_amplitude_dps = with_shape.beta(a);
      out.warm_up_amplitude_std_dps = amplitude_std;
      out.warm_up_time_constant_s = std::exp(log_tau);
    }
  }
  out.bias_dps = chosen.beta(0);
  out.bias_std_dps = std::sqrt(chosen.covariance(0, 0));
  if (with_temperature) {
    out.coefficient_dps_per_c = chosen.beta(1);
    out.coefficient_std_dps_per_c = std::sqrt(chosen.covariance(1, 1));
  }
  out.residual_correlation = chosen.rho;
  return out;
}

}  // namespace gyrod::processing
