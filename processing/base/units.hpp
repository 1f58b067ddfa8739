#pragma once
// Unit conversions used across gyrod. Rates travel through the code in °/s and
// times in s; the paper's noise-term units (°/√h, °/h, ...) appear only at the edges.
//
// Noise terms in SI (reference: IEEE Std 952-1997 Annex C for the terms, and the Kalibr wiki
// "IMU Noise Model" for the continuous-time densities Kalibr's imu.yaml expects): a density
// in X/√Hz is the same number as X·√s, so the conversions below only change the angle unit
// (° → rad) or the acceleration unit (g → m/s²) and the time unit (h → s).
#include <cmath>
#include <numbers>

namespace gyrod::units {

inline constexpr double kSecondsPerHour = 3600.0;
inline constexpr double kSqrtSecondsPerSqrtHour = 60.0;           // √3600
inline constexpr double kSecondsPerHourToThreeHalves = 216000.0;  // 3600^1.5
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;
inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;
inline constexpr double kStandardGravity = 9.80665;  // m/s² per g (CGPM 1901)

inline constexpr double degPerHourToDegPerSecond(double v) { return v / kSecondsPerHour; }
inline constexpr double degPerSecondToDegPerHour(double v) { return v * kSecondsPerHour; }
inline constexpr double microradToDeg(double v) { return v * 1e-6 * kDegPerRad; }
inline constexpr double degToMicrorad(double v) { return v * kRadPerDeg * 1e6; }
inline constexpr double gToMetresPerSecond2(double v) { return v * kStandardGravity; }

// Gyro terms, the paper's units → SI.
// Quantization Q: µrad → rad.
inline constexpr double microradToRad(double v) { return v * 1e-6; }
// Angle random walk N: °/√h → rad/s/√Hz (Kalibr's gyroscope_noise_density); 1 °/√h = π/180/60.
inline constexpr double arwDegPerSqrtHourToRadPerSecondSqrtHz(double v) {
  return v * kRadPerDeg / kSqrtSecondsPerSqrtHour;
}
// Bias instability B: °/h → rad/s.
inline constexpr double degPerHourToRadPerSecond(double v) { return v * kRadPerDeg / kSecondsPerHour; }
// Rate random walk K: °/h/√h → rad/s²/√Hz (Kalibr's gyroscope_random_walk); 1 °/h^1.5 = π/180/216000.
inline constexpr double rrwDegPerHourSqrtHourToRadPerSecond2SqrtHz(double v) {
  return v * kRadPerDeg / kSecondsPerHourToThreeHalves;
}
// Rate ramp R: °/h² → rad/s².
inline constexpr double degPerHour2ToRadPerSecond2(double v) {
  return v * kRadPerDeg / (kSecondsPerHour * kSecondsPerHour);
}

// Accelerometer terms, from the paper-style units (the gyro's with ° replaced by m/s) → SI.
// Velocity random walk: m/s/√h → m/s²/√Hz (Kalibr's accelerometer_noise_density).
inline constexpr double vrwMetresPerSecondSqrtHourToMetresPerSecond2SqrtHz(double v) {
  return v / kSqrtSecondsPerSqrtHour;
}
// Bias instability: mg → m/s².
inline constexpr double milligToMetresPerSecond2(double v) { return v * 1e-3 * kStandardGravity; }
// Acceleration random walk: m/s/h/√h → m/s³/√Hz (Kalibr's accelerometer_random_walk).
inline constexpr double accelRandomWalkMetresPerSecondHourSqrtHourToSi(double v) {
  return v / kSecondsPerHourToThreeHalves;
}
// Acceleration ramp: m/s/h² → m/s³.
inline constexpr double metresPerSecondHour2ToMetresPerSecond3(double v) {
  return v / (kSecondsPerHour * kSecondsPerHour);
}

// Discrete-time standard deviation of white noise sampled at `rate_hz` from its density
// (σ_d = σ_c·√rate, as Kalibr discretises), and back.
inline double discreteStdFromDensity(double density, double rate_hz) { return density * std::sqrt(rate_hz); }
inline double densityFromDiscreteStd(double discrete_std, double rate_hz) { return discrete_std / std::sqrt(rate_hz); }

}  // namespace gyrod::units
