#pragma once
// Fixes the processing layer's thread count for a test's scope (shareThreadOverride), so that
// "the same bits for any number of threads" means the same on a 2-core CI machine and a
// 64-core one.
#include <cstddef>

#include "processing/base/parallel_share.hpp"

class FixedThreads {
 public:
  explicit FixedThreads(std::size_t n) { gyrod::processing::shareThreadOverride().store(n); }
  ~FixedThreads() { gyrod::processing::shareThreadOverride().store(0); }
  FixedThreads(const FixedThreads&) = delete;
  FixedThreads& operator=(const FixedThreads&) = delete;
};
