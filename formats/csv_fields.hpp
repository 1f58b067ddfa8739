#pragma once
// The field conventions every CSV file of the project follows (recordings, motion tables):
// fields separated by ',', blanks and '\r' around a field ignored, numbers in the C locale
// with an optional leading '+'. Shared so that every reader accepts the same text.
#include <optional>
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

}  // namespace gyrod::recording
