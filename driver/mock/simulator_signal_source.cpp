#include "driver/mock/simulator_signal_source.hpp"

#include <stdexcept>
#include <utility>

#include "driver/mpu6050_registers.hpp"

namespace gyrod::driver {

namespace {
processing::SimulationModel modelAtInternalRate(processing::SimulationModel model, int dlpf_cfg) {
  if (dlpf_cfg < 0 || dlpf_cfg > 7) throw std::invalid_argument("SimulatorSignalSource: DLPF_CFG must be 0..7");
  // The simulator's analog stream runs at the internal rate of its DLPF setting; with the
  // output rate set to that same rate, nextAnalog() delivers exactly one value per tick.
  // DLPF_CFG 7 ticks at 8 kHz like 0.
  const int cfg = dlpf_cfg == 7 ? 0 : dlpf_cfg;
  model.dlpf_cfg = cfg;
  model.fs_sel.reset();
  model.rate_hz = mpu6050::gyroOutputRateHz(cfg);
  return model;
}
}  // namespace

SimulatorSignalSource::SimulatorSignalSource(const processing::SimulationModel& model, int dlpf_cfg, std::uint64_t seed,
                                             double horizon_s, processing::MotionProfile motion)
    : simulator_(motion.atRest() ? std::make_unique<processing::NoiseSimulator>(modelAtInternalRate(model, dlpf_cfg),
                                                                                horizon_s, seed)
                                 : std::make_unique<processing::NoiseSimulator>(modelAtInternalRate(model, dlpf_cfg),
                                                                                horizon_s, seed, std::move(motion))) {}

AnalogSample SimulatorSignalSource::nextTick(double /*t_s*/) {
  const processing::SimulatedSample s = simulator_->nextAnalog();
  AnalogSample a;
  a.rate_dps = s.rate_dps;
  a.temperature_c = s.temperature_c;
  return a;
}

}  // namespace gyrod::driver
