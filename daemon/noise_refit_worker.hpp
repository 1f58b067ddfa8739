#pragma once
// The noise refit off the event loop. refitNoiseTerms takes seconds at a 1 h window at
// 1 kHz (it identifies the noise type on the whole window at every τ: about 1 s per axis
// for 3.6 M samples on an x86-64 core, several on a Pi), far longer than the chip's FIFO
// lasts (~73 ms at 1 kHz); on the loop it made gyrod lose samples. Here the loop only
// copies one stream's state into a buffer allocated once, in steps of kCopyPointsPerTurn
// phase points between which the loop serves its samples (all at once, 58 MB at 3.6 M
// samples, it took a 10-20 ms turn), and a worker thread refits the copy. The axes are refitted one after the other, each raw stream
// (the noise terms and types) then its mean and Kalman streams (their noise types, for the
// ALLAN reply's intervals); the result of each is applied on the loop, so the pipeline is
// only ever touched by the loop thread. The numbers are exactly those of
// SamplePipeline::refitNoiseTerms on the state at the moment the copy began
// (RollingOverlappingAllan::beginCopyFrom).
// Stopping does not wait for a refit in progress (see ~NoiseRefitWorker): gyrod's exit on
// SIGTERM must not wait seconds for a result nobody will read.
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "daemon/event_loop.hpp"
#include "daemon/priority_inheritance_mutex.hpp"
#include "daemon/sample_pipeline.hpp"

namespace gyrod::daemon {

class NoiseRefitWorker {
 public:
  // Phase points copied per loop turn (16 B each: 1 MB, a fraction of a millisecond).
  static constexpr std::size_t kCopyPointsPerTurn = std::size_t{1} << 16;

  // What refits one axis on the worker thread: refitNoiseTerms, or a stand-in in tests.
  using RefitFunction =
      std::function<NoiseRefit(const processing::RollingOverlappingAllan&, double tau0_s, bool fit_terms)>;

  // `pipeline` must outlive the worker; `on_cycle_done` runs on the loop after the last axis
  // of a cycle has been applied.
  NoiseRefitWorker(EventLoop& loop, SamplePipeline& pipeline, double rate_hz, std::function<void()> on_cycle_done,
                   RefitFunction refit = refitNoiseTerms);
  // An idle worker thread is joined. A refit in progress is abandoned: its thread is
  // detached, finishes the arithmetic it is in (it cannot be interrupted inside
  // processing's snapshot), drops the result and ends; the process's exit ends it sooner.
  ~NoiseRefitWorker();
  NoiseRefitWorker(const NoiseRefitWorker&) = delete;
  NoiseRefitWorker& operator=(const NoiseRefitWorker&) = delete;

  // Starts refitting the three axes, unless a cycle is still running (then no effect:
  // returns false).
  bool startCycle();
  bool busy() const { return job_.has_value(); }

 private:
  // Everything the worker thread touches. Shared with the thread, which may outlive the
  // worker (an abandoned refit).
  struct Shared {
    Shared(const processing::RollingOverlappingAllan& stream, double tau0, RefitFunction function);

    double tau0_s;
    RefitFunction refit;
    Fd done_fd;  // eventfd: the worker's "result ready" to the loop
    // Shared by the loop (maybe SCHED_FIFO) and the worker (SCHED_OTHER): with priority
    // inheritance, so that the loop never waits for a preempted worker holding it.
    PriorityInheritanceMutex mutex;
    std::condition_variable_any wake;
    bool work = false;      // copy holds a stream to refit
    bool fit_terms = true;  // copy is a raw stream: fit the noise terms too
    bool stop = false;
    processing::RollingOverlappingAllan copy;  // written by the loop only while !work
    NoiseRefit result;
  };

  void startJob(std::size_t job);  // job = axis·kStreams + stream
  void copyStep();
  void onAxisDone();
  static void threadMain(const std::shared_ptr<Shared>& shared);

  EventLoop& loop_;
  SamplePipeline& pipeline_;
  std::function<void()> on_cycle_done_;
  std::optional<std::size_t> job_;  // the (axis, stream) being refitted (loop thread only)
  std::shared_ptr<Shared> shared_;
  std::thread thread_;
  // Deferred copy steps may outlive the worker in the loop: they check this first.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace gyrod::daemon
