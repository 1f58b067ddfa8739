#include "daemon/device_backend.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "driver/gpio_data_ready.hpp"
#include "driver/linux_i2c_bus.hpp"
#include "driver/mock/replay_clock.hpp"
#include "driver/mock/simulator_signal_source.hpp"
#include "driver/mpu6050_config.hpp"
#include "driver/polling_data_ready.hpp"
#include "formats/input_file.hpp"
#include "formats/model_toml.hpp"
#include "formats/motion_spec.hpp"
#include "formats/recording_csv.hpp"

namespace gyrod::daemon {
namespace {

std::int64_t secondsToNs(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

int fsSelFor(int full_scale_dps) {
  switch (full_scale_dps) {
    case 250: return 0;
    case 500: return 1;
    case 1000: return 2;
    case 2000: return 3;
  }
  throw std::invalid_argument("device.full_scale_dps must be 250, 500, 1000 or 2000");
}

// A recording at its own rate: each sample held for a whole number of the chip's ticks, the
// chip's clock run fast or slow by what that rounding leaves (driver/mock/replay_clock.hpp),
// so that the mock presents the recording's rate as the chip's. The end of the recording is
// logged each time the replay starts over.
std::unique_ptr<driver::SignalSource> replaySource(const std::string& path, int dlpf_cfg, double& clock_error_ppm) {
  recording::ReadOptions replay;
  replay.input_kind = &formats::kReplayInput;
  const recording::Recording rec = recording::readRecordingCsv(path, replay);
  const double internal = driver::mpu6050::gyroOutputRateHz(dlpf_cfg);
  const double rate = rec.t.size() >= 2 ? recording::sampleRateFromTimes(rec) : 50.0;
  const auto clock = driver::replayClockFor(rate, internal);
  if (!clock) {
    std::ostringstream s;
    s << path << ": a recording at " << rate << " Hz cannot be replayed at the chip's internal rate of " << internal
      << " Hz (no whole number of ticks per sample within the mock's 10 % clock tolerance)";
    throw std::runtime_error(s.str());
  }
  clock_error_ppm = clock->clock_error_ppm;
  const std::size_t hold = clock->hold;
  const std::vector<double>* columns[3] = {nullptr, nullptr, nullptr};
  for (std::size_t c = 0; c < rec.axis_names.size(); ++c)
    if (const auto axis = recording::axisOfColumn(rec.axis_names[c])) columns[*axis] = &rec.axes[c];
  std::vector<double> axes[3], temp;
  for (int a = 0; a < 3; ++a) {
    const std::vector<double>* col = columns[a];
    for (std::size_t i = 0; i < rec.size(); ++i)
      for (std::size_t k = 0; k < hold; ++k) axes[a].push_back(col ? (*col)[i] : 0.0);
  }
  for (std::size_t i = 0; i < rec.size(); ++i)
    for (std::size_t k = 0; k < hold; ++k) temp.push_back(rec.temp.empty() ? 25.0 : rec.temp[i]);
  auto source = std::make_unique<driver::ReplaySource>(std::move(axes[0]), std::move(axes[1]), std::move(axes[2]),
                                                       std::move(temp), internal);
  source->onEnd([path, samples = rec.size()](std::uint64_t loops) {
    spdlog::info("mock: the replay of {} reached its end ({} samples); starting over (pass {})", path, samples,
                 loops + 1);
  });
  return source;
}

}  // namespace

processing::SimulationModel defaultMockModel() {
  processing::SimulationModel m;
  const double biases[3] = {-3.34, 1.09, -0.50};  // °/s, as measured on a real part (tests/data)
  for (std::size_t a = 0; a < 3; ++a) {
    auto& axis = m.axes[a];
    axis.terms.quantization_urad = 0.1663;
    axis.terms.arw_deg_per_sqrt_h = 0.95164;
    axis.terms.bias_instability_deg_per_h = 0.60565;
    axis.terms.rrw_deg_per_h_sqrt_h = 0.07759;
    axis.terms.rate_ramp_deg_per_h2 = 0.0;  // a ramp grows without bound in a long demo
    axis.bias_dps = biases[a];
  }
  m.temperature = {28.0, 34.0, 900.0, 0.02};
  return m;
}

driver::FaultPlan faultPlanFor(const MockFaults& f) {
  driver::FaultPlan plan;
  plan.random_errors.probability = f.transfer_error_fraction;
  plan.random_errors.error = EIO;
  for (const auto& b : f.error_bursts) plan.error_bursts.push_back({secondsToNs(b.at_s), b.count, EREMOTEIO});
  for (const auto& v : f.vanish)
    plan.outages.push_back({secondsToNs(v.at_s), secondsToNs(v.duration_s), EREMOTEIO, v.power_lost});
  for (double t : f.silent_reset_at_s) plan.brownouts_ns.push_back(secondsToNs(t));
  for (double t : f.fifo_overflow_at_s) plan.forced_fifo_overflows_ns.push_back(secondsToNs(t));
  if (f.who_am_i) plan.who_am_i = static_cast<std::uint8_t>(*f.who_am_i);
  for (const auto& g : f.glitch_bursts)
    plan.glitch_bursts.push_back({secondsToNs(g.at_s), secondsToNs(g.duration_s), g.count, g.axis, g.bit});
  for (double t : f.stuck_data_ready_at_s) {
    // "Until the end" when no duration is given: a century of sensor time.
    const double duration = f.stuck_data_ready_duration_s.value_or(100.0 * 365 * 86400);
    plan.stuck_data_ready.push_back({secondsToNs(t), secondsToNs(duration), false});
  }
  return plan;
}

DeviceParts makeDeviceParts(const GyrodConfig& config) {
  DeviceParts b;
  auto& dc = b.driver_config;
  dc.address = static_cast<std::uint8_t>(config.device.address);
  dc.sample_rate_hz = config.device.rate_hz;
  dc.dlpf_cfg = config.device.dlpf;
  dc.fs_sel = fsSelFor(config.device.full_scale_dps);
  dc.accel = config.device.accel;
  dc.afs_sel = driver::afsSelForRangeG(config.device.accel_range_g).value_or(-1);  // -1: validateConfig names it

  if (config.device.backend == DeviceBackend::Mock) {
    const auto& mc = config.mock;
    double replay_clock_error_ppm = 0.0;
    if (mc.source == MockSource::Replay) {
      b.source = replaySource(mc.replay_file, config.device.dlpf, replay_clock_error_ppm);
    } else {
      processing::SimulationModel model =
          config.filter.model.empty() ? defaultMockModel() : recording::readModelToml(config.filter.model);
      if (!mc.warm_up.empty())
        model.temperature = processing::withWarmUp(model.temperature, recording::parseWarmUpSpec(mc.warm_up));
      for (std::size_t a = 0; a < mc.temperature_coefficient_dps_per_c.size(); ++a)
        model.axes[a].extra.temperature_coefficient_dps_per_c = mc.temperature_coefficient_dps_per_c[a];
      const processing::MotionProfile motion =
          mc.motion.empty() ? processing::MotionProfile{} : recording::motionFromSpec(mc.motion);
      b.source = std::make_unique<driver::SimulatorSignalSource>(
          model, config.device.dlpf, mc.seed, driver::SimulatorSignalSource::kDefaultHorizonS, motion);
    }
    std::unique_ptr<driver::VirtualClock> virtual_clock;
    if (mc.speed == 1.0) {
      b.clock = std::make_unique<driver::MonotonicClock>();
    } else {
      virtual_clock = std::make_unique<driver::VirtualClock>(0);
      b.virtual_clock = virtual_clock.get();
      b.clock = std::move(virtual_clock);
    }
    driver::MockMpu6050Config mock_config;
    mock_config.address = dc.address;
    mock_config.clock_error_ppm = replay_clock_error_ppm;
    mock_config.accel_noise_seed = mc.seed;
    // A zero-g offset of a few mg per axis, like a real part's (product spec §6.2: ±50 mg).
    mock_config.accel_bias_g = {0.012, -0.008, 0.02};
    auto mock = std::make_unique<driver::MockMpu6050>(*b.clock, *b.source, mock_config);
    mock->setFaultPlan(faultPlanFor(mc.faults));
    b.mock = mock.get();
    b.data_ready = &mock->dataReady();
    b.bus = std::move(mock);
    dc.data_ready_mode = driver::DataReadyMode::InterruptEdges;
    dc.bus_name = "the mock bus";
    std::ostringstream d;
    d << "mock MPU6050 (" << toString(mc.source) << ", seed " << mc.seed << ", ";
    if (mc.speed == 1.0)
      d << "real time";
    else
      d << mc.speed << "x real time";
    if (!mc.motion.empty()) d << ", motion " << mc.motion;
    if (!mc.warm_up.empty()) d << ", warm-up " << mc.warm_up;
    if (replay_clock_error_ppm != 0.0)
      d << ", chip clock " << std::showpos << replay_clock_error_ppm << std::noshowpos
        << " ppm to replay at the recording's rate";
    d << ')';
    b.description = d.str();
    return b;
  }

  b.clock = std::make_unique<driver::MonotonicClock>();
  b.bus = std::make_unique<driver::LinuxI2cBus>(config.device.bus);
  dc.bus_name = config.device.bus;
  if (!config.gpio.chip.empty()) {
    driver::GpioLineConfig line;
    line.chip = config.gpio.chip;
    line.offset = static_cast<unsigned>(*config.gpio.line);
    b.data_ready_owned = std::make_unique<driver::GpioDataReady>(line);
    dc.data_ready_mode = driver::DataReadyMode::InterruptEdges;
  } else {
    dc.data_ready_mode = driver::DataReadyMode::Polling;
    dc.polling_period_ns = driver::pollingPeriodNs(dc);
    b.data_ready_owned = std::make_unique<driver::PollingDataReady>(*b.clock, dc.polling_period_ns);
  }
  b.data_ready = b.data_ready_owned.get();
  std::ostringstream d;
  d << config.device.bus << "@0x" << std::hex << config.device.address;
  b.description = d.str();
  return b;
}

}  // namespace gyrod::daemon
