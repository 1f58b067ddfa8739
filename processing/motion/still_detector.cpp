#include "processing/motion/still_detector.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "processing/base/distributions.hpp"

namespace gyrod::processing {
namespace {

// D ≈ g·χ²(h) for white noise (header): g = 3/2, h = 2(W − 1)/3.
constexpr double kDifferenceScale = 1.5;
double differenceDof(std::size_t window) { return 2.0 * static_cast<double>(window - 1) / 3.0; }

void requirePositiveLevel(double v, const std::string& what) {
  if (!std::isfinite(v) || !(v > 0.0))
    throw std::invalid_argument(what + " must be finite and > 0, got " + std::to_string(v));
}

}  // namespace

StillNoiseLevel stillNoiseLevelFromTerms(const NoiseTerms& terms, double rate_hz, std::size_t window_samples) {
  if (!std::isfinite(rate_hz) || !(rate_hz > 0.0))
    throw std::invalid_argument("rate_hz must be finite and > 0, got " + std::to_string(rate_hz));
  const double tau0 = 1.0 / rate_hz;
  return {allanVarianceOfTerms(terms, static_cast<double>(window_samples) * tau0), allanVarianceOfTerms(terms, tau0)};
}

StillDetector::StillDetector(const StillDetectorParameters& params,
                             const std::array<StillNoiseLevel, kMotionAxes>& levels)
    : params_(params), levels_(levels) {
  if (params_.window_samples < 3)
    throw std::invalid_argument("still.window_samples must be >= 3, got " + std::to_string(params_.window_samples));
  if (!std::isfinite(params_.mean_threshold_sigmas) || !(params_.mean_threshold_sigmas > 0.0))
    throw std::invalid_argument("still.mean_threshold_sigmas must be finite and > 0, got " +
                                std::to_string(params_.mean_threshold_sigmas));
  if (!(params_.difference_false_alarm > 0.0 && params_.difference_false_alarm < 1.0))
    throw std::invalid_argument("still.difference_false_alarm must be in (0, 1), got " +
                                std::to_string(params_.difference_false_alarm));
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    const std::string axis = std::string("axis ") + "xyz"[a] + ": ";
    requirePositiveLevel(levels_[a].window_allan_variance, axis + "window_allan_variance");
    requirePositiveLevel(levels_[a].sample_allan_variance, axis + "sample_allan_variance");
  }
  difference_threshold_ =
      kDifferenceScale * chiSquareQuantile(1.0 - params_.difference_false_alarm, differenceDof(params_.window_samples));
  ring_.assign(kMotionAxes * params_.window_samples, 0.0);
  if (params_.accel_window_samples < 3)
    throw std::invalid_argument("still.accel_window_samples must be >= 3, got " +
                                std::to_string(params_.accel_window_samples));
  requirePositiveLevel(params_.accel_noise_g, "still.accel_noise_g");
  const auto wa = static_cast<double>(params_.accel_window_samples);
  accel_difference_threshold_ = kDifferenceScale * chiSquareQuantile(1.0 - params_.difference_false_alarm,
                                                                     differenceDof(params_.accel_window_samples));
  accel_slope_bound_ = params_.mean_threshold_sigmas * params_.accel_noise_g / std::sqrt(wa * (wa * wa - 1.0) / 12.0);
  accel_ring_.assign(kMotionAxes * params_.accel_window_samples, 0.0);
}

void StillDetector::observeAccel(const std::array<double, kMotionAxes>& accel_g) {
  const bool finite = std::isfinite(accel_g[0]) && std::isfinite(accel_g[1]) && std::isfinite(accel_g[2]);
  if (!finite) {
    accel_present_ = false;
    accel_next_ = accel_filled_ = 0;
    return;
  }
  accel_present_ = true;
  const std::size_t wa = params_.accel_window_samples;
  for (std::size_t a = 0; a < kMotionAxes; ++a) accel_ring_[a * wa + accel_next_] = accel_g[a];
  accel_next_ = (accel_next_ + 1) % wa;
  if (accel_filled_ < wa) ++accel_filled_;
}

bool StillDetector::accelSteady() const {
  const std::size_t wa = params_.accel_window_samples;
  if (!accel_present_ || accel_filled_ < wa) return false;
  // Recomputed over the ring each time (O(Wa), no running sums to drift): the slope about the
  // window's centre k̄ = (Wa − 1)/2, and the sum of squared differences, oldest first.
  const double centre = 0.5 * static_cast<double>(wa - 1);
  const double s = static_cast<double>(wa) * (static_cast<double>(wa) * static_cast<double>(wa) - 1.0) / 12.0;
  const double two_var = 2.0 * params_.accel_noise_g * params_.accel_noise_g;
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    const double* ring = &accel_ring_[a * wa];
    double weighted = 0.0, diff = 0.0, previous = 0.0;
    for (std::size_t i = 0; i < wa; ++i) {
      const double v = ring[(accel_next_ + i) % wa];
      weighted += (static_cast<double>(i) - centre) * v;
      if (i > 0) diff += (v - previous) * (v - previous);
      previous = v;
    }
    if (std::fabs(weighted / s) > accel_slope_bound_ || diff / two_var > accel_difference_threshold_) return false;
  }
  return true;
}

void StillDetector::reset() {
  accel_next_ = accel_filled_ = 0;
  accel_present_ = false;
  next_slot_ = filled_ = still_run_ = 0;
  still_ = false;
  sum_ = diff_sq_sum_ = last_ = {};
}

void StillDetector::recomputeSums() {
  const std::size_t w = params_.window_samples;
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    const double* ring = &ring_[a * w];
    double sum = 0.0, diff = 0.0;
    for (std::size_t i = 0; i < filled_; ++i) {
      const std::size_t slot = (next_slot_ + w - filled_ + i) % w;  // oldest first
      sum += ring[slot];
      if (i > 0) {
        const double d = ring[slot] - ring[(slot + w - 1) % w];
        diff += d * d;
      }
    }
    sum_[a] = sum;
    diff_sq_sum_[a] = diff;
  }
}

bool StillDetector::update(const AngularRate& corrected, const AngularRate& expected,
                           const AngularRate& expected_variance) {
  const std::size_t w = params_.window_samples;
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    double* ring = &ring_[a * w];
    if (filled_ == w) {  // the oldest sample and its difference leave the window
      const double oldest = ring[next_slot_];
      const double d = ring[(next_slot_ + 1) % w] - oldest;
      sum_[a] -= oldest;
      diff_sq_sum_[a] -= d * d;
    }
    if (filled_ > 0) {
      const double d = corrected[a] - last_[a];
      diff_sq_sum_[a] += d * d;
    }
    ring[next_slot_] = corrected[a];
    sum_[a] += corrected[a];
    last_[a] = corrected[a];
  }
  next_slot_ = (next_slot_ + 1) % w;
  if (filled_ < w) ++filled_;
  if (next_slot_ == 0) recomputeSums();

  bool still = filled_ == w;
  for (std::size_t a = 0; a < kMotionAxes && still; ++a) {
    const double mean = sum_[a] / static_cast<double>(w);
    const double spread = std::sqrt(levels_[a].window_allan_variance + expected_variance[a]);
    const double d_statistic = diff_sq_sum_[a] / (2.0 * levels_[a].sample_allan_variance);
    still =
        std::fabs(mean - expected[a]) <= params_.mean_threshold_sigmas * spread && d_statistic <= difference_threshold_;
  }
  if (still && accel_present_) still = accelSteady();
  still_ = still;
  still_run_ = still ? still_run_ + 1 : 0;
  return still;
}

double StillDetector::windowMean(std::size_t axis) const {
  return filled_ == 0 ? 0.0 : sum_.at(axis) / static_cast<double>(filled_);
}

double StillDetector::falseMovingProbabilityPerAxis() const {
  const double alpha_mean = 2.0 * (1.0 - normalCdf(params_.mean_threshold_sigmas));
  const double alpha_diff = params_.difference_false_alarm;
  return alpha_mean + alpha_diff - alpha_mean * alpha_diff;
}

double StillDetector::falseMovingProbability() const {
  return 1.0 - std::pow(1.0 - falseMovingProbabilityPerAxis(), static_cast<double>(kMotionAxes));
}

double StillDetector::falseStillProbability(std::size_t axis, double offset_dps, double expected_variance) const {
  const double z = params_.mean_threshold_sigmas;
  const double s = std::sqrt(levels_.at(axis).window_allan_variance + expected_variance);
  const double mean_passes = normalCdf(z - offset_dps / s) - normalCdf(-z - offset_dps / s);
  const double other_axes = std::pow(1.0 - falseMovingProbabilityPerAxis(), static_cast<double>(kMotionAxes - 1));
  return mean_passes * (1.0 - params_.difference_false_alarm) * other_axes;
}

}  // namespace gyrod::processing
