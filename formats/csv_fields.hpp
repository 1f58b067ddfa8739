#pragma once
// The field conventions every CSV file of the project follows (recordings, motion tables):
// fields separated by ',', blanks and '\r' around a field ignored, numbers in the C locale
// with an optional leading '+'. Shared so that every reader accepts the same text.
#include <cstddef>
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gyrod::recording {

// `s` without the blanks, tabs and '\r' at either end.
std::string_view trimField(std::string_view s);
// The fields of one line, each trimmed; one field for a line without commas.
std::vector<std::string_view> splitFields(std::string_view line);
// A whole field as a double; nullopt when it is not a number at all, HUGE_VAL when it is out
// of range (so that the caller reports it as non-finite).
std::optional<double> parseNumber(std::string_view field);

// The longest line an input file may have (README, "Errors"). Checked while reading, so
// that a file without newlines costs this much memory, not its size, before it is refused.
inline constexpr std::size_t kMaxLineBytes = 64 * 1024;

// Reads lines of at most `max_bytes` bytes (the '\n' not counted) into one buffer.
class BoundedLineReader {
 public:
  enum class Result { Line, End, TooLong };
  explicit BoundedLineReader(std::istream& in, std::size_t max_bytes = kMaxLineBytes);
  // Line: line() holds it, without its '\n'. TooLong: the line has more than max_bytes bytes
  // and reading must stop there. End: no more lines, or a read error (in.bad()).
  Result next();
  std::string_view line() const { return {buffer_.data(), length_}; }
  std::size_t maxBytes() const { return max_bytes_; }

 private:
  std::istream& in_;
  std::size_t max_bytes_;
  std::string buffer_;
  std::size_t length_ = 0;
};

// The cause for a TooLong line: "line longer than 65536 bytes (the limit)".
std::string lineTooLongCause(std::size_t max_bytes = kMaxLineBytes);

}  // namespace gyrod::recording
