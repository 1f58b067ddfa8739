// sampleRateFromTimes (recording_csv.hpp): the median step of t without a copy of every step.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <vector>

#include "formats/recording_csv.hpp"
#include "processing/base/parallel_share.hpp"

namespace gyrod::recording {
namespace {

// Steps drawn evenly from the column to guess where the median lies.
constexpr std::size_t kSampledSteps = 1024;
// The guessed bracket: this many sampled steps either side of the sampled median.
constexpr std::size_t kBracketHalfWidth = 32;

// Below this many steps the counting pass stays on one core.
constexpr std::size_t kParallelSteps = std::size_t{1} << 16;

// The steps of t[first - 1 .. end) against the bracket [low, high] around `guess`.
struct StepCount {
  std::size_t below = 0, equal = 0, above = 0;
  std::vector<double> lower, upper;  // inside the bracket, below and above the guess
  std::size_t not_increasing = 0;    // the first i with t[i] <= t[i - 1], 0 when none

  void count(const std::vector<double>& t, std::size_t first, std::size_t end, double low, double guess, double high) {
    for (std::size_t i = first; i < end; ++i) {
      const double dt = t[i] - t[i - 1];
      if (!(dt > 0.0)) {
        not_increasing = i;
        return;
      }
      if (dt < low)
        ++below;
      else if (dt > high)
        ++above;
      else if (dt == guess)
        ++equal;
      else if (dt < guess)
        lower.push_back(dt);
      else
        upper.push_back(dt);
    }
  }
};

[[noreturn]] void notIncreasing(const Recording& r, std::size_t i) {
  std::ostringstream s;
  s.precision(17);
  s << r.path << ':' << r.lineOfSample(i) << ": column 't' is not strictly increasing (t = " << r.t[i] << " after "
    << r.t[i - 1] << ")";
  throw RecordingError(s.str());
}

// The k-th smallest of the steps of t (every one > 0) by their bits, with no copy of them:
// positive doubles order as their IEEE 754 bit patterns read as integers, so the k-th step is
// found 16 bits at a time from the top, each pass counting the steps that share the bits
// found so far by their next 16 (a histogram per half of the steps, the halves on both cores
// beyond `split`). Four passes over t at most, each as cheap as the bracket's.
double kthStepByBits(const std::vector<double>& t, std::size_t k, std::size_t split) {
  constexpr int kDigitBits = 16;
  constexpr std::size_t kDigits = std::size_t{1} << kDigitBits;
  std::uint64_t prefix = 0;  // the bits found so far, in place
  std::vector<std::size_t> front(kDigits), back(kDigits);
  for (int shift = 64 - kDigitBits; shift >= 0; shift -= kDigitBits) {
    const std::uint64_t known = shift + kDigitBits >= 64 ? 0 : ~std::uint64_t{0} << (shift + kDigitBits);
    const auto histogram = [&](std::vector<std::size_t>& counts, std::size_t first, std::size_t end) {
      std::fill(counts.begin(), counts.end(), 0);
      for (std::size_t i = first; i < end; ++i) {
        const auto bits = std::bit_cast<std::uint64_t>(t[i] - t[i - 1]);
        if ((bits & known) == prefix) ++counts[(bits >> shift) & (kDigits - 1)];
      }
    };
    if (split == t.size()) {
      histogram(front, 1, t.size());
      std::fill(back.begin(), back.end(), 0);
    } else {
      processing::runBoth([&] { histogram(front, 1, split); }, [&] { histogram(back, split, t.size()); });
    }
    std::uint64_t digit = 0;
    for (; digit + 1 < kDigits && front[digit] + back[digit] <= k; ++digit) k -= front[digit] + back[digit];
    prefix |= digit << shift;
  }
  return std::bit_cast<double>(prefix);
}

// The k-th smallest step (0-based) of t, every step checked > 0 in order: the value
// std::nth_element would put at k in a copy of the steps. One pass counts the steps below a
// bracket guessed from a sample, and those equal to the sampled median (the common step of a
// regular clock), and keeps only the others inside the bracket, on both cores (each half of
// the steps apart, the first half's non-increasing step named first); the steps are searched
// by their bits (kthStepByBits) only when the k-th step falls outside the bracket: a regular
// clock printed in decimal has a few distinct steps in a pattern the even sample can alias.
double kthStep(const Recording& r, std::size_t k) {
  const std::vector<double>& t = r.t;
  const std::size_t steps = t.size() - 1;
  std::vector<double> sample;
  const std::size_t drawn = std::min(steps, kSampledSteps);
  sample.reserve(drawn);
  for (std::size_t j = 0; j < drawn; ++j) {
    const std::size_t i = j * steps / drawn + 1;
    sample.push_back(t[i] - t[i - 1]);
  }
  std::sort(sample.begin(), sample.end());
  const std::size_t mid = drawn / 2;
  const double guess = sample[mid];
  const double low = sample[mid >= kBracketHalfWidth ? mid - kBracketHalfWidth : 0];
  const double high = sample[std::min(drawn - 1, mid + kBracketHalfWidth)];

  StepCount front, back;
  const std::size_t split = steps < kParallelSteps ? t.size() : t.size() / 2;
  if (split == t.size())
    front.count(t, 1, t.size(), low, guess, high);
  else
    processing::runBoth([&] { front.count(t, 1, split, low, guess, high); },
                        [&] { back.count(t, split, t.size(), low, guess, high); });
  if (front.not_increasing != 0) notIncreasing(r, front.not_increasing);
  if (back.not_increasing != 0) notIncreasing(r, back.not_increasing);
  const std::size_t below = front.below + back.below, equal = front.equal + back.equal,
                    above = front.above + back.above;
  std::vector<double>& lower = front.lower;
  std::vector<double>& upper = front.upper;
  lower.insert(lower.end(), back.lower.begin(), back.lower.end());
  upper.insert(upper.end(), back.upper.begin(), back.upper.end());
  if (k >= below && k < steps - above) {
    std::size_t rank = k - below;
    if (rank < lower.size()) {
      std::nth_element(lower.begin(), lower.begin() + static_cast<std::ptrdiff_t>(rank), lower.end());
      return lower[rank];
    }
    rank -= lower.size();
    if (rank < equal) return guess;
    rank -= equal;
    std::nth_element(upper.begin(), upper.begin() + static_cast<std::ptrdiff_t>(rank), upper.end());
    return upper[rank];
  }
  return kthStepByBits(t, k, split);
}

}  // namespace

double sampleRateFromTimes(const Recording& r) {
  if (r.t.size() < 2) throw RecordingError(r.path + ": need at least two samples in column 't' to infer the rate");
  const double median = kthStep(r, (r.t.size() - 1) / 2);
  if (!std::isfinite(1.0 / median)) {  // steps of 1e-320 s are positive, but no rate
    std::ostringstream s;
    s.precision(17);
    s << r.path << ": column 't' steps by " << median << " s, too small for a sample rate";
    throw RecordingError(s.str());
  }
  return 1.0 / median;
}

}  // namespace gyrod::recording
