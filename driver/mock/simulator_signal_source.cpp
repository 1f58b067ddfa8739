#include "driver/mock/simulator_signal_source.hpp"

#include <array>
#include <stdexcept>
#include <utility>

#include "driver/mpu6050_registers.hpp"

namespace gyrod::driver {

namespace {
processing::SimulationModel modelAtInternalRate(processing::SimulationModel model, int dlpf_cfg) {
  if (dlpf_cfg < 0 || dlpf_cfg > 7)
    throw std::invalid_argument("the simulated sensor needs DLPF_CFG 0..7, got " + std::to_string(dlpf_cfg));
  // The simulator's analog stream runs at the internal rate of its DLPF setting; with the
  // output rate set to that same rate, nextAnalog() delivers exactly one value per tick.
  // DLPF_CFG 7 ticks at 8 kHz like 0.
  const int cfg = dlpf_cfg == 7 ? 0 : dlpf_cfg;
  model.dlpf_cfg = cfg;
  model.fs_sel.reset();
  model.rate_hz = mpu6050::gyroOutputRateHz(cfg);
  // Gravity at the integrated attitude only: the mock adds its own accel noise and bias.
  // (The accel draws from a stream of its own, so the gyro samples are the same with it.)
  model.accel = processing::AccelModel{};
  return model;
}
}  // namespace

SimulatorSignalSource::SimulatorSignalSource(const processing::SimulationModel& model, int dlpf_cfg, std::uint64_t seed,
                                             double horizon_s, processing::MotionProfile motion)
    : simulator_(motion.atRest() ? std::make_unique<processing::NoiseSimulator>(modelAtInternalRate(model, dlpf_cfg),
                                                                                horizon_s, seed)
                                 : std::make_unique<processing::NoiseSimulator>(modelAtInternalRate(model, dlpf_cfg),
                                                                                horizon_s, seed, std::move(motion))) {
  for (const processing::AxisNoiseModel& axis : simulator_->model().axes)
    has_lines_ = has_lines_ || !axis.extra.narrowband_lines.empty();
}

AnalogSample SimulatorSignalSource::nextTick(double /*t_s*/) {
  const processing::SimulatedSample s = simulator_->nextAnalog();
  AnalogSample a;
  a.rate_dps = s.rate_dps;
  // The temperature coupling is one of the simulator's output-rate effects, which the mock does
  // not take (its output rate is the driver's); a warm-up needs it, and it is slow, so it joins
  // the analog rate here. Nothing is added (not even 0.0) to an axis without one.
  const processing::SimulationModel& model = simulator_->model();
  for (std::size_t axis = 0; axis < a.rate_dps.size(); ++axis)
    if (model.axes[axis].extra.temperature_coefficient_dps_per_c != 0.0)
      a.rate_dps[axis] += processing::temperatureCouplingDps(model.axes[axis].extra, model.temperature, s.t_s);
  // The narrowband lines likewise, at the internal rate (their random numbers are the extras'
  // own, so the rest of the stream is the same with them).
  if (has_lines_) {
    const std::array<double, processing::kSimulatedAxes> lines = simulator_->nextNarrowbandLines();
    for (std::size_t axis = 0; axis < a.rate_dps.size(); ++axis)
      if (!model.axes[axis].extra.narrowband_lines.empty()) a.rate_dps[axis] += lines[axis];
  }
  a.temperature_c = s.temperature_c;
  a.accel_g = s.accel_g;
  return a;
}

}  // namespace gyrod::driver
