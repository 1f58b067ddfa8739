// Detectors that know the effect's form; see known_form_detectors.hpp.
#include "processing/model_check/known_form_detectors.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "processing/model_check/detail.hpp"
#include "processing/model_check/model_check.hpp"

namespace gyrod::processing {
namespace {

using model_check_detail::blockMeans;
using model_check_detail::removeLineInPlace;

}  // namespace

std::vector<double> knownStepDifferences(std::span<const double> x, std::size_t step_sample, std::size_t block) {
  if (block == 0) throw std::invalid_argument("the step detector needs a block length of at least 1 sample, got 0");
  if (step_sample == 0 || step_sample >= x.size())
    throw std::invalid_argument("the step detector's step at sample " + std::to_string(step_sample) +
                                " is not inside the series of " + std::to_string(x.size()));
  std::vector<double> y = blockMeans(x, block);
  if (y.size() < 4)
    throw std::invalid_argument("the step detector needs at least 4 blocks, got " + std::to_string(y.size()));
  std::vector<double> prefix(y.size() + 1, 0.0);
  for (std::size_t i = 0; i < y.size(); ++i) prefix[i + 1] = prefix[i] + y[i];
  // The boundary nearest the step: the step is between blocks at−1 and at.
  const std::size_t at = std::clamp<std::size_t>((step_sample + block / 2) / block, 1, y.size() - 1);
  std::vector<double> d;
  for (std::size_t w = 1; w <= at && at + w <= y.size(); w *= 2)
    d.push_back(((prefix[at + w] - prefix[at]) - (prefix[at] - prefix[at - w])) / static_cast<double>(w));
  return d;
}

double knownStepStatistic(std::span<const double> differences, std::span<const double> clean_sd) {
  double best = 0.0;
  for (std::size_t j = 0; j < differences.size() && j < clean_sd.size(); ++j)
    if (clean_sd[j] > 0.0) best = std::max(best, std::fabs(differences[j]) / clean_sd[j]);
  return best;
}

double knownSinusoidStatistic(std::span<const double> x, double rate_hz, double freq_hz) {
  if (x.size() < 4)
    throw std::invalid_argument("the sinusoid detector needs at least 4 samples, got " + std::to_string(x.size()));
  if (!(freq_hz > 0.0 && freq_hz < rate_hz / 2.0))
    throw std::invalid_argument("the sinusoid detector's frequency " + std::to_string(freq_hz) +
                                " Hz is not inside (0, rate/2)");
  std::vector<double> y(x.begin(), x.end());
  removeLineInPlace(y);
  double ss = 0.0;
  for (double v : y) ss += v * v;
  const double n = static_cast<double>(y.size());
  const double var = ss / n;
  const SinusoidFit fit = fitSinusoidAt(y, rate_hz, freq_hz);
  return var > 0.0 ? n * fit.amp_dps * fit.amp_dps / (2.0 * var) : 0.0;
}

double knownTemperatureStatistic(std::span<const double> x, std::span<const double> temperature_c, std::size_t block) {
  if (x.size() != temperature_c.size())
    throw std::invalid_argument("the temperature detector has " + std::to_string(temperature_c.size()) +
                                " temperatures for " + std::to_string(x.size()) + " samples");
  if (block == 0)
    throw std::invalid_argument("the temperature detector needs a block length of at least 1 sample, got 0");
  std::vector<double> y = blockMeans(x, block), tb = blockMeans(temperature_c, block);
  if (y.size() < 8)
    throw std::invalid_argument("the temperature detector needs at least 8 blocks, got " + std::to_string(y.size()));
  removeLineInPlace(y);
  removeLineInPlace(tb);
  double stt = 0.0, sty = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    stt += tb[i] * tb[i];
    sty += tb[i] * y[i];
  }
  if (!(stt > 0.0))
    throw std::invalid_argument("the temperature detector needs a temperature that changes; this one does not move");
  const double k = sty / stt;
  double rss = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) rss += (y[i] - k * tb[i]) * (y[i] - k * tb[i]);
  const double dof = static_cast<double>(y.size()) - 3.0;  // constant, line, slope
  const double se = std::sqrt(rss / dof / stt);
  return se > 0.0 ? std::fabs(k) / se : 0.0;
}

double spectralScoreStatistic(std::span<const double> power, std::span<const double> base_power,
                              std::span<const double> shape) {
  if (power.size() != base_power.size() || power.size() != shape.size())
    throw std::invalid_argument("the spectral detector needs the same frequency bins in the power, base and shape");
  double num = 0.0, norm = 0.0;
  for (std::size_t k = 0; k < power.size(); ++k) {
    if (!(base_power[k] > 0.0)) continue;
    const double w = shape[k] / base_power[k];
    num += w * (power[k] / base_power[k] - 1.0);
    norm += w * w;
  }
  if (!(norm > 0.0)) throw std::invalid_argument("the spectral detector has no usable frequency bin");
  return num / std::sqrt(norm);
}

std::vector<double> gaussMarkovSpectralShape(double correlation_time_s, double rate_hz, std::size_t nfft) {
  if (!(correlation_time_s > 0.0 && rate_hz > 0.0) || nfft < 2)
    throw std::invalid_argument(
        "the Gauss-Markov spectrum needs a correlation time T and a rate > 0 and at least 2 FFT points");
  const double rho = std::exp(-1.0 / (rate_hz * correlation_time_s));
  std::vector<double> s(nfft / 2 + 1);
  for (std::size_t k = 0; k < s.size(); ++k) {
    const double c = std::cos(2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(nfft));
    s[k] = (1.0 - rho * rho) / (1.0 - 2.0 * rho * c + rho * rho);
  }
  return s;
}

double calibratedThreshold(std::vector<double> clean_values, double false_alarm) {
  if (clean_values.empty())
    throw std::invalid_argument("the detector threshold needs detector values from clean replicas; there are none");
  if (!(false_alarm > 0.0 && false_alarm < 1.0))
    throw std::invalid_argument("the detector threshold's false alarm rate " + std::to_string(false_alarm) +
                                " is not inside (0, 1)");
  std::sort(clean_values.begin(), clean_values.end());
  return model_check_detail::sortedQuantile(clean_values, 1.0 - false_alarm);
}

}  // namespace gyrod::processing
