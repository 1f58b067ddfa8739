#pragma once
// What the sample thread hands the delivery thread (daemon/gyrod.hpp): one RATE or GAP line's
// content per slot of a lock-free ring (daemon/spsc_ring.hpp), sized here so that the memory
// budget (daemon/memory_budget.cpp) counts exactly what gyrod allocates.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "protocol/protocol.hpp"

namespace gyrod::daemon {

struct LineForClients {
  enum class Kind : std::uint8_t { Rate, Gap };
  Kind kind = Kind::Rate;
  protocol::RateSample rate;
  std::uint64_t gap_first_seq = 0;
  std::uint64_t gap_count = 0;
  std::array<char, protocol::kMaxGapReasonBytes + 1> gap_reason{};  // NUL-terminated token
};

// The ring holds this much of the stream, in real time, for the moments the delivery thread is
// not scheduled, within these bounds (at 8 kHz: 16384 lines).
inline constexpr double kClientQueueSeconds = 2.0;
inline constexpr std::size_t kMinClientQueueLines = 4096;
inline constexpr std::size_t kMaxClientQueueLines = std::size_t{1} << 16;

// Lines for `samples_per_second` (the device's rate, times the mock's speed).
inline std::size_t clientQueueLines(double samples_per_second) {
  const double lines = std::ceil(kClientQueueSeconds * samples_per_second);
  return static_cast<std::size_t>(
      std::clamp(lines, static_cast<double>(kMinClientQueueLines), static_cast<double>(kMaxClientQueueLines)));
}

}  // namespace gyrod::daemon
