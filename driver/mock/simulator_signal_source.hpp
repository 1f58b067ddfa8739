#pragma once
// The noise simulator (processing/simulation/noise_simulator.hpp) as what the mock MPU-6050 "feels":
// one analog sample per internal gyro tick (bias, ARW, bias instability, RRW, ramp and
// the temperature curve, plus the true rate of a motion profile when the board is turned).
// The mock applies the DLPF, decimation, saturation and quantisation itself, so they act on
// the motion as on the chip.
//
// With motion the source also tells the mock what gravity reads in the chip's axes: the
// attitude integrated from the true rates (processing::AttitudeIntegrator, level at the first
// tick), so the mock's accel tilts with the board; the mock adds its accel noise and bias.
//
// The temperature coupling k·(T(t) − T_ref) of the model's [x.extra] (the bias following a
// warm-up) is added to the analog rate, so it passes the DLPF like the rest of the bias. So are
// the model's narrowband lines ([x.extra] narrowband_lines): a line is defined by its centre and
// width in Hz, so the simulator plays it at the internal rate (NoiseSimulator::nextNarrowbandLines)
// and the mock's DLPF attenuates it as the chip's would.
//
// Not included: the terms the simulator defines at the *output* rate — angle
// quantization noise Q, the AR(p) component and the other extra effects — because the mock's output rate is set by
// the driver through SMPLRT_DIV at run time, not by the model. A model that relies on
// them is simulated faithfully only by `gyroctl simulate`.
#include <cstdint>
#include <memory>

#include "driver/mock/mock_signal_source.hpp"
#include "processing/simulation/noise_simulator.hpp"

namespace gyrod::driver {

class SimulatorSignalSource final : public SignalSource {
 public:
  static constexpr double kDefaultHorizonS = 7.0 * 24 * 3600;  // a week of running

  // `dlpf_cfg` selects the internal rate the chip will tick at (8 kHz for 0 and 7, else
  // 1 kHz); it must match CONFIG.DLPF_CFG as the driver will set it. `horizon_s` is the
  // longest run the flicker (bias-instability) model is built for. Throws
  // std::invalid_argument for a model the simulator rejects. `motion` turns the board (time
  // from the first tick); at rest by default, which gives the very samples it always gave.
  SimulatorSignalSource(const processing::SimulationModel& model, int dlpf_cfg, std::uint64_t seed,
                        double horizon_s = kDefaultHorizonS, processing::MotionProfile motion = {});
  double expectedTickRateHz() const override { return simulator_->internalRateHz(); }
  AnalogSample nextTick(double t_s) override;

 private:
  std::unique_ptr<processing::NoiseSimulator> simulator_;
  bool has_lines_ = false;  // some axis has narrowband lines
};

}  // namespace gyrod::driver
