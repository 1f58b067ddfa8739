#pragma once
// Bounded lock-free ring for exactly one producer thread and one consumer thread.
// Storage is allocated once in the constructor; tryPush/tryPop never allocate, lock or
// make a system call. Head and tail are free-running counters (their difference is the
// fill level), so all `capacity` slots are usable and wrap-around needs no special case.
#include <atomic>
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace gyrod::daemon {

template <class T>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "slots are copied with plain assignment");

 public:
  // Capacity is min_capacity rounded up to a power of two (so that index = counter & mask).
  explicit SpscRing(std::size_t min_capacity) {
    if (min_capacity == 0 || min_capacity > (std::size_t{1} << 30))
      throw std::invalid_argument("the sample queue needs a capacity of 1..2^30 samples (got " +
                                  std::to_string(min_capacity) + ")");
    std::size_t c = 1;
    while (c < min_capacity) c <<= 1;
    capacity_ = c;
    mask_ = c - 1;
    slots_ = std::make_unique<T[]>(c);
  }
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // Producer only. False when full (the value is not stored).
  bool tryPush(const T& value) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail - head_cache_ == capacity_) {
      head_cache_ = head_.load(std::memory_order_acquire);  // pairs with tryPop's release
      if (tail - head_cache_ == capacity_) return false;
    }
    slots_[tail & mask_] = value;
    tail_.store(tail + 1, std::memory_order_release);  // publishes the slot to the consumer
    return true;
  }

  // Consumer only. False when empty.
  bool tryPop(T& out) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_cache_) {
      tail_cache_ = tail_.load(std::memory_order_acquire);  // pairs with tryPush's release
      if (head == tail_cache_) return false;
    }
    out = slots_[head & mask_];
    head_.store(head + 1, std::memory_order_release);  // hands the slot back to the producer
    return true;
  }

  std::size_t capacity() const noexcept { return capacity_; }
  // Producer only: how many values wait, at least (the consumer may have taken some since).
  std::size_t sizeSeenByProducer() const noexcept {
    return tail_.load(std::memory_order_relaxed) - head_.load(std::memory_order_acquire);
  }

 private:
  // Each side's counter and its cached copy of the other side's counter share a cache
  // line that the other side only reads occasionally.
  alignas(64) std::atomic<std::size_t> head_{0};  // written by the consumer
  std::size_t tail_cache_ = 0;                    // consumer's view of tail_
  alignas(64) std::atomic<std::size_t> tail_{0};  // written by the producer
  std::size_t head_cache_ = 0;                    // producer's view of head_
  alignas(64) std::size_t capacity_ = 0;
  std::size_t mask_ = 0;
  std::unique_ptr<T[]> slots_;
};

}  // namespace gyrod::daemon
