#pragma once
// Splitting a loop over [0, count) into contiguous shares run on the machine's cores.
// Callers write each share's results to their own slots and combine them in index order
// afterwards, so a result never depends on the number of threads.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <span>
#include <thread>
#include <vector>

namespace gyrod::processing {

// Threads worth starting: the cores, at most kMaxShareThreads (the loops it serves are
// memory-bound beyond a few cores).
inline constexpr std::size_t kMaxShareThreads = 4;

// A fixed thread count instead of the cores' (0: the cores), so that a test can show a result
// is the same bits with 1, 2, 3 or more threads whatever machine it runs on.
inline std::atomic<std::size_t>& shareThreadOverride() {
  static std::atomic<std::size_t> threads{0};
  return threads;
}
inline std::size_t shareThreadCount() {
  const std::size_t fixed = shareThreadOverride().load(std::memory_order_relaxed);
  if (fixed != 0) return fixed;
  return std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1, kMaxShareThreads);
}

// Calls body(first, end) for contiguous shares covering [0, count), one per thread, the last
// share on the calling thread; below `min_per_thread` items per thread it stays on one.
template <typename Body>
void forEachShare(std::size_t count, Body&& body, std::size_t min_per_thread = 16) {
  const std::size_t threads = std::min(shareThreadCount(), std::max<std::size_t>(1, count / min_per_thread));
  if (threads <= 1) {
    body(std::size_t{0}, count);
    return;
  }
  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  const auto boundary = [&](std::size_t t) { return count * t / threads; };
  for (std::size_t t = 0; t + 1 < threads; ++t) workers.emplace_back([&, t] { body(boundary(t), boundary(t + 1)); });
  body(boundary(threads - 1), count);
  for (auto& w : workers) w.join();
}

// Runs first() and second() at once (second on the calling thread) when there are two cores,
// else one after the other. Each writes only its own results, so nothing depends on the
// thread count. An exception from either is rethrown once both have ended, first()'s before
// second()'s: the one the sequential order would have thrown.
template <typename First, typename Second>
void runBoth(First&& first, Second&& second) {
  if (shareThreadCount() <= 1) {
    first();
    second();
    return;
  }
  std::exception_ptr first_error;
  std::exception_ptr second_error;
  std::thread worker([&] {
    try {
      first();
    } catch (...) {
      first_error = std::current_exception();
    }
  });
  try {
    second();
  } catch (...) {
    second_error = std::current_exception();
  }
  worker.join();
  if (first_error) std::rethrow_exception(first_error);
  if (second_error) std::rethrow_exception(second_error);
}

// Runs every task once, on two threads where there are two cores (the calling thread and one
// more), each taking the next task not yet taken: put the longest first and the two threads
// end close together, however unequal the tasks. Each task writes only its own results, so
// nothing depends on which thread ran it. The first exception in task order is rethrown once
// all have ended.
template <typename Task>
void runTasksOnBothCores(std::span<Task> tasks) {
  std::vector<std::exception_ptr> errors(tasks.size());
  std::atomic<std::size_t> next{0};
  const auto take = [&] {
    for (std::size_t t = next.fetch_add(1); t < tasks.size(); t = next.fetch_add(1)) {
      try {
        tasks[t]();
      } catch (...) {
        errors[t] = std::current_exception();
      }
    }
  };
  if (shareThreadCount() <= 1 || tasks.size() <= 1) {
    take();
  } else {
    std::thread worker(take);
    take();
    worker.join();
  }
  for (const auto& error : errors)
    if (error) std::rethrow_exception(error);
}

}  // namespace gyrod::processing
