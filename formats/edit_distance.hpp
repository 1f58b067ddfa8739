#pragma once
// How far a misspelt name is from the valid ones, for "did you mean" in messages: the TOML
// reader's unknown keys and gyroctl's unknown commands.
#include <cstddef>
#include <string_view>

namespace gyrod::formats {

// Levenshtein distance: how many single-character insertions, deletions and substitutions
// turn `a` into `b`.
std::size_t editDistance(std::string_view a, std::string_view b);

}  // namespace gyrod::formats
