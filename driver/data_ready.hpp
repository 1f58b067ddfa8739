#pragma once
// The chip's data-ready signal as the daemon's epoll loop sees it. Implementations: the
// mock device's (driver/mock/mock_mpu6050.hpp), libgpiod v1 line events on the INT pin, and a
// timerfd that polls INT_STATUS when no GPIO is wired.
#include <cstdint>

namespace gyrod::driver {

// Which transitions of the INT line count as data-ready edges, as in a GPIO line request.
// The chip drives INT active high unless INT_PIN_CFG.INT_LEVEL is set.
enum class EdgeDirection { Rising, Falling, Both };

class DataReadySource {
 public:
  virtual ~DataReadySource() = default;

  // A file descriptor to put in epoll for EPOLLIN. Readable means an edge may be pending:
  // a polling implementation can wake with nothing to report, so consumeEdge() may still
  // say -EAGAIN. Owned by the implementation; valid for its lifetime.
  virtual int fd() const = 0;

  // Takes the oldest pending edge and writes its time (CLOCK_MONOTONIC ns, taken when the
  // line moved, not when we woke). Returns 0, -EAGAIN when no edge is pending, or another
  // −errno. Edges are kept in a bounded queue; when it is full, new edges are dropped and
  // counted, as the kernel's GPIO line-event FIFO does.
  [[nodiscard]] virtual int consumeEdge(std::int64_t& timestamp_ns) = 0;

  // Edges lost because nobody consumed them in time.
  virtual std::uint64_t edgesDropped() const = 0;
};

}  // namespace gyrod::driver
