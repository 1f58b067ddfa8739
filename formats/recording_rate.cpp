// sampleRateFromTimes (recording_csv.hpp): the median step of t without a copy of every step.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <sstream>
#include <vector>

#include "formats/recording_csv.hpp"
#include "processing/parallel_share.hpp"

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

// The k-th smallest step (0-based) of t, every step checked > 0 in order: the value
// std::nth_element would put at k in a copy of the steps. One pass counts the steps below a
// bracket guessed from a sample, and those equal to the sampled median (the common step of a
// regular clock), and keeps only the others inside the bracket, on both cores (each half of
// the steps apart, the first half's non-increasing step named first); the full copy is made
// only when the k-th step falls outside the bracket.
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
  std::vector<double> dt(steps);
  for (std::size_t i = 1; i < t.size(); ++i) dt[i - 1] = t[i] - t[i - 1];
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(k), dt.end());
  return dt[k];
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
