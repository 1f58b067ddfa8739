#pragma once
// Times the machine itself while a real-time test runs: one thread per CPU, pinned to it,
// SCHED_FIFO above gyrod, waking every millisecond on an absolute CLOCK_MONOTONIC deadline.
// Such a thread is late only when its CPU was not running at all (a virtual machine's CPU
// descheduled by its host, or the whole guest held back): nothing of gyrod's or of the test's
// can delay it. A sample lost while a probe saw the machine stop for longer than the chip's
// FIFO holds is the machine's; one lost with no such stall is gyrod's.
#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <thread>
#include <vector>

namespace gyrod::test {

class MachineStallProbe {
 public:
  struct Stall {
    double end_s = 0.0;  // CLOCK_MONOTONIC, when the probe ran again
    double length_ms = 0.0;
    unsigned cpu = 0;
  };

  // Stalls shorter than `report_ms` are not kept. Starts nothing when real-time scheduling is
  // refused (then running() is false and every question is answered with "no stall").
  explicit MachineStallProbe(double report_ms = 2.0) : report_ms_(report_ms) {
    timespec real{}, mono{};
    ::clock_gettime(CLOCK_REALTIME, &real);
    ::clock_gettime(CLOCK_MONOTONIC, &mono);
    realtime_minus_monotonic_s_ = seconds(real) - seconds(mono);
    cpus_ = std::max(1u, std::thread::hardware_concurrency());
    const unsigned cpus = cpus_;
    for (unsigned cpu = 0; cpu < cpus; ++cpu) threads_.emplace_back([this, cpu] { probe(cpu); });
    // Each thread reports whether it became real-time before it starts timing.
    while (started_.load() < static_cast<int>(cpus)) std::this_thread::yield();
  }
  ~MachineStallProbe() {
    stop_ = true;
    for (auto& t : threads_) t.join();
  }
  MachineStallProbe(const MachineStallProbe&) = delete;
  MachineStallProbe& operator=(const MachineStallProbe&) = delete;

  bool running() const { return real_time_.load() > 0; }

  std::vector<Stall> stalls() const {
    const std::lock_guard lock(mutex_);
    return stalls_;
  }
  double longestMs() const {
    double longest = 0.0;
    for (const Stall& s : stalls()) longest = std::max(longest, s.length_ms);
    return longest;
  }
  // A stall of at least `min_ms` that ended in [t_s - before_s, t_s].
  bool stalledBefore(double t_s, double before_s, double min_ms) const {
    for (const Stall& s : stalls())
      if (s.length_ms >= min_ms && s.end_s <= t_s && s.end_s >= t_s - before_s) return true;
    return false;
  }
  // The most time one CPU stood still in [t_s - window_s, t_s], in ms: what the host took from
  // a thread that ran there. Many short stops add up: on a busy host a CPU stopped 2-7 ms a
  // hundred times a second, each stop below any one-stop threshold, and together they cost a
  // thread a full FIFO.
  double stolenMsBefore(double t_s, double window_s) const {
    std::vector<double> per_cpu(cpus_, 0.0);
    const double from = t_s - window_s;
    for (const Stall& s : stalls()) {
      const double start = s.end_s - s.length_ms * 1e-3;
      const double overlap = std::min(s.end_s, t_s) - std::max(start, from);
      if (overlap > 0.0 && s.cpu < per_cpu.size()) per_cpu[s.cpu] += overlap * 1e3;
    }
    return per_cpu.empty() ? 0.0 : *std::max_element(per_cpu.begin(), per_cpu.end());
  }
  // A CLOCK_REALTIME instant (a log line's time stamp) on the probes' CLOCK_MONOTONIC.
  double monotonicFromRealtime(double realtime_s) const { return realtime_s - realtime_minus_monotonic_s_; }

 private:
  static double seconds(const timespec& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
  }

  void probe(unsigned cpu) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    const bool pinned = ::pthread_setaffinity_np(::pthread_self(), sizeof set, &set) == 0;
    sched_param fifo{};
    fifo.sched_priority = 50;  // above gyrod (10) and its watcher (9): their load cannot delay it
    const bool real_time = pinned && ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &fifo) == 0;
    if (real_time) ++real_time_;
    ++started_;
    if (!real_time) return;
    constexpr long kPeriodNs = 1'000'000;
    timespec next{};
    ::clock_gettime(CLOCK_MONOTONIC, &next);
    while (!stop_) {
      next.tv_nsec += kPeriodNs;
      if (next.tv_nsec >= 1'000'000'000) {
        next.tv_nsec -= 1'000'000'000;
        ++next.tv_sec;
      }
      ::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
      timespec now{};
      ::clock_gettime(CLOCK_MONOTONIC, &now);
      const double late_ms = (seconds(now) - seconds(next)) * 1e3;
      if (late_ms >= report_ms_) {
        const std::lock_guard lock(mutex_);
        stalls_.push_back({seconds(now), late_ms, cpu});
      }
      if (late_ms > 1.0) next = now;  // no burst of catch-up wake-ups after a stall
    }
  }

  double report_ms_;
  double realtime_minus_monotonic_s_ = 0.0;
  unsigned cpus_ = 1;
  std::atomic<bool> stop_{false};
  std::atomic<int> started_{0}, real_time_{0};
  mutable std::mutex mutex_;
  std::vector<Stall> stalls_;
  std::vector<std::thread> threads_;
};

}  // namespace gyrod::test
