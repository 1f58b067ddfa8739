#pragma once
#include <cstdint>
#include <limits>

namespace gyrod::driver::mock {

// "Not scheduled": later than any clock time.
inline constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();

}  // namespace gyrod::driver::mock
