#include "daemon/noise_refit_worker.hpp"

#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cstdint>

namespace gyrod::daemon {

NoiseRefitWorker::NoiseRefitWorker(EventLoop& loop, SamplePipeline& pipeline, double rate_hz,
                                   std::function<void()> on_cycle_done)
    : loop_(loop),
      pipeline_(pipeline),
      tau0_s_(1.0 / rate_hz),
      on_cycle_done_(std::move(on_cycle_done)),
      done_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)),
      copy_(pipeline.rawAllan(0)) {  // allocated (and its pages touched) once, here
  if (!done_fd_) throw errnoError("eventfd for the noise refit");
  loop_.addFd(done_fd_.get(), EPOLLIN, [this](std::uint32_t) {
    std::uint64_t count = 0;
    if (::read(done_fd_.get(), &count, sizeof count) == static_cast<ssize_t>(sizeof count)) onAxisDone();
  });
  thread_ = std::thread([this] { threadMain(); });
}

NoiseRefitWorker::~NoiseRefitWorker() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();  // a refit in progress finishes first (seconds at most)
  loop_.removeFd(done_fd_.get());
}

bool NoiseRefitWorker::startCycle() {
  if (job_) return false;
  startJob(0);
  return true;
}

void NoiseRefitWorker::startJob(std::size_t job) {
  job_ = job;
  const auto stream = static_cast<AllanStream>(job % kStreams);
  {
    const std::lock_guard lock(mutex_);
    copy_ = pipeline_.allanStream(job / kStreams, stream);  // same sizes: reuses copy_'s memory
    fit_terms_ = stream == AllanStream::Raw;
    work_ = true;
  }
  wake_.notify_one();
}

void NoiseRefitWorker::onAxisDone() {
  if (!job_) return;
  NoiseRefit result;
  {
    const std::lock_guard lock(mutex_);
    if (work_) return;  // not done yet (a stale wake-up)
    result = std::move(result_);
  }
  pipeline_.applyNoiseRefit(*job_ / kStreams, static_cast<AllanStream>(*job_ % kStreams), result);
  if (*job_ + 1 < kAxes * kStreams) {
    startJob(*job_ + 1);
    return;
  }
  job_.reset();
  if (on_cycle_done_) on_cycle_done_();
}

void NoiseRefitWorker::threadMain() {
  // Seconds of arithmetic must never compete with the loop: when gyrod runs SCHED_FIFO, a
  // thread of the same priority would keep the loop off a single CPU until it finished.
  const sched_param normal{};
  ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &normal);
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return work_ || stop_; });
    if (stop_) return;
    // Unlocked while refitting: the loop does not write copy_ while work_ is set.
    lock.unlock();
    NoiseRefit result;
    try {
      result = refitNoiseTerms(copy_, tau0_s_, fit_terms_);
    } catch (const std::exception& e) {
      spdlog::error("noise refit failed: {}", e.what());
    }
    lock.lock();
    result_ = std::move(result);
    work_ = false;
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(done_fd_.get(), &one, sizeof one);
  }
}

}  // namespace gyrod::daemon
