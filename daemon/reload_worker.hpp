#pragma once
// SIGHUP's reading and checking off the event loop. Reading the configuration and the files
// it names (a model file, a replay file) can take long: a large file, a slow disk, a network
// mount that hangs. On the loop that would stop the samples (the chip's FIFO lasts ~128 ms at
// 1 kHz) and SIGTERM with them. Here each reload runs `load` on a thread of its own, at
// normal priority; the loop waits for nothing: when the result is ready it runs `apply` with
// it (so the running state is only ever touched by the loop thread), or `fail` with the
// reason when `load` threw or did not finish within the time limit. A load past its limit is
// abandoned: its thread is detached and its result dropped whenever it comes.
// A request while a reload runs is remembered, and one more reload starts when it ends, so
// that the last edit is always read.
#include <pthread.h>
#include <sched.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "daemon/event_loop.hpp"

namespace gyrod::daemon {

template <typename Settings>
class ReloadWorker {
 public:
  using Load = std::function<Settings()>;  // runs on the reload's thread: touches nothing of the loop's
  using Apply = std::function<void(Settings&&)>;
  using Fail = std::function<void(const std::string& why)>;

  ReloadWorker(EventLoop& loop, std::chrono::milliseconds time_limit, Load load, Apply apply, Fail fail)
      : loop_(loop),
        time_limit_(time_limit),
        load_(std::move(load)),
        apply_(std::move(apply)),
        fail_(std::move(fail)) {}
  ~ReloadWorker() { forgetCurrent(); }
  ReloadWorker(const ReloadWorker&) = delete;
  ReloadWorker& operator=(const ReloadWorker&) = delete;

  // Starts a reload, or, while one runs, asks for one more after it.
  void request() {
    if (current_)
      another_ = true;
    else
      start();
  }
  bool running() const { return current_ != nullptr; }
  std::chrono::milliseconds timeLimit() const { return time_limit_; }

 private:
  // What one reload's thread shares with the loop; the thread may outlive the worker.
  struct Attempt {
    Fd done_fd;  // eventfd: "the result is ready"
    std::mutex mutex;
    std::optional<Settings> result;
    std::string error;
  };

  void start() {
    auto attempt = std::make_shared<Attempt>();
    attempt->done_fd = Fd(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
    if (!attempt->done_fd) {
      fail_("cannot start the reload: eventfd failed");
      return;
    }
    loop_.addFd(attempt->done_fd.get(), EPOLLIN, [this, attempt](std::uint32_t) { finish(attempt); });
    timer_ = loop_.addOneShotTimer(time_limit_, [this, attempt](std::uint64_t) { timeOut(attempt); });
    current_ = attempt;
    try {
      std::thread([attempt, load = load_] { run(*attempt, load); }).detach();
    } catch (const std::exception& e) {
      forgetCurrent();
      fail_(std::string("cannot start the reload's thread: ") + e.what());
    }
  }

  static void run(Attempt& attempt, const Load& load) {
    // Never in competition with the loop, which may run SCHED_FIFO.
    const sched_param normal{};
    ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &normal);
    std::optional<Settings> result;
    std::string error;
    try {
      result.emplace(load());
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
    std::optional<Settings> result;
    std::string error;
    {
      const std::lock_guard lock(attempt->mutex);
      result = std::move(attempt->result);
      error = std::move(attempt->error);
    }
    if (!result && error.empty()) return;  // a wake-up before the result (cannot happen; harmless)
    forgetCurrent();
    if (result)
      apply_(std::move(*result));
    else
      fail_(error);
    startAnother();
  }

  void timeOut(const std::shared_ptr<Attempt>& attempt) {
    if (attempt != current_) return;
    forgetCurrent();
    fail_("reading and checking the configuration took longer than " + std::to_string(time_limit_.count()) +
          " ms (abandoned)");
    startAnother();
  }

  void forgetCurrent() {
    if (!current_) return;
    loop_.removeFd(current_->done_fd.get());
    loop_.removeSource(timer_);
    current_.reset();
  }

  void startAnother() {
    if (!another_) return;
    another_ = false;
    start();
  }

  EventLoop& loop_;
  std::chrono::milliseconds time_limit_;
  Load load_;
  Apply apply_;
  Fail fail_;
  std::shared_ptr<Attempt> current_;
  EventLoop::SourceId timer_ = 0;
  bool another_ = false;
};

}  // namespace gyrod::daemon
