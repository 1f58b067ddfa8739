#include "processing/paper/mean_filter.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gyrod::processing {

namespace {

void validateParameters(const char* who, std::size_t window_length, double threshold) {
  if (window_length == 0)
    throw std::invalid_argument(std::string(who) + " needs a window length L of at least 1, got 0");
  if (!(threshold > 0.0) || !std::isfinite(threshold))
    throw std::invalid_argument(std::string(who) + " needs a threshold r that is positive and finite, got " +
                                std::to_string(threshold));
}

// Paper eq. 4 on one window given as two contiguous pieces (a ring buffer's older and
// newer parts, in time order): m = mean of the window; samples with |x − m| > r are gross
// errors; the result is the mean of the others, or m if every sample was rejected.
struct WindowEstimate {
  double value;
  std::size_t rejected;
};
WindowEstimate rejectAndAverage(std::span<const double> older, std::span<const double> newer, double r) {
  double sum = 0.0;
  for (double v : older) sum += v;
  for (double v : newer) sum += v;
  const std::size_t n = older.size() + newer.size();
  const double m = sum / static_cast<double>(n);
  double kept_sum = 0.0;
  std::size_t kept = 0;
  for (std::span<const double> part : {older, newer}) {
    for (double v : part) {
      if (std::abs(v - m) <= r) {
        kept_sum += v;
        ++kept;
      }
    }
  }
  if (kept == 0) return {m, n};
  return {kept_sum / static_cast<double>(kept), n - kept};
}

}  // namespace

GrossErrorMeanFilter::GrossErrorMeanFilter(std::size_t window_length, double threshold_dps)
    : threshold_(threshold_dps) {
  validateParameters("the mean filter", window_length, threshold_dps);
  window_.assign(window_length, 0.0);
}

double GrossErrorMeanFilter::update(double x) {
  if (!std::isfinite(x))
    throw std::invalid_argument("the mean filter cannot take a sample that is not finite, got " + std::to_string(x));
  const std::size_t len = window_.size();
  window_[next_] = x;
  next_ = next_ + 1 == len ? 0 : next_ + 1;
  if (filled_ < len) ++filled_;
  // Time order: while filling, the samples are window_[0, filled_); once full, the oldest
  // is at next_ (just past the newest) and the window wraps around the end of the buffer.
  const std::span<const double> buf(window_);
  WindowEstimate e = filled_ < len ? rejectAndAverage(buf.first(filled_), {}, threshold_)
                                   : rejectAndAverage(buf.subspan(next_), buf.first(next_), threshold_);
  last_rejected_ = e.rejected;
  return e.value;
}

void GrossErrorMeanFilter::reset() {
  next_ = 0;
  filled_ = 0;
  last_rejected_ = 0;
}

std::vector<double> blockMeanFilter(std::span<const double> x, std::size_t window_length, double threshold_dps) {
  validateParameters("the block mean filter", window_length, threshold_dps);
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i]))
      throw std::invalid_argument("the block mean filter cannot use sample " + std::to_string(i) +
                                  ": it is not finite");
  std::vector<double> out;
  out.reserve(x.size() / window_length);
  for (std::size_t start = 0; start + window_length <= x.size(); start += window_length)
    out.push_back(rejectAndAverage(x.subspan(start, window_length), {}, threshold_dps).value);
  return out;
}

}  // namespace gyrod::processing
