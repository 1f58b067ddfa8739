#include "daemon/noise_refit_worker.hpp"

#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cstdint>
#include <stdexcept>
#include <string>

namespace gyrod::daemon {

NoiseRefitWorker::Shared::Shared(const processing::RollingOverlappingAllan& stream, double tau0, RefitFunction function)
    : tau0_s(tau0),
      refit(std::move(function)),
      done_fd(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)),
      copy(stream) {}  // allocated (and its pages touched) once, here

NoiseRefitWorker::NoiseRefitWorker(EventLoop& loop, SamplePipeline& pipeline, double rate_hz,
                                   std::function<void()> on_cycle_done, RefitFunction refit)
    : loop_(loop),
      pipeline_(pipeline),
      on_cycle_done_(std::move(on_cycle_done)),
      shared_(std::make_shared<Shared>(pipeline.rawAllan(0), 1.0 / rate_hz, std::move(refit))) {
  if (!shared_->refit) throw std::invalid_argument("the noise refit worker needs a refit function; none given");
  if (!shared_->done_fd) throw errnoError("eventfd for the noise refit");
  const int done_fd = shared_->done_fd.get();
  loop_.addFd(done_fd, EPOLLIN, [this, done_fd](std::uint32_t) {
    std::uint64_t count = 0;
    if (::read(done_fd, &count, sizeof count) == static_cast<ssize_t>(sizeof count)) onAxisDone();
  });
  thread_ = std::thread([shared = shared_] { threadMain(shared); });
}

NoiseRefitWorker::~NoiseRefitWorker() {
  loop_.removeFd(shared_->done_fd.get());
  bool refitting = false;
  {
    const std::lock_guard lock(shared_->mutex);
    shared_->stop = true;
    refitting = shared_->work;
  }
  shared_->wake.notify_one();
  // A refit of one axis takes seconds at a 1 h window at 1 kHz, more on a Pi, and a join
  // would hold gyrod's exit on SIGTERM that long. The thread owns what it uses (shared_).
  if (refitting)
    thread_.detach();
  else
    thread_.join();  // waiting for work or about to: it sees stop at once
}

bool NoiseRefitWorker::startCycle() {
  if (job_) return false;
  startJob(0);
  return true;
}

void NoiseRefitWorker::startJob(std::size_t job) {
  job_ = job;
  const auto stream = static_cast<AllanStream>(job % kStreams);
  // The worker does not touch copy while work is unset: no lock for the copy itself.
  shared_->copy.beginCopyFrom(pipeline_.allanStream(job / kStreams, stream));
  copyStep();
}

void NoiseRefitWorker::copyStep() {
  if (!job_) return;
  const auto stream = static_cast<AllanStream>(*job_ % kStreams);
  const auto& source = pipeline_.allanStream(*job_ / kStreams, stream);
  switch (shared_->copy.continueCopyFrom(source, kCopyPointsPerTurn)) {
    case processing::RollingOverlappingAllan::CopyStep::Overrun: shared_->copy.beginCopyFrom(source); [[fallthrough]];
    case processing::RollingOverlappingAllan::CopyStep::Copying:
      // The rest after the next turn's events: the samples never wait for more than one step.
      loop_.defer([this, alive = std::weak_ptr<bool>(alive_)] {
        if (!alive.expired()) copyStep();
      });
      return;
    case processing::RollingOverlappingAllan::CopyStep::Done: break;
  }
  {
    const std::lock_guard lock(shared_->mutex);
    shared_->fit_terms = stream == AllanStream::Raw;
    shared_->work = true;
  }
  shared_->wake.notify_one();
}

void NoiseRefitWorker::onAxisDone() {
  if (!job_) return;
  NoiseRefit result;
  {
    const std::lock_guard lock(shared_->mutex);
    if (shared_->work) return;  // not done yet (a stale wake-up)
    result = std::move(shared_->result);
  }
  pipeline_.applyNoiseRefit(*job_ / kStreams, static_cast<AllanStream>(*job_ % kStreams), result);
  if (*job_ + 1 < kAxes * kStreams) {
    startJob(*job_ + 1);
    return;
  }
  job_.reset();
  if (on_cycle_done_) on_cycle_done_();
}

void NoiseRefitWorker::threadMain(const std::shared_ptr<Shared>& shared) {
  // Seconds of arithmetic must never compete with the loop: when gyrod runs SCHED_FIFO, a
  // thread of the same priority would keep the loop off a single CPU until it finished.
  const sched_param normal{};
  ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &normal);
  Shared& s = *shared;
  std::unique_lock lock(s.mutex);
  while (true) {
    s.wake.wait(lock, [&s] { return s.work || s.stop; });
    if (s.stop) return;
    // Unlocked while refitting: the loop does not write copy while work is set.
    lock.unlock();
    NoiseRefit result;
    std::string error;
    try {
      result = s.refit(s.copy, s.tau0_s, s.fit_terms);
    } catch (const std::exception& e) {
      error = e.what();
    }
    lock.lock();
    // Abandoned (~NoiseRefitWorker): nobody reads the result, and the process may be exiting
    // (its logger with it). Otherwise the worker cannot finish destruction while this holds the lock.
    if (s.stop) return;
    if (!error.empty()) spdlog::error("noise refit failed: {}", error);
    s.result = std::move(result);
    s.work = false;
    // Woken once the lock is free: the loop takes it as soon as it reads the eventfd.
    lock.unlock();
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(s.done_fd.get(), &one, sizeof one);
    lock.lock();
  }
}

}  // namespace gyrod::daemon
