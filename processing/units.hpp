#pragma once
// Unit conversions used across gyrod. Rates travel through the code in °/s and
// times in s; the paper's noise-term units (°/√h, °/h, ...) appear only at the edges.
#include <numbers>

namespace gyrod::units {

inline constexpr double kSecondsPerHour = 3600.0;
inline constexpr double kSqrtSecondsPerSqrtHour = 60.0;  // √3600
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;
inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;
inline constexpr double kStandardGravity = 9.80665;  // m/s² per g (CGPM 1901)

inline constexpr double degPerHourToDegPerSecond(double v) { return v / kSecondsPerHour; }
inline constexpr double degPerSecondToDegPerHour(double v) { return v * kSecondsPerHour; }
inline constexpr double microradToDeg(double v) { return v * 1e-6 * kDegPerRad; }
inline constexpr double degToMicrorad(double v) { return v * kRadPerDeg * 1e6; }

}  // namespace gyrod::units
