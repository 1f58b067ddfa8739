#include "processing/simulation/narrowband_line.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "processing/base/portable_math.hpp"
#include "processing/simulation/motion_profile.hpp"

namespace gyrod::processing {
namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

}  // namespace

double ar2StationaryVariancePerDrive(double a1, double a2) {
  return (1.0 - a2) / ((1.0 + a2) * ((1.0 - a2) * (1.0 - a2) - a1 * a1));
}

NarrowbandLineRecursion narrowbandLineRecursion(const NarrowbandLine& line, double rate_hz) {
  if (!(std::isfinite(rate_hz) && rate_hz > 0.0))
    throw std::invalid_argument("narrowband line: rate must be finite and > 0, got " + number(rate_hz));
  if (!(std::isfinite(line.centre_hz) && line.centre_hz > 0.0 && line.centre_hz < rate_hz / 2.0))
    throw std::invalid_argument("narrowband line: centre_hz must be in (0, rate/2 = " + number(rate_hz / 2.0) +
                                "), got " + number(line.centre_hz));
  if (!(std::isfinite(line.width_hz) && line.width_hz > 0.0))
    throw std::invalid_argument("narrowband line: width_hz must be finite and > 0, got " + number(line.width_hz));
  if (!(std::isfinite(line.rms_dps) && line.rms_dps >= 0.0))
    throw std::invalid_argument("narrowband line: rms_dps must be finite and >= 0, got " + number(line.rms_dps));
  // portable::exp and the sine of cycles: the simulator's stream is the same bits everywhere.
  const double r = portable::exp(-std::numbers::pi * line.width_hz / rate_hz);
  NarrowbandLineRecursion out;
  out.a1 = 2.0 * r * portableSinOfCycles(line.centre_hz / rate_hz + 0.25);
  out.a2 = -r * r;
  out.drive_var = line.rms_dps * line.rms_dps / ar2StationaryVariancePerDrive(out.a1, out.a2);
  return out;
}

double narrowbandLinePsd(const NarrowbandLineRecursion& line, double rate_hz, double freq_hz) {
  const double w = 2.0 * std::numbers::pi * freq_hz / rate_hz;
  const double re = 1.0 - line.a1 * std::cos(w) - line.a2 * std::cos(2.0 * w);
  const double im = line.a1 * std::sin(w) + line.a2 * std::sin(2.0 * w);
  return 2.0 * line.drive_var / rate_hz / (re * re + im * im);
}

}  // namespace gyrod::processing
