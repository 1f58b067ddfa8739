#pragma once
// SIGHUP's reading and checking off the event loop. Reading the configuration and the files
// it names (a model file, a replay file) can take long: a large file, a slow disk, a network
// mount that hangs. On the loop that would stop the samples (the chip's FIFO lasts ~73 ms at
// 1 kHz) and SIGTERM with them. Here each reload runs `load` on a thread of its own, at
// normal priority (daemon/off_loop_job.hpp); the loop waits for nothing: when the result is
// ready it runs `apply` with it (so the running state is only ever touched by the loop
// thread), or `fail` with the reason when `load` threw or did not finish within the time
// limit. A load past its limit is abandoned: its thread finishes and its result is dropped.
// A request while a reload runs is remembered, and one more reload starts when it ends, so
// that the last edit is always read.
#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <string>
#include <utility>

#include "daemon/event_loop.hpp"
#include "daemon/off_loop_job.hpp"

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
        fail_(std::move(fail)),
        job_(
            loop,
            [this](Settings&& settings) {
              stopTimer();
              apply_(std::move(settings));
              startAnother();
            },
            [this](const std::string& why) {
              stopTimer();
              fail_(why);
              startAnother();
            }) {}
  ~ReloadWorker() { stopTimer(); }
  ReloadWorker(const ReloadWorker&) = delete;
  ReloadWorker& operator=(const ReloadWorker&) = delete;

  // Starts a reload, or, while one runs, asks for one more after it.
  void request() {
    if (job_.running())
      another_ = true;
    else
      start();
  }
  bool running() const { return job_.running(); }
  std::chrono::milliseconds timeLimit() const { return time_limit_; }

 private:
  void start() {
    try {
      job_.start(load_);
    } catch (const std::exception& e) {
      fail_(std::string("cannot start the reload: ") + e.what());
      return;
    }
    timer_ = loop_.addOneShotTimer(time_limit_, [this](std::uint64_t) { timeOut(); });
  }

  void timeOut() {
    timer_ = 0;
    job_.abandon();
    fail_("reading and checking the configuration took longer than " + std::to_string(time_limit_.count()) +
          " ms (abandoned)");
    startAnother();
  }

  void stopTimer() {
    if (timer_ != 0) loop_.removeSource(timer_);
    timer_ = 0;
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
  OffLoopJob<Settings> job_;
  EventLoop::SourceId timer_ = 0;
  bool another_ = false;
};

}  // namespace gyrod::daemon
