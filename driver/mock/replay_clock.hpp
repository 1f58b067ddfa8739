#pragma once
// How the mock replays a recording at the recording's own rate. The mock's chip ticks at its
// internal rate (1 kHz, or 8 kHz without the DLPF) and each recorded sample is held for a whole
// number of ticks; a rate that does not divide the internal rate (a real record's 100.31 Hz)
// is met by running the chip's clock that much fast or slow, as a real part's clock is off by
// its tolerance: 10 ticks of a clock 3100 ppm fast last one period of 100.31 Hz. The chip then
// presents the recording's rate as its own, and gyrod measures it as it would a real chip's.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>

namespace gyrod::driver {

// The mock's clock may be off by at most this much (MockMpu6050Config::clock_error_ppm).
inline constexpr double kMockMaxClockErrorPpm = 100'000.0;

struct ReplayClock {
  std::size_t hold = 1;          // ticks of the chip's clock per recorded sample
  double clock_error_ppm = 0.0;  // how fast the chip's clock runs for hold ticks to last one sample
};

// nullopt when no whole number of ticks comes within the mock's clock tolerance (a rate above
// about a fifth of the internal rate that does not divide it), or for a rate that is not > 0.
inline std::optional<ReplayClock> replayClockFor(double recording_rate_hz, double internal_rate_hz) {
  if (!(recording_rate_hz > 0.0 && std::isfinite(recording_rate_hz) && internal_rate_hz > 0.0)) return std::nullopt;
  const double ticks = internal_rate_hz / recording_rate_hz;
  const double hold = std::max(1.0, std::round(ticks));
  ReplayClock clock;
  clock.hold = static_cast<std::size_t>(hold);
  clock.clock_error_ppm = (recording_rate_hz * hold / internal_rate_hz - 1.0) * 1e6;
  // Within a part per million the rate divides the internal rate (the rounding of t).
  if (std::abs(clock.clock_error_ppm) < 1.0) clock.clock_error_ppm = 0.0;
  if (std::abs(clock.clock_error_ppm) > kMockMaxClockErrorPpm) return std::nullopt;
  return clock;
}

}  // namespace gyrod::driver
