#pragma once
// The lines the MQTT publisher keeps for a broker that is away (daemon/mqtt_publisher.hpp):
// first in, first out, at most `limit`, the oldest dropped to make room. The storage is one
// array that grows by doubling as lines come (a board that never loses its broker never pays
// for a full buffer) and never shrinks, so that a long outage costs limit × sizeof(T) plus, for
// the moment of the last growth, the half it grew from. Publisher thread only.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace gyrod::daemon {

template <class T>
class KeptLines {
 public:
  explicit KeptLines(std::size_t limit) : limit_(limit) {}

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const T& front() const { return slots_[head_]; }
  void popFront() {
    head_ = (head_ + 1) % slots_.size();
    --size_;
  }
  // False when the oldest line was dropped to make room (limit 0: `line` itself is dropped).
  bool pushBack(const T& line) {
    if (limit_ == 0) return false;
    bool kept_all = true;
    if (size_ == slots_.size() && slots_.size() < limit_) grow();
    if (size_ == slots_.size()) {  // full at the limit
      popFront();
      kept_all = false;
    }
    slots_[(head_ + size_) % slots_.size()] = line;
    ++size_;
    return kept_all;
  }

 private:
  void grow() {
    std::vector<T> bigger(std::min(limit_, std::max<std::size_t>(64, 2 * slots_.size())));
    for (std::size_t i = 0; i < size_; ++i) bigger[i] = slots_[(head_ + i) % slots_.size()];
    slots_.swap(bigger);
    head_ = 0;
  }

  std::size_t limit_;
  std::vector<T> slots_;
  std::size_t head_ = 0, size_ = 0;
};

}  // namespace gyrod::daemon
