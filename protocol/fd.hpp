#pragma once
// An owned file descriptor: closed exactly once, when its owner goes away. Every fd the
// daemon, the driver and gyroctl open (epoll, timers, sockets, clients, the I2C bus) lives
// in one of these. Header-only and free of the protocol's JSON: target gyrod_fd.
#include <unistd.h>

#include <cerrno>
#include <string>
#include <system_error>
#include <utility>

namespace gyrod::protocol {

class Fd {
 public:
  Fd() noexcept = default;
  explicit Fd(int fd) noexcept : fd_(fd) {}
  ~Fd() { reset(); }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  Fd(Fd&& other) noexcept : fd_(other.release()) {}
  Fd& operator=(Fd&& other) noexcept {
    if (this != &other) reset(other.release());
    return *this;
  }

  int get() const noexcept { return fd_; }
  bool valid() const noexcept { return fd_ >= 0; }
  explicit operator bool() const noexcept { return valid(); }

  // Gives up ownership without closing.
  int release() noexcept { return std::exchange(fd_, -1); }

  // Closes the current fd (if any) and takes `fd`. close() is not retried on EINTR:
  // on Linux the descriptor is released even then, and a retry could close a reused one.
  void reset(int fd = -1) noexcept {
    const int old = std::exchange(fd_, fd);
    if (old >= 0) ::close(old);
  }

 private:
  int fd_ = -1;
};

// std::system_error for the current errno, with `what` saying which call failed on what.
inline std::system_error errnoError(const std::string& what) {
  return std::system_error(errno, std::generic_category(), what);
}

}  // namespace gyrod::protocol
