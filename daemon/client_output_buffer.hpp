#pragma once
// A client's output buffer in the socket server: preallocated at connect, so that queueing
// a line on the per-sample path never allocates.
#include <sys/uio.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>
#include <memory>

namespace gyrod::daemon {

// Preallocated ring of bytes: whole lines in, any prefix out (partial writes).
class ClientOutputBuffer {
 public:
  explicit ClientOutputBuffer(std::size_t capacity) : data_(new char[capacity]), capacity_(capacity) {}
  std::size_t size() const noexcept { return size_; }
  std::size_t free() const noexcept { return capacity_ - size_; }
  bool empty() const noexcept { return size_ == 0; }
  std::size_t capacity() const noexcept { return capacity_; }
  // Caller checks free() first.
  void append(const char* p, std::size_t n) noexcept {
    const std::size_t tail = (head_ + size_) % capacity_;
    const std::size_t first = std::min(n, capacity_ - tail);
    std::memcpy(data_.get() + tail, p, first);
    std::memcpy(data_.get(), p + first, n - first);
    size_ += n;
  }
  // The buffered bytes as at most two pieces, oldest first.
  int pieces(std::array<iovec, 2>& iov) const noexcept {
    if (size_ == 0) return 0;
    const std::size_t first = std::min(size_, capacity_ - head_);
    iov[0] = {data_.get() + head_, first};
    if (first == size_) return 1;
    iov[1] = {data_.get(), size_ - first};
    return 2;
  }
  // Drops the n oldest bytes; returns how many '\n' they contained (lines completed).
  std::size_t consume(std::size_t n) noexcept {
    std::size_t newlines = 0;
    std::size_t left = n;
    while (left > 0) {
      const std::size_t piece = std::min(left, capacity_ - head_);
      const char* p = data_.get() + head_;
      const char* end = p + piece;
      while ((p = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)))) != nullptr) {
        ++newlines;
        ++p;
      }
      head_ = (head_ + piece) % capacity_;
      left -= piece;
    }
    size_ -= n;
    if (size_ == 0) head_ = 0;
    return newlines;
  }

 private:
  std::unique_ptr<char[]> data_;
  std::size_t capacity_;
  std::size_t head_ = 0;
  std::size_t size_ = 0;
};

}  // namespace gyrod::daemon
