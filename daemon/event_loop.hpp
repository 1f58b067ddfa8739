#pragma once
// gyrod's one event loop: epoll over every source, each behind the same small interface.
//   - fds (sensor data-ready, listening socket, clients): a callback with the epoll events;
//   - timers on timerfd (CLOCK_MONOTONIC), periodic or one-shot: a callback with the number
//     of expirations since the last one (> 1 means the loop was late);
//   - signals on signalfd: a callback with the signal number. The signals are blocked in the
//     calling thread (and so in threads it creates later) so that they are only ever
//     delivered through the signalfd, never to a handler racing the loop.
// Level-triggered throughout. Callbacks may add or remove any source, including their own,
// while the loop is dispatching: an event for a source removed earlier in the same batch is
// not delivered. The loop owns the timerfds and signalfds it creates; it never owns an fd
// passed to addFd (that stays with the caller's protocol::Fd).
// Deferred work (defer): a source that has more to do than one turn should take (a client
// with a backlog of requests) does a bounded share and asks to be called again after the
// events of the next turn, whose wait then does not block.
// Exceptions thrown by a callback propagate out of run()/runOnce(): sources that must not
// stop the daemon (clients) handle their own errors.
#include <sys/epoll.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <unordered_map>
#include <vector>

#include "daemon/priority_inheritance_mutex.hpp"
#include "protocol/fd.hpp"

namespace gyrod::daemon {

// The daemon's descriptors are the protocol's owned Fd (shared with the driver and gyroctl).
using protocol::errnoError;
using protocol::Fd;

class EventLoop {
 public:
  using FdCallback = std::function<void(std::uint32_t epoll_events)>;
  using TimerCallback = std::function<void(std::uint64_t expirations)>;
  using SignalCallback = std::function<void(int signal_number)>;
  using SourceId = std::uint64_t;  // never reused within one loop

  EventLoop();
  ~EventLoop();
  EventLoop(const EventLoop&) = delete;
  EventLoop& operator=(const EventLoop&) = delete;

  // ---- fds ---------------------------------------------------------------------------
  // Watches `fd` for `events` (EPOLLIN, EPOLLOUT, ...; EPOLLERR and EPOLLHUP are always
  // reported). Throws std::invalid_argument for fd < 0 or an fd already watched, and
  // std::system_error when epoll refuses it (e.g. a regular file).
  void addFd(int fd, std::uint32_t events, FdCallback callback);
  // Changes the events of a watched fd. Throws std::invalid_argument if it is not watched.
  void modifyFd(int fd, std::uint32_t events);
  // Stops watching `fd` (no effect if not watched). Does not close it.
  void removeFd(int fd) noexcept;
  bool watches(int fd) const noexcept { return fd_sources_.count(fd) != 0; }

  // ---- timers ------------------------------------------------------------------------
  // First expiry after `period`, then every `period`. Throws std::invalid_argument for a
  // period ≤ 0.
  SourceId addPeriodicTimer(std::chrono::nanoseconds period, TimerCallback callback);
  // Expires once after `delay` (> 0), then removes itself.
  SourceId addOneShotTimer(std::chrono::nanoseconds delay, TimerCallback callback);
  // Removes a timer or signal source (no effect if already gone).
  void removeSource(SourceId id) noexcept;

  // ---- signals -----------------------------------------------------------------------
  // Blocks `signals` in the calling thread. Call this in main() before any thread is
  // created, so that every thread inherits the mask. Throws std::system_error.
  static void blockSignals(std::initializer_list<int> signals);
  // Blocks `signals` (as above) and delivers them through a signalfd to `callback`.
  SourceId addSignals(std::initializer_list<int> signals, SignalCallback callback);

  // ---- deferred work -----------------------------------------------------------------
  // Runs `callback` once, after the events of the next turn (the wait of that turn does not
  // block). What is deferred during a turn never runs in that same turn.
  void defer(std::function<void()> callback);

  // ---- shared state ------------------------------------------------------------------
  // Holds `mutex` while each turn dispatches (never while it waits for events), so that
  // another thread that takes it sees the state the callbacks own between two turns. Set
  // before run(); nullptr (the default): no lock.
  void guardTurnsWith(PriorityInheritanceMutex* mutex) noexcept { turn_mutex_ = mutex; }

  // ---- running -----------------------------------------------------------------------
  // Dispatches events until stop() is called (by a callback). EINTR is retried.
  void run();
  // Waits at most `timeout` (negative: forever) for one batch of events and dispatches
  // it. Returns the number of events dispatched. For tests and for embedding.
  std::size_t runOnce(std::chrono::milliseconds timeout);
  void stop() noexcept { stopped_ = true; }
  bool stopped() const noexcept { return stopped_; }
  // The longest time one turn spent dispatching (events and deferred work, and the wait for
  // the turn's mutex, not the wait for events): how long a sample could have waited for the loop.
  std::chrono::nanoseconds longestTurn() const noexcept { return longest_turn_; }

 private:
  enum class Kind { Fd, Timer, Signal };
  struct Source {
    Kind kind = Kind::Fd;
    int fd = -1;
    Fd owned;  // the timerfd or signalfd; empty for Kind::Fd
    bool one_shot = false;
    FdCallback on_fd;
    TimerCallback on_timer;
    SignalCallback on_signal;
  };

  SourceId addSource(std::shared_ptr<Source> source, std::uint32_t events);
  SourceId addTimer(std::chrono::nanoseconds first, std::chrono::nanoseconds period, bool one_shot,
                    TimerCallback callback);
  void dispatch(SourceId id, std::uint32_t events);

  Fd epoll_;
  SourceId next_id_ = 1;
  bool stopped_ = false;
  std::unordered_map<SourceId, std::shared_ptr<Source>> sources_;
  std::unordered_map<int, SourceId> fd_sources_;  // only Kind::Fd sources
  std::vector<epoll_event> events_;
  std::vector<std::function<void()>> deferred_, running_deferred_;
  std::chrono::nanoseconds longest_turn_{0};
  PriorityInheritanceMutex* turn_mutex_ = nullptr;
};

}  // namespace gyrod::daemon
