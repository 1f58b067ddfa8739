#pragma once
// The recording reader's source of lines (recording_csv.cpp): a std::FILE read in large
// chunks, with the line length limit of recording_format.hpp.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string_view>
#include <vector>

namespace gyrod::recording {

// Lines of at most `max_bytes` bytes (the '\n' not counted) from a std::FILE, read in large
// chunks: one copy of the text, no allocation per line, the same results as
// BoundedLineReader (a line past the limit stops the reading).
class ChunkedLineReader {
 public:
  enum class Result { Line, End, TooLong };
  static constexpr std::size_t kChunkBytes = std::size_t{1} << 20;

  ChunkedLineReader(std::FILE* file, std::size_t max_bytes)
      : file_(file), max_bytes_(max_bytes), buffer_(kChunkBytes + max_bytes + 2) {}

  Result next() {
    while (true) {
      const char* begin = buffer_.data() + pos_;
      const std::size_t available = end_ - pos_;
      if (const void* nl = std::memchr(begin, '\n', available)) {
        const auto length = static_cast<std::size_t>(static_cast<const char*>(nl) - begin);
        line_ = {begin, length};
        pos_ += length + 1;
        consumed_ += length + 1;
        return length > max_bytes_ ? Result::TooLong : Result::Line;
      }
      if (const auto result = withoutNewline(begin, available)) return *result;
    }
  }
  // Every complete line now in the buffer, with their '\n' (refilling first when there is
  // none), or the last line of the file without one. Lines longer than the limit are left
  // to the caller to find; TooLong when no line ends within the limit.
  Result nextLines() {
    while (true) {
      const char* begin = buffer_.data() + pos_;
      const std::size_t available = end_ - pos_;
      if (const void* nl = available > 0 ? ::memrchr(begin, '\n', available) : nullptr) {
        const auto length = static_cast<std::size_t>(static_cast<const char*>(nl) - begin) + 1;
        line_ = {begin, length};
        pos_ += length;
        consumed_ += length;
        return Result::Line;
      }
      if (const auto result = withoutNewline(begin, available)) return *result;
    }
  }
  // Reads on now, when nextLines() has taken every complete line: the partial line left moves
  // to the front of the buffer (over the text nextLines() returned) and the rest is filled,
  // as the next call of nextLines() would have done first.
  void prefetch() {
    const std::size_t available = end_ - pos_;
    if (!eof_ && available <= max_bytes_) refill(buffer_.data() + pos_, available);
  }
  std::string_view line() const { return line_; }
  std::size_t maxBytes() const { return max_bytes_; }
  std::uint64_t bytesConsumed() const { return consumed_; }

 private:
  // No '\n' in the `available` bytes at `begin`: TooLong past the limit; at the end of the
  // file the last line (End when nothing is left); else nothing, after a refill.
  std::optional<Result> withoutNewline(const char* begin, std::size_t available) {
    if (available > max_bytes_) return Result::TooLong;
    if (eof_) {
      if (available == 0) return Result::End;
      line_ = {begin, available};
      pos_ = end_;
      consumed_ += available;
      return Result::Line;
    }
    refill(begin, available);
    return std::nullopt;
  }

  // Keeps the partial line (at most max_bytes_) and fills the rest of the buffer.
  void refill(const char* begin, std::size_t available) {
    std::memmove(buffer_.data(), begin, available);
    pos_ = 0;
    end_ = available;
    const std::size_t got = std::fread(buffer_.data() + end_, 1, buffer_.size() - end_, file_);
    end_ += got;
    if (got == 0) eof_ = true;
  }

  std::FILE* file_;
  std::size_t max_bytes_;
  std::vector<char> buffer_;
  std::size_t pos_ = 0, end_ = 0;
  std::uint64_t consumed_ = 0;
  bool eof_ = false;
  std::string_view line_;
};

}  // namespace gyrod::recording
