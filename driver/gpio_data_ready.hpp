#pragma once
// The MPU6050's INT pin on a GPIO line, through libgpiod v1 (1.6.x: Debian bookworm,
// Raspberry Pi OS). The line is requested for edge events; its event fd goes into the
// daemon's epoll loop, and each event's kernel timestamp (taken in the interrupt handler,
// CLOCK_MONOTONIC on the v1 uAPI since Linux 5.7) is the edge time the driver anchors its
// sample clock to.
#include <cstdint>
#include <stdexcept>
#include <string>

#include "driver/data_ready.hpp"

struct gpiod_chip;
struct gpiod_line;

namespace gyrod::driver {

struct GpioLineConfig {
  // As gpiod_chip_open_lookup() takes it: "gpiochip0", "/dev/gpiochip0", "0", or a label
  // such as "pinctrl-bcm2835" (Pi 1–4) / "pinctrl-rp1" (Pi 5).
  std::string chip = "gpiochip0";
  unsigned int offset = 17;  // BCM GPIO number on a Pi (GPIO17 = header pin 11)
  // Rising for the driver's default INT configuration (active high); Falling with
  // Mpu6050Config::int_active_low.
  EdgeDirection edge = EdgeDirection::Rising;
  std::string consumer = "gyrod";
};

// Thrown when the line cannot be requested; what() says why and what to do.
class GpioError : public std::runtime_error {
 public:
  GpioError(const std::string& message, int error) : std::runtime_error(message), error_(error) {}
  int error() const { return error_; }  // positive errno

 private:
  int error_;
};

// The message for a failure of gpiod_chip_open_lookup (step "open"), gpiod_chip_get_line
// ("line") or the event request ("request"), for errno `error`. Pure, for tests.
std::string describeGpioError(const std::string& step, int error, const GpioLineConfig& config,
                              unsigned int chip_lines = 0, const std::string& current_consumer = {});

class GpioDataReady final : public DataReadySource {
 public:
  // Throws GpioError with an actionable message.
  explicit GpioDataReady(const GpioLineConfig& config);
  ~GpioDataReady() override;
  GpioDataReady(const GpioDataReady&) = delete;
  GpioDataReady& operator=(const GpioDataReady&) = delete;

  int fd() const override { return fd_; }
  // Reads one line event (the fd is non-blocking): 0 and the kernel's timestamp, -EAGAIN
  // when none is pending, or another −errno.
  [[nodiscard]] int consumeEdge(std::int64_t& timestamp_ns) override;
  // The v1 uAPI does not report events dropped from the kernel's 16-entry queue; the
  // driver notices missing edges itself (its watchdog and timestamp checks). Always 0.
  std::uint64_t edgesDropped() const override { return 0; }
  // Events whose timestamp was not on CLOCK_MONOTONIC (kernels before 5.7 stamped v1
  // line events with CLOCK_REALTIME) and were replaced by the read time.
  std::uint64_t timestampsReplaced() const { return timestamps_replaced_; }

 private:
  gpiod_chip* chip_ = nullptr;
  gpiod_line* line_ = nullptr;
  int fd_ = -1;  // owned by libgpiod and closed with chip_, so not a protocol::Fd
  std::uint64_t timestamps_replaced_ = 0;
};

}  // namespace gyrod::driver
