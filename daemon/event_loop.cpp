#include "daemon/event_loop.hpp"

#include <signal.h>
#include <sys/signalfd.h>
#include <sys/timerfd.h>

#include <algorithm>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

namespace gyrod::daemon {
namespace {

constexpr int kMaxEventsPerWait = 64;

timespec toTimespec(std::chrono::nanoseconds d) {
  const auto s = std::chrono::duration_cast<std::chrono::seconds>(d);
  return timespec{static_cast<time_t>(s.count()), static_cast<long>((d - s).count())};
}

sigset_t signalSet(std::initializer_list<int> signals) {
  sigset_t set;
  sigemptyset(&set);
  for (const int s : signals) {
    if (sigaddset(&set, s) != 0)
      throw std::invalid_argument("the event loop cannot watch signal " + std::to_string(s) +
                                  ": it is not a signal number");
  }
  return set;
}

}  // namespace

EventLoop::EventLoop() : epoll_(::epoll_create1(EPOLL_CLOEXEC)), events_(kMaxEventsPerWait) {
  if (!epoll_) throw errnoError("epoll_create1");
}

EventLoop::~EventLoop() = default;

EventLoop::SourceId EventLoop::addSource(std::shared_ptr<Source> source, std::uint32_t events) {
  const SourceId id = next_id_++;
  epoll_event ev{};
  ev.events = events;
  ev.data.u64 = id;
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, source->fd, &ev) != 0)
    throw errnoError("epoll_ctl(ADD, fd " + std::to_string(source->fd) + ")");
  sources_.emplace(id, std::move(source));
  return id;
}

void EventLoop::addFd(int fd, std::uint32_t events, FdCallback callback) {
  if (fd < 0)
    throw std::invalid_argument("the event loop cannot watch fd " + std::to_string(fd) + ": it is not a descriptor");
  if (watches(fd)) throw std::invalid_argument("the event loop cannot watch fd " + std::to_string(fd) + " twice");
  if (!callback) throw std::invalid_argument("the event loop needs a callback for a descriptor; none given");
  auto source = std::make_shared<Source>();
  source->kind = Kind::Fd;
  source->fd = fd;
  source->on_fd = std::move(callback);
  const SourceId id = addSource(std::move(source), events);
  fd_sources_.emplace(fd, id);
}

void EventLoop::modifyFd(int fd, std::uint32_t events) {
  const auto it = fd_sources_.find(fd);
  if (it == fd_sources_.end())
    throw std::invalid_argument("the event loop cannot change fd " + std::to_string(fd) + ": it is not watched");
  epoll_event ev{};
  ev.events = events;
  ev.data.u64 = it->second;
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_MOD, fd, &ev) != 0)
    throw errnoError("epoll_ctl(MOD, fd " + std::to_string(fd) + ")");
}

void EventLoop::removeFd(int fd) noexcept {
  const auto it = fd_sources_.find(fd);
  if (it == fd_sources_.end()) return;
  ::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, fd, nullptr);
  sources_.erase(it->second);
  fd_sources_.erase(it);
}

EventLoop::SourceId EventLoop::addTimer(std::chrono::nanoseconds first, std::chrono::nanoseconds period, bool one_shot,
                                        TimerCallback callback) {
  if (!callback) throw std::invalid_argument("the event loop needs a callback for a timer; none given");
  auto source = std::make_shared<Source>();
  source->kind = Kind::Timer;
  source->owned.reset(::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC));
  if (!source->owned) throw errnoError("timerfd_create");
  source->fd = source->owned.get();
  source->one_shot = one_shot;
  source->on_timer = std::move(callback);
  itimerspec spec{};
  spec.it_value = toTimespec(first);
  spec.it_interval = toTimespec(period);
  if (::timerfd_settime(source->fd, 0, &spec, nullptr) != 0) throw errnoError("timerfd_settime");
  return addSource(std::move(source), EPOLLIN);
}

EventLoop::SourceId EventLoop::addPeriodicTimer(std::chrono::nanoseconds period, TimerCallback callback) {
  if (period <= std::chrono::nanoseconds::zero())
    throw std::invalid_argument("the event loop needs a timer period > 0 (got " + std::to_string(period.count()) +
                                " ns)");
  return addTimer(period, period, false, std::move(callback));
}

EventLoop::SourceId EventLoop::addOneShotTimer(std::chrono::nanoseconds delay, TimerCallback callback) {
  if (delay <= std::chrono::nanoseconds::zero())
    throw std::invalid_argument("the event loop needs a timer delay > 0 (got " + std::to_string(delay.count()) +
                                " ns)");
  return addTimer(delay, std::chrono::nanoseconds::zero(), true, std::move(callback));
}

void EventLoop::removeSource(SourceId id) noexcept {
  const auto it = sources_.find(id);
  if (it == sources_.end()) return;
  ::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, it->second->fd, nullptr);
  if (it->second->kind == Kind::Fd) fd_sources_.erase(it->second->fd);
  sources_.erase(it);
}

void EventLoop::blockSignals(std::initializer_list<int> signals) {
  const sigset_t set = signalSet(signals);
  if (const int rc = ::pthread_sigmask(SIG_BLOCK, &set, nullptr); rc != 0)
    throw std::system_error(rc, std::generic_category(), "pthread_sigmask(SIG_BLOCK)");
}

EventLoop::SourceId EventLoop::addSignals(std::initializer_list<int> signals, SignalCallback callback) {
  if (!callback) throw std::invalid_argument("the event loop needs a callback for signals; none given");
  blockSignals(signals);
  const sigset_t set = signalSet(signals);
  auto source = std::make_shared<Source>();
  source->kind = Kind::Signal;
  source->owned.reset(::signalfd(-1, &set, SFD_NONBLOCK | SFD_CLOEXEC));
  if (!source->owned) throw errnoError("signalfd");
  source->fd = source->owned.get();
  source->on_signal = std::move(callback);
  return addSource(std::move(source), EPOLLIN);
}

void EventLoop::dispatch(SourceId id, std::uint32_t events) {
  const auto it = sources_.find(id);
  if (it == sources_.end()) return;  // removed by an earlier callback of this batch
  // Keep the source alive while its callback runs, even if the callback removes it.
  const std::shared_ptr<Source> source = it->second;
  switch (source->kind) {
    case Kind::Fd: source->on_fd(events); break;
    case Kind::Timer: {
      std::uint64_t expirations = 0;
      const ssize_t n = ::read(source->fd, &expirations, sizeof expirations);
      if (n != static_cast<ssize_t>(sizeof expirations)) return;  // EAGAIN: already consumed
      if (source->one_shot) removeSource(id);
      source->on_timer(expirations);
      break;
    }
    case Kind::Signal: {
      signalfd_siginfo info;
      while (::read(source->fd, &info, sizeof info) == static_cast<ssize_t>(sizeof info)) {
        source->on_signal(static_cast<int>(info.ssi_signo));
        if (sources_.count(id) == 0) break;  // the callback removed this source
      }
      break;
    }
  }
}

void EventLoop::defer(std::function<void()> callback) {
  if (!callback) throw std::invalid_argument("the event loop needs a callback to defer; none given");
  deferred_.push_back(std::move(callback));
}

std::size_t EventLoop::runOnce(std::chrono::milliseconds timeout) {
  int timeout_ms = timeout.count() < 0 ? -1 : static_cast<int>(timeout.count());
  if (!deferred_.empty()) timeout_ms = 0;
  const int n = ::epoll_wait(epoll_.get(), events_.data(), static_cast<int>(events_.size()), timeout_ms);
  if (n < 0) {
    if (errno == EINTR) return 0;
    throw errnoError("epoll_wait");
  }
  const auto turn_start = std::chrono::steady_clock::now();
  std::unique_lock<PriorityInheritanceMutex> state;
  if (turn_mutex_ != nullptr) state = std::unique_lock(*turn_mutex_);
  // Taken before the events are dispatched: what they defer waits for the next turn.
  running_deferred_.swap(deferred_);
  for (int i = 0; i < n; ++i)
    dispatch(events_[static_cast<std::size_t>(i)].data.u64, events_[static_cast<std::size_t>(i)].events);
  for (auto& callback : running_deferred_) callback();
  running_deferred_.clear();
  if (state.owns_lock()) state.unlock();
  longest_turn_ =
      std::max(longest_turn_,
               std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - turn_start));
  return static_cast<std::size_t>(n);
}

void EventLoop::run() {
  stopped_ = false;
  while (!stopped_) runOnce(std::chrono::milliseconds(-1));
}

}  // namespace gyrod::daemon
