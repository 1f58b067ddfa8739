#pragma once
// The simulator's temperature curve fitted to a recorded temperature channel, so that a
// model written from a recording (`gyroctl model-check --write-model`) warms up as it did.
#include <span>

#include "processing/simulation/noise_simulator.hpp"

namespace gyrod::processing {

// Least squares of T(t) = final + (start − final)·e^{−t/T} (the simulator's warm-up curve):
// for a fixed time constant T the model is linear in (final, start − final); T by a
// log-spaced scan from duration/100 to 10·duration, refined by golden section on ln T.
// The white-noise std from first differences (√(mean Δ²/2)), so slow wiggles of the room
// do not count as noise. A flat channel gives start = final = its mean.
// `secs`: seconds from the first sample. Throws std::invalid_argument for fewer than 2
// samples, channels of different lengths or a non-finite value.
TemperatureModel fitExponentialWarmUp(std::span<const double> secs, std::span<const double> temp);

}  // namespace gyrod::processing
