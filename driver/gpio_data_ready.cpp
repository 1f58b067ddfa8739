#include "driver/gpio_data_ready.hpp"

#include <fcntl.h>
#include <gpiod.h>
#include <time.h>

#include <cerrno>
#include <cstring>

#include "driver/clock.hpp"

namespace gyrod::driver {
namespace {

std::int64_t monotonicNowNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

const char* edgeName(EdgeDirection e) {
  switch (e) {
    case EdgeDirection::Rising: return "rising";
    case EdgeDirection::Falling: return "falling";
    case EdgeDirection::Both: return "both";
  }
  return "?";
}

}  // namespace

std::string describeGpioError(const std::string& step, int error, const GpioLineConfig& config, unsigned int chip_lines,
                              const std::string& current_consumer) {
  const std::string chip = "GPIO chip '" + config.chip + "'";
  const std::string line = "line " + std::to_string(config.offset) + " of " + chip;
  const std::string sys = std::string(" (") + std::strerror(error) + ")";
  if (step == "open") {
    switch (error) {
      case ENOENT:
        return chip + " not found" + sys +
               ". List the chips with `gpiodetect`; on a Raspberry Pi the 40-pin header is the chip "
               "labelled pinctrl-bcm2835 (Pi 1-3), pinctrl-bcm2711 (Pi 4) or pinctrl-rp1 (Pi 5); the label "
               "can be given instead of the name.";
      case EACCES:
      case EPERM:
        return "permission denied opening " + chip + sys +
               ": add the user running gyrod to the 'gpio' group (`sudo usermod -aG gpio $USER`, then log in "
               "again), or run it as the gyrod service user set up by the package.";
      case ENOTTY:
      case ENODEV: return chip + " is not a GPIO character device" + sys + ". Use a /dev/gpiochipN device or its name.";
      default: return "cannot open " + chip + sys;
    }
  }
  if (step == "line") {
    if (error == EINVAL && chip_lines > 0) {
      return "line offset " + std::to_string(config.offset) + " is out of range: " + chip + " has " +
             std::to_string(chip_lines) + " lines (offsets 0.." + std::to_string(chip_lines - 1) +
             "). On a Pi the offset is the BCM GPIO number, not the header pin number.";
    }
    return "cannot get " + line + sys;
  }
  // request
  switch (error) {
    case EBUSY:
      return line + " is already in use" +
             (current_consumer.empty() ? std::string() : " by '" + current_consumer + "'") + sys +
             ": another program or a device-tree overlay owns it (see `gpioinfo`). Free it or wire INT to another GPIO.";
    case EACCES:
    case EPERM: return "permission denied requesting " + line + sys + ": add the user to the 'gpio' group.";
    case EINVAL:
    case EOPNOTSUPP:
      return line + " cannot deliver " + edgeName(config.edge) + "-edge events" + sys +
             " (the pin may not support interrupts); choose another GPIO.";
    default: return std::string("cannot request ") + edgeName(config.edge) + "-edge events on " + line + sys;
  }
}

GpioDataReady::GpioDataReady(const GpioLineConfig& config) {
  chip_ = gpiod_chip_open_lookup(config.chip.c_str());
  if (chip_ == nullptr) {
    const int e = errno != 0 ? errno : ENOENT;
    throw GpioError(describeGpioError("open", e, config), e);
  }
  line_ = gpiod_chip_get_line(chip_, config.offset);
  if (line_ == nullptr) {
    const int e = errno != 0 ? errno : EINVAL;
    const unsigned int lines = gpiod_chip_num_lines(chip_);
    gpiod_chip_close(chip_);
    throw GpioError(describeGpioError("line", e, config, lines), e);
  }
  int r = -1;
  switch (config.edge) {
    case EdgeDirection::Rising: r = gpiod_line_request_rising_edge_events(line_, config.consumer.c_str()); break;
    case EdgeDirection::Falling: r = gpiod_line_request_falling_edge_events(line_, config.consumer.c_str()); break;
    case EdgeDirection::Both: r = gpiod_line_request_both_edges_events(line_, config.consumer.c_str()); break;
  }
  if (r != 0) {
    const int e = errno != 0 ? errno : EIO;
    std::string consumer;
    if (gpiod_line_update(line_) == 0 && gpiod_line_consumer(line_) != nullptr) consumer = gpiod_line_consumer(line_);
    gpiod_chip_close(chip_);
    throw GpioError(describeGpioError("request", e, config, 0, consumer), e);
  }
  fd_ = gpiod_line_event_get_fd(line_);
  // libgpiod 1.6 leaves the event fd blocking; the driver must never block in read().
  const int flags = fd_ >= 0 ? fcntl(fd_, F_GETFL) : -1;
  if (flags < 0 || fcntl(fd_, F_SETFL, flags | O_NONBLOCK) != 0) {
    const int e = errno;
    gpiod_chip_close(chip_);  // also releases the line
    throw GpioError(
        "cannot make the event fd of line " + std::to_string(config.offset) + " non-blocking: " + std::strerror(e), e);
  }
}

GpioDataReady::~GpioDataReady() {
  if (chip_ != nullptr) gpiod_chip_close(chip_);
}

int GpioDataReady::consumeEdge(std::int64_t& timestamp_ns) {
  gpiod_line_event event{};
  if (gpiod_line_event_read_fd(fd_, &event) != 0) {
    return errno == EAGAIN || errno == EWOULDBLOCK ? -EAGAIN : -(errno != 0 ? errno : EIO);
  }
  const std::int64_t t = static_cast<std::int64_t>(event.ts.tv_sec) * kNsPerSecond + event.ts.tv_nsec;
  const std::int64_t now = monotonicNowNs();
  // An event cannot come from the future, nor (with the loop draining the queue) from
  // minutes ago; anything else is a CLOCK_REALTIME stamp from an old kernel.
  if (t > now + kNsPerSecond || t < now - 60 * kNsPerSecond) {
    ++timestamps_replaced_;
    timestamp_ns = now;
  } else {
    timestamp_ns = t;
  }
  return 0;
}

}  // namespace gyrod::driver
