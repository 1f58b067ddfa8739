#include "processing/simulation/sensor_model.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "processing/base/portable_math.hpp"

namespace gyrod::processing {
namespace {

// Register map rev 4.2, CONFIG (0x1A): gyroscope columns of the DLPF_CFG table.
constexpr std::array<DlpfSetting, 7> kDlpfTable = {{
    {0, 256.0, 0.98, 8000.0},
    {1, 188.0, 1.9, 1000.0},
    {2, 98.0, 2.8, 1000.0},
    {3, 42.0, 4.8, 1000.0},
    {4, 20.0, 8.3, 1000.0},
    {5, 10.0, 13.4, 1000.0},
    {6, 5.0, 18.6, 1000.0},
}};

}  // namespace

const DlpfSetting& dlpfSetting(int cfg) {
  if (cfg < 0 || cfg > 6)
    throw std::invalid_argument("DLPF_CFG must be 0..6 (7 is reserved), got " + std::to_string(cfg));
  return kDlpfTable[static_cast<std::size_t>(cfg)];
}

DigitalLowPassFilter::DigitalLowPassFilter(int cfg) : setting_(&dlpfSetting(cfg)) {
  // One section: bilinear transform of K/(s + K) with s = (1 − z⁻¹)/(1 + z⁻¹) (the
  // prewarped frequency axis Ω = tan(πf/fs)), giving
  //   H1(z) = g·(1 + z⁻¹)/(1 + p·z⁻¹),  g = K/(1 + K),  p = (K − 1)/(K + 1),
  // |H1|² = 1/(1 + (tan(πf/fs)/K)²). Two sections give |H|² = 1/2 at the bandwidth f_c
  // when tan(πf_c/fs)/K = √(√2 − 1). portable::tan keeps the coefficients (and hence the
  // simulator's stream) bit-identical across machines.
  const double fs = setting_->internal_rate_hz;
  const double k = portable::tan(std::numbers::pi * setting_->bandwidth_hz / fs) / std::sqrt(std::sqrt(2.0) - 1.0);
  const double g = k / (1.0 + k);
  const double p = (k - 1.0) / (k + 1.0);
  b0_ = g * g;
  b1_ = 2.0 * g * g;
  b2_ = g * g;
  a1_ = 2.0 * p;
  a2_ = p * p;
}

double DigitalLowPassFilter::update(double x) {
  const double y = b0_ * x + b1_ * x1_ + b2_ * x2_ - a1_ * y1_ - a2_ * y2_;
  x2_ = x1_;
  x1_ = x;
  y2_ = y1_;
  y1_ = y;
  return y;
}

void DigitalLowPassFilter::reset(double value) {
  // The DC gain is 1 (up to rounding), so a constant input `value` has output `value`.
  x1_ = x2_ = y1_ = y2_ = value;
}

std::complex<double> DigitalLowPassFilter::frequencyResponse(double f_hz) const {
  const double w = 2.0 * std::numbers::pi * f_hz / setting_->internal_rate_hz;
  const std::complex<double> z1 = std::polar(1.0, -w);  // z⁻¹ on the unit circle
  const std::complex<double> z2 = z1 * z1;
  return (b0_ + b1_ * z1 + b2_ * z2) / (1.0 + a1_ * z1 + a2_ * z2);
}

double DigitalLowPassFilter::groupDelayAtDc() const {
  // τg(0) = Σ n·bₙ/Σ bₙ − Σ n·aₙ/Σ aₙ samples (derivative of the phase at ω = 0).
  const double numerator = (b1_ + 2.0 * b2_) / (b0_ + b1_ + b2_);
  const double denominator = (a1_ + 2.0 * a2_) / (1.0 + a1_ + a2_);
  return (numerator - denominator) / setting_->internal_rate_hz;
}

double gyroSensitivityLsbPerDps(int fs_sel) {
  // Register map rev 4.2 §4.19 (GYRO_XOUT…): FS_SEL → LSB per °/s.
  constexpr std::array<double, 4> kSensitivity = {131.0, 65.5, 32.8, 16.4};
  if (fs_sel < 0 || fs_sel > 3) throw std::invalid_argument("FS_SEL must be 0..3, got " + std::to_string(fs_sel));
  return kSensitivity[static_cast<std::size_t>(fs_sel)];
}

std::int16_t quantizeToInt16(double value, double lsb_per_unit) {
  if (!(lsb_per_unit > 0.0) || !std::isfinite(lsb_per_unit))
    throw std::invalid_argument("the sensor model needs a scale (LSB per unit) that is finite and > 0, got " +
                                std::to_string(lsb_per_unit));
  if (std::isnan(value)) return 0;
  const double counts = std::round(value * lsb_per_unit);  // ±inf stays ±inf
  if (counts >= 32767.0) return 32767;
  if (counts <= -32768.0) return -32768;
  return static_cast<std::int16_t>(counts);
}

}  // namespace gyrod::processing
