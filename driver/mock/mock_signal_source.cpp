#include "driver/mock/mock_signal_source.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace gyrod::driver {
namespace {

void requireFinite(double v, const std::string& what) {
  if (!std::isfinite(v)) throw std::invalid_argument(what + " must be finite, got " + std::to_string(v));
}

}  // namespace

ConstantSource::ConstantSource(std::array<double, 3> rate_dps, double temperature_c) {
  for (int i = 0; i < 3; ++i) requireFinite(rate_dps[i], "ConstantSource rate_dps[" + std::to_string(i) + "]");
  requireFinite(temperature_c, "ConstantSource temperature_c");
  value_.rate_dps = rate_dps;
  value_.temperature_c = temperature_c;
}

AnalogSample ConstantSource::nextTick(double) { return value_; }

SinusoidSource::SinusoidSource(std::array<SinusoidAxis, 3> axes, double temperature_c)
    : axes_(axes), temperature_c_(temperature_c) {
  for (int i = 0; i < 3; ++i) {
    const std::string axis = "SinusoidSource axis " + std::to_string(i);
    requireFinite(axes[i].offset_dps, axis + " offset_dps");
    requireFinite(axes[i].amplitude_dps, axis + " amplitude_dps");
    requireFinite(axes[i].frequency_hz, axis + " frequency_hz");
    requireFinite(axes[i].phase_rad, axis + " phase_rad");
    if (axes[i].frequency_hz < 0.0) {
      throw std::invalid_argument(axis + " frequency_hz must be >= 0, got " + std::to_string(axes[i].frequency_hz));
    }
  }
  requireFinite(temperature_c, "SinusoidSource temperature_c");
}

AnalogSample SinusoidSource::nextTick(double t_s) {
  AnalogSample s;
  for (int i = 0; i < 3; ++i) {
    const SinusoidAxis& a = axes_[i];
    s.rate_dps[i] =
        a.offset_dps + a.amplitude_dps * std::sin(2.0 * std::numbers::pi * a.frequency_hz * t_s + a.phase_rad);
  }
  s.temperature_c = temperature_c_;
  return s;
}

ReplaySource::ReplaySource(std::vector<double> x_dps, std::vector<double> y_dps, std::vector<double> z_dps,
                           std::vector<double> temperature_c, double tick_rate_hz, AtEnd at_end)
    : x_(std::move(x_dps)),
      y_(std::move(y_dps)),
      z_(std::move(z_dps)),
      temperature_(std::move(temperature_c)),
      tick_rate_hz_(tick_rate_hz),
      at_end_(at_end) {
  if (x_.empty()) throw std::invalid_argument("the replayed signal has no x values");
  const auto check_length = [&](const std::vector<double>& v, const char* name) {
    if (v.size() != x_.size()) {
      throw std::invalid_argument(std::string("the replayed signal has ") + std::to_string(v.size()) + " " + name +
                                  " values but " + std::to_string(x_.size()) + " x values");
    }
  };
  check_length(y_, "y_dps");
  check_length(z_, "z_dps");
  check_length(temperature_, "temperature_c");
  if (!(tick_rate_hz > 0.0) || !std::isfinite(tick_rate_hz)) {
    throw std::invalid_argument("the replayed signal needs a tick rate that is finite and > 0 Hz, got " +
                                std::to_string(tick_rate_hz));
  }
  const auto check_finite = [](const std::vector<double>& v, const char* name) {
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!std::isfinite(v[i])) {
        throw std::invalid_argument(std::string("the replayed signal's ") + name + " value " + std::to_string(i) +
                                    " is not finite");
      }
    }
  };
  check_finite(x_, "x_dps");
  check_finite(y_, "y_dps");
  check_finite(z_, "z_dps");
  check_finite(temperature_, "temperature_c");
}

AnalogSample ReplaySource::nextTick(double) {
  if (next_ == x_.size()) {
    // Reached the end: Loop starts over (counted every time), HoldLast keeps serving the
    // last element (counted once).
    if (at_end_ == AtEnd::Loop) {
      ++exhausted_;
      next_ = 0;
      if (on_end_) on_end_(exhausted_);
    } else {
      if (exhausted_ == 0) {
        ++exhausted_;
        if (on_end_) on_end_(exhausted_);
      }
      const std::size_t last = x_.size() - 1;
      return AnalogSample{{x_[last], y_[last], z_[last]}, temperature_[last]};
    }
  }
  const std::size_t i = next_++;
  return AnalogSample{{x_[i], y_[i], z_[i]}, temperature_[i]};
}

}  // namespace gyrod::driver
