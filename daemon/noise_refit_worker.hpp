#pragma once
// The noise refit off the event loop. refitNoiseTerms takes seconds at a 1 h window at
// 1 kHz (it identifies the noise type on the whole window at every τ: about 1.5 s per axis
// for 3.6 M samples), far longer than the chip's FIFO lasts (~128 ms at 1 kHz); on the loop
// it made gyrod lose samples. Here the loop only copies one raw stream's state into a
// buffer allocated once (~20 ms for 3.6 M samples), and a worker thread refits the copy.
// The axes are refitted one after the other, each raw stream (the noise terms and types) then
// its mean and Kalman streams (their noise types, for the ALLAN reply's intervals); the result
// of each is applied on the loop, so the pipeline is only ever touched by the loop thread. The numbers are exactly those of
// SamplePipeline::refitNoiseTerms on the state at the moment of the copy.
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "daemon/event_loop.hpp"
#include "daemon/sample_pipeline.hpp"

namespace gyrod::daemon {

class NoiseRefitWorker {
 public:
  // `pipeline` must outlive the worker; `on_cycle_done` runs on the loop after the last axis
  // of a cycle has been applied.
  NoiseRefitWorker(EventLoop& loop, SamplePipeline& pipeline, double rate_hz, std::function<void()> on_cycle_done);
  ~NoiseRefitWorker();
  NoiseRefitWorker(const NoiseRefitWorker&) = delete;
  NoiseRefitWorker& operator=(const NoiseRefitWorker&) = delete;

  // Starts refitting the three axes, unless a cycle is still running (then no effect:
  // returns false).
  bool startCycle();
  bool busy() const { return job_.has_value(); }

 private:
  void startJob(std::size_t job);  // job = axis·kStreams + stream
  void onAxisDone();
  void threadMain();

  EventLoop& loop_;
  SamplePipeline& pipeline_;
  double tau0_s_;
  std::function<void()> on_cycle_done_;
  std::optional<std::size_t> job_;  // the (axis, stream) being refitted (loop thread only)
  Fd done_fd_;                      // eventfd: the worker's "result ready" to the loop

  std::mutex mutex_;
  std::condition_variable wake_;
  bool work_ = false;      // copy_ holds a stream to refit
  bool fit_terms_ = true;  // copy_ is a raw stream: fit the noise terms too
  bool stop_ = false;
  processing::RollingOverlappingAllan copy_;  // written by the loop only while !work_
  NoiseRefit result_;
  std::thread thread_;
};

}  // namespace gyrod::daemon
