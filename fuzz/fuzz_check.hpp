#pragma once
// What the fuzz targets share. A target catches the error its reader documents for bad
// input (that is the reader doing its job); anything else escapes and crashes the run, and
// a broken invariant of an accepted input is reported through fuzzCheck.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace gyrod::fuzz {

inline std::string inputText(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Aborts (a crash to libFuzzer and to the replay test) when an accepted input breaks what
// the reader promises of its result.
inline void fuzzCheck(bool holds, const char* what) {
  if (holds) return;
  std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
  std::abort();
}

}  // namespace gyrod::fuzz
