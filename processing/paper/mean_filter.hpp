#pragma once
// Mean filter with gross-error rejection (paper eq. 4), exactly as specified:
// the window is the last L samples, current included (while fewer than L have arrived,
// the window is what has arrived); m = window mean; samples with |x − m| > r are
// dropped; the output is the mean of the kept samples, or m when none is kept.
#include <cstddef>
#include <span>
#include <vector>

namespace gyrod::processing {

class GrossErrorMeanFilter {
 public:
  // Throws std::invalid_argument for L = 0 or r ≤ 0 / non-finite.
  GrossErrorMeanFilter(std::size_t window_length, double threshold_dps);
  // One sample in, one out. Allocates nothing; O(L). Throws std::invalid_argument for a
  // non-finite sample (the filter's state is then unchanged), since one NaN would
  // otherwise poison the next L outputs.
  double update(double x);
  // Forget all samples (the window is empty again, as after construction).
  void reset();
  std::size_t windowLength() const { return window_.size(); }
  double threshold() const { return threshold_; }
  // Samples rejected as gross errors in the most recent update.
  std::size_t lastRejected() const { return last_rejected_; }

 private:
  std::vector<double> window_;  // ring buffer, sized once
  std::size_t next_ = 0;
  std::size_t filled_ = 0;
  double threshold_;
  std::size_t last_rejected_ = 0;
};

// Decimating (block) mode: consecutive non-overlapping blocks of L samples, one output
// per complete block, same rejection rule. A trailing partial block is dropped.
// Throws as the constructor above, and for non-finite samples.
std::vector<double> blockMeanFilter(std::span<const double> x, std::size_t window_length, double threshold_dps);

}  // namespace gyrod::processing
