#pragma once
// What the mock MPU-6050's sensing element "feels": the analog angular rate on three axes
// (°/s) and the die temperature (°C), one value per internal gyro tick (1 kHz, or 8 kHz
// with DLPF_CFG 0 or 7). The mock runs each value through the on-chip DLPF model, then
// decimates and quantises it as the chip would.
//
// Implementations here: constant, sinusoid (tests), replay of in-memory arrays (a caller
// reads recordings elsewhere; the driver parses no files). An adapter for the noise
// simulator (processing/simulation/noise_simulator.hpp) is another small class implementing
// SignalSource: expectedTickRateHz() returns the simulator's rate, nextTick() draws one
// sample.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

namespace gyrod::driver {

struct AnalogSample {
  std::array<double, 3> rate_dps{};  // x, y, z, °/s
  double temperature_c = 25.0;
  // What an ideal accelerometer reads (x, y, z, g: gravity at the board's attitude) when the
  // source knows it; NaN: the mock uses its configured fixed vector (MockMpu6050Config).
  std::array<double, 3> accel_g{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                                std::numeric_limits<double>::quiet_NaN()};
};

class SignalSource {
 public:
  virtual ~SignalSource() = default;
  // The internal tick rate this source's samples are meant for, Hz; 0 when it can serve
  // any rate (it is a function of time). The mock counts ticks taken at another rate.
  virtual double expectedTickRateHz() const = 0;
  // The input at the next internal tick, which the chip takes at t_s seconds after the
  // mock was created (true time, so a fast chip clock samples a sinusoid at the right
  // phase). Called once per tick, in order; must not allocate.
  virtual AnalogSample nextTick(double t_s) = 0;
};

class ConstantSource final : public SignalSource {
 public:
  // Throws std::invalid_argument for non-finite values.
  explicit ConstantSource(std::array<double, 3> rate_dps, double temperature_c = 25.0);
  double expectedTickRateHz() const override { return 0.0; }
  AnalogSample nextTick(double t_s) override;

 private:
  AnalogSample value_;
};

// rate_i(t) = offset_i + amplitude_i · sin(2π f t + phase_i), temperature constant.
struct SinusoidAxis {
  double offset_dps = 0.0;
  double amplitude_dps = 0.0;
  double frequency_hz = 0.0;
  double phase_rad = 0.0;
};
class SinusoidSource final : public SignalSource {
 public:
  // Throws std::invalid_argument for non-finite values or a negative frequency.
  explicit SinusoidSource(std::array<SinusoidAxis, 3> axes, double temperature_c = 25.0);
  double expectedTickRateHz() const override { return 0.0; }
  AnalogSample nextTick(double t_s) override;

 private:
  std::array<SinusoidAxis, 3> axes_;
  double temperature_c_;
};

// Plays recorded arrays, one element per tick. At the end it starts over (Loop) or keeps
// the last value (HoldLast); timesExhausted() counts how often the end was reached.
class ReplaySource final : public SignalSource {
 public:
  enum class AtEnd { Loop, HoldLast };
  // x, y, z in °/s and temperature in °C, all the same non-zero length, finite;
  // tick_rate_hz > 0. Throws std::invalid_argument naming what is wrong.
  ReplaySource(std::vector<double> x_dps, std::vector<double> y_dps, std::vector<double> z_dps,
               std::vector<double> temperature_c, double tick_rate_hz, AtEnd at_end = AtEnd::Loop);
  double expectedTickRateHz() const override { return tick_rate_hz_; }
  AnalogSample nextTick(double t_s) override;
  std::size_t position() const { return next_; }
  std::uint64_t timesExhausted() const { return exhausted_; }
  // Called each time the end is reached, with timesExhausted(), so that the owner can say so
  // (gyrod logs that the replay starts over): a loop is otherwise invisible in the data.
  void onEnd(std::function<void(std::uint64_t)> callback) { on_end_ = std::move(callback); }

 private:
  std::vector<double> x_, y_, z_, temperature_;
  double tick_rate_hz_;
  AtEnd at_end_;
  std::size_t next_ = 0;
  std::uint64_t exhausted_ = 0;
  std::function<void(std::uint64_t)> on_end_;
};

}  // namespace gyrod::driver
