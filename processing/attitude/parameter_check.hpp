#pragma once
// The attitude estimators' parameter checks: a value out of range is a std::invalid_argument
// naming the parameter and its value ("attitude: NAME must be ..., not VALUE").
#include <cmath>
#include <stdexcept>
#include <string>

namespace gyrod::processing::attitude {

inline void requirePositiveParameter(double value, const std::string& name) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw std::invalid_argument("attitude: " + name + " must be a positive number, not " + std::to_string(value));
}

inline void requireNonNegativeParameter(double value, const std::string& name) {
  if (!(value >= 0.0) || !std::isfinite(value))
    throw std::invalid_argument("attitude: " + name + " must be finite and >= 0, not " + std::to_string(value));
}

}  // namespace gyrod::processing::attitude
