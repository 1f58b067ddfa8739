#pragma once
// The noise terms of one column in the units its users read them in: the paper's units and SI
// for the gyro, and their accelerometer counterparts (° replaced by m/s) and SI for the
// accelerometer. docs/coming-from.md maps these names to other tools'.
//
// The fit (noise_fit.hpp) works on a series in its column's own unit, °/s for a gyro column
// and g for an accelerometer column, and reports NoiseTerms in the paper's units as if the
// series were in °/s. Every figure below is a fixed multiple of that number, so a 1-σ
// uncertainty converts by the same function.
//
// JSON key scheme: <term>_<unit>, the unit spelled with "per" for '/', a digit for a power
// ("s2" = s²), "sqrt_h" / "sqrt_hz" for √h / √Hz: arw_rad_per_s_sqrt_hz is rad/s/√Hz.
#include <string_view>
#include <vector>

#include "processing/base/noise_terms.hpp"

namespace gyrod::processing {

enum class SensorKind { Gyro, Accel };

// ax, ay, az measure the accelerometer (in g); every other column the gyro (in °/s).
SensorKind sensorOfColumn(std::string_view column);

struct NoiseFigure {
  std::string_view key;    // JSON key, the unit in its name
  std::string_view label;  // for text output, the unit in brackets
  double value = 0.0;
};

// The figures a term stands for: the paper's unit (or its accelerometer counterpart) first,
// then SI when that is a different unit.
std::vector<NoiseFigure> noiseFigures(NoiseTerm term, double value, SensorKind sensor);

// The continuous-time white-noise density (Kalibr's *_noise_density: rad/s/√Hz for the gyro,
// m/s²/√Hz for the accelerometer) and the bias random walk (Kalibr's *_random_walk:
// rad/s²/√Hz, m/s³/√Hz) of a column's terms.
double noiseDensitySi(const NoiseTerms& terms, SensorKind sensor);
double biasRandomWalkSi(const NoiseTerms& terms, SensorKind sensor);

}  // namespace gyrod::processing
