#pragma once
// The device side of gyrod as configured: the bus (the Linux I2C adapter or the mock
// MPU6050), the data-ready source (GPIO line, FIFO polling or the mock's INT line) and the
// clock the driver stamps samples with.
//
// The mock runs in one of two ways:
//  - speed 1 (the default): real time. The mock's clock is CLOCK_MONOTONIC and its INT line
//    wakes the event loop like a GPIO line would.
//  - speed X ≠ 1: sensor time runs X times faster than real time on a virtual clock that
//    the daemon pumps from a periodic timer (see Gyrod). Timestamps are then sensor time.
#include <cstdint>
#include <memory>
#include <string>

#include "daemon/config.hpp"
#include "driver/clock.hpp"
#include "driver/data_ready.hpp"
#include "driver/i2c_bus.hpp"
#include "driver/mock/mock_mpu6050.hpp"
#include "driver/mock/mock_signal_source.hpp"
#include "driver/mpu6050_types.hpp"
#include "processing/simulation/noise_simulator.hpp"

namespace gyrod::daemon {

struct DeviceParts {
  std::unique_ptr<driver::Clock> clock;
  std::unique_ptr<driver::SignalSource> source;  // mock only
  std::unique_ptr<driver::I2cBus> bus;
  std::unique_ptr<driver::DataReadySource> data_ready_owned;  // GPIO or polling
  driver::DataReadySource* data_ready = nullptr;
  driver::MockMpu6050* mock = nullptr;            // mock only (owned by `bus`)
  driver::VirtualClock* virtual_clock = nullptr;  // accelerated mock only (owned by `clock`)
  driver::Mpu6050Config driver_config;
  std::string description;  // "/dev/i2c-1@0x68", "mock (simulator, seed 1, real time)"
};

// The signal the mock feels when no model file is configured: the paper's noise terms
// (Table 2) on every axis, biases typical of a real part, and a warm-up from 28 to 34 °C.
processing::SimulationModel defaultMockModel();

// Builds the backend. Throws std::runtime_error (or a driver error type derived from it)
// with an actionable one-line message when the device or a file cannot be opened.
DeviceParts makeDeviceParts(const GyrodConfig& config);

// The mock's FaultPlan for the [mock.faults] section (seconds → sensor-time ns).
driver::FaultPlan faultPlanFor(const MockFaults& faults);

}  // namespace gyrod::daemon
