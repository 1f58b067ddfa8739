#include "formats/csv_fields.hpp"

#include <charconv>
#include <cmath>
#include <system_error>

#include "formats/decimal_number.hpp"

namespace gyrod::recording {

std::string_view trimField(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

std::vector<std::string_view> splitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    fields.push_back(
        trimField(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

std::optional<double> parseNumber(std::string_view field) {
  if (field.empty()) return std::nullopt;
  if (field.front() == '+') field.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = decimalFromChars(field.data(), field.data() + field.size(), value);
  if (ec == std::errc::result_out_of_range) return HUGE_VAL;  // reported as non-finite
  if (ec != std::errc() || end != field.data() + field.size()) return std::nullopt;
  return value;
}

BoundedLineReader::BoundedLineReader(std::istream& in, std::size_t max_bytes)
    : in_(in), max_bytes_(max_bytes), buffer_(max_bytes + 2, '\0') {}

BoundedLineReader::Result BoundedLineReader::next() {
  length_ = 0;
  if (!in_.good()) return Result::End;
  // Room for one byte past the limit: filling it (failbit without eofbit) means too long.
  in_.getline(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  const auto extracted = static_cast<std::size_t>(in_.gcount());
  if (in_.bad()) return Result::End;
  if (in_.fail() && !in_.eof()) return Result::TooLong;
  if (extracted == 0 && in_.eof()) return Result::End;
  length_ = in_.eof() ? extracted : extracted - 1;  // the '\n' is extracted, not stored
  return length_ > max_bytes_ ? Result::TooLong : Result::Line;
}

std::string lineTooLongCause(std::size_t max_bytes) {
  return "line longer than " + std::to_string(max_bytes) + " bytes (the limit for one line)";
}

}  // namespace gyrod::recording
