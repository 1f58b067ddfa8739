#pragma once
// One computation off the event loop: start() runs `work` on a thread of its own at normal
// priority, and the loop runs `done` with its result (or `failed` with the exception's message)
// when it is ready, so that the state the loop owns is only ever touched by the loop. gyrod uses
// it for the end of the start-up still window (the motion check and the filter's identification:
// tens of milliseconds at 8 kHz, longer than the chip's FIFO holds there) and for SIGHUP's
// reading (daemon/reload_worker.hpp). One job at a time.
// A job still running when the object is destroyed is abandoned: its thread finishes and drops
// the result.
#include <pthread.h>
#include <sched.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "daemon/event_loop.hpp"

namespace gyrod::daemon {

template <typename Result>
class OffLoopJob {
 public:
  using Done = std::function<void(Result&&)>;
  using Failed = std::function<void(const std::string& why)>;

  OffLoopJob(EventLoop& loop, Done done, Failed failed)
      : loop_(loop), done_(std::move(done)), failed_(std::move(failed)) {}
  ~OffLoopJob() { forgetCurrent(); }
  OffLoopJob(const OffLoopJob&) = delete;
  OffLoopJob& operator=(const OffLoopJob&) = delete;

  bool running() const { return current_ != nullptr; }
  // Forgets the running job, if any: its thread finishes and its result is dropped.
  void abandon() { forgetCurrent(); }

  // Throws std::logic_error while a job runs, std::system_error when no eventfd or thread can be had.
  void start(std::function<Result()> work) {
    if (current_) throw std::logic_error("an off-loop job is already running");
    auto attempt = std::make_shared<Attempt>();
    attempt->done_fd = Fd(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
    if (!attempt->done_fd) throw errnoError("eventfd for an off-loop job");
    loop_.addFd(attempt->done_fd.get(), EPOLLIN, [this, attempt](std::uint32_t) { finish(attempt); });
    current_ = attempt;
    try {
      std::thread([attempt, work = std::move(work)] { run(*attempt, work); }).detach();
    } catch (...) {
      forgetCurrent();
      throw;
    }
  }

 private:
  struct Attempt {
    Fd done_fd;  // eventfd: "the result is ready"
    std::mutex mutex;
    std::optional<Result> result;
    std::string error;
  };

  static void run(Attempt& attempt, const std::function<Result()>& work) {
    // Never in competition with the loop, which may run SCHED_FIFO.
    const sched_param normal{};
    ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &normal);
    std::optional<Result> result;
    std::string error;
    try {
      result.emplace(work());
    } catch (const std::exception& e) {
      error = e.what();
      if (error.empty()) error = "unknown error";
    }
    {
      const std::lock_guard lock(attempt.mutex);
      attempt.result = std::move(result);
      attempt.error = std::move(error);
    }
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(attempt.done_fd.get(), &one, sizeof one);
  }

  void finish(const std::shared_ptr<Attempt>& attempt) {
    if (attempt != current_) return;
    std::optional<Result> result;
    std::string error;
    {
      const std::lock_guard lock(attempt->mutex);
      result = std::move(attempt->result);
      error = std::move(attempt->error);
    }
    if (!result && error.empty()) return;  // a wake-up before the result (cannot happen; harmless)
    forgetCurrent();
    if (result)
      done_(std::move(*result));
    else
      failed_(error);
  }

  void forgetCurrent() {
    if (!current_) return;
    loop_.removeFd(current_->done_fd.get());
    current_.reset();
  }

  EventLoop& loop_;
  Done done_;
  Failed failed_;
  std::shared_ptr<Attempt> current_;
};

}  // namespace gyrod::daemon
