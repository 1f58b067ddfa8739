#include "processing/paper/statistics_tests.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "processing/base/distributions.hpp"

namespace gyrod::processing {

namespace {

// Two-sided 5 % critical value of the standard normal, as the paper uses it.
constexpr double kNormalCritical5Percent = 1.96;

void requireFinite(std::span<const double> x, const char* who) {
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]))
      throw std::invalid_argument(std::string(who) + " cannot use sample " + std::to_string(i) + ": it is not finite");
  }
}

double meanOf(std::span<const double> x) {
  double s = 0.0;
  for (double v : x) s += v;
  return s / static_cast<double>(x.size());
}

// The class of a value among sorted edges, as std::upper_bound counts it (the number of
// edges ≤ v), through a table of equal cells over [first edge, last edge]: each cell
// remembers the class of its lower end, and a few comparisons with the edges finish the
// count. The same answer as the binary search, without its unpredictable branches.
class EqualCellIndex {
 public:
  explicit EqualCellIndex(const std::vector<double>& edges) : edges_(edges) {
    if (edges_.size() < 2 || !(edges_.back() > edges_.front())) return;
    lo_ = edges_.front();
    scale_ = static_cast<double>(kCells) / (edges_.back() - lo_);
    cell_class_.resize(kCells + 1);
    std::size_t cls = 0;
    for (std::size_t c = 0; c <= kCells; ++c) {
      const double start = lo_ + static_cast<double>(c) / scale_;
      while (cls < edges_.size() && edges_[cls] <= start) ++cls;
      cell_class_[c] = cls;
    }
  }
  std::size_t classOf(double v) const {
    if (cell_class_.empty() || !(v >= lo_))
      return static_cast<std::size_t>(std::upper_bound(edges_.begin(), edges_.end(), v) - edges_.begin());
    const double cell = (v - lo_) * scale_;
    std::size_t cls = cell_class_[cell >= static_cast<double>(kCells) ? kCells : static_cast<std::size_t>(cell)];
    // The table's class is a lower bound up to rounding of the cell's start; settle it both ways.
    while (cls > 0 && edges_[cls - 1] > v) --cls;
    while (cls < edges_.size() && edges_[cls] <= v) ++cls;
    return cls;
  }

 private:
  static constexpr std::size_t kCells = 4096;
  const std::vector<double>& edges_;
  double lo_ = 0.0, scale_ = 0.0;
  std::vector<std::size_t> cell_class_;
};

}  // namespace

ZeroMeanTest zeroMeanTest(std::span<const double> x) {
  if (x.size() < 2)
    throw std::invalid_argument("the zero-mean test needs at least 2 samples, got " + std::to_string(x.size()));
  requireFinite(x, "the zero-mean test");
  const double n = static_cast<double>(x.size());
  ZeroMeanTest t;
  t.mean = meanOf(x);
  double ss = 0.0;
  for (double v : x) ss += (v - t.mean) * (v - t.mean);
  t.standard_deviation = std::sqrt(ss / (n - 1.0));
  if (t.standard_deviation == 0.0) {
    // A constant series: its mean is exactly known; it is zero or it is not.
    t.z = t.mean == 0.0 ? 0.0 : std::copysign(INFINITY, t.mean);
  } else {
    t.z = t.mean / (t.standard_deviation / std::sqrt(n));
  }
  t.zero_mean = std::abs(t.z) < kNormalCritical5Percent;
  return t;
}

std::size_t countReverseArrangements(std::span<const double> v) {
  // N is the number of segments (~100): the direct O(N²) count is the definition itself.
  std::size_t a = 0;
  for (std::size_t i = 0; i < v.size(); ++i)
    for (std::size_t j = i + 1; j < v.size(); ++j)
      if (v[i] > v[j]) ++a;
  return a;
}

ReverseArrangementsTest reverseArrangementsTestOfSequence(std::span<const double> v) {
  if (v.size() < kMinReverseArrangementsSegments)
    throw std::invalid_argument("the reverse arrangements test needs at least " +
                                std::to_string(kMinReverseArrangementsSegments) + " values, got " +
                                std::to_string(v.size()));
  requireFinite(v, "the reverse arrangements test");
  const double n = static_cast<double>(v.size());
  ReverseArrangementsTest t;
  t.segments = v.size();
  t.arrangements = static_cast<double>(countReverseArrangements(v));
  // Moments of A for N independent observations (Bendat & Piersol §4.5.2).
  t.mean_arrangements = n * (n - 1.0) / 4.0;
  t.sd_arrangements = std::sqrt(n * (2.0 * n + 5.0) * (n - 1.0) / 72.0);
  t.u = (t.arrangements - t.mean_arrangements) / t.sd_arrangements;
  t.stationary = std::abs(t.u) < kNormalCritical5Percent;
  return t;
}

ReverseArrangementsTest reverseArrangementsTest(std::span<const double> x, std::size_t segments,
                                                SegmentStatistic statistic) {
  if (segments < kMinReverseArrangementsSegments)
    throw std::invalid_argument("the reverse arrangements test needs at least " +
                                std::to_string(kMinReverseArrangementsSegments) + " segments, got " +
                                std::to_string(segments));
  if (x.size() < segments)
    throw std::invalid_argument("the reverse arrangements test cannot fill " + std::to_string(segments) +
                                " segments with " + std::to_string(x.size()) + " samples");
  requireFinite(x, "the reverse arrangements test");
  // Bendat & Piersol apply the test to the mean-square values of equal-length segments of a
  // record they take as zero-mean. The paper ran it on raw data whose mean (1.367) dwarfs the
  // fluctuations, where a plain mean square would be almost entirely the constant mean². The
  // default therefore uses each segment's mean square about the mean of the whole series: it
  // equals segment variance + (segment mean − overall mean)², so it does not depend on the
  // constant offset and reacts to a change of the variance (and of the mean, see the header
  // for the one shape it misses) along the record.
  const std::size_t len = x.size() / segments;
  const std::size_t used = len * segments;  // trailing remainder (< segments samples) unused
  const double overall_mean = meanOf(x.first(used));
  std::vector<double> v(segments);
  for (std::size_t s = 0; s < segments; ++s) {
    const std::span<const double> seg = x.subspan(s * len, len);
    if (statistic == SegmentStatistic::Mean) {
      v[s] = meanOf(seg);
    } else {
      double ss = 0.0;
      for (double xi : seg) ss += (xi - overall_mean) * (xi - overall_mean);
      v[s] = ss / static_cast<double>(len);
    }
  }
  return reverseArrangementsTestOfSequence(v);
}

ChiSquareNormalityTest chiSquareNormalityTest(std::span<const double> x, std::size_t bins) {
  constexpr std::size_t kMinExpectedPerBin = 5;
  constexpr std::size_t kMinBins = 4;  // dof = bins − 3 ≥ 1
  const std::size_t n = x.size();
  if (n < 5 * kMinExpectedPerBin)
    throw std::invalid_argument("the chi-square normality test needs at least 25 samples, got " + std::to_string(n));
  requireFinite(x, "the chi-square normality test");
  const std::size_t max_bins = n / kMinExpectedPerBin;
  if (bins == 0) {
    // Moore (1986): about 2·n^(2/5) equiprobable classes; bounded so that the test keeps
    // some resolution for small n and does not spread a long record over thousands of bins.
    const auto moore = static_cast<std::size_t>(std::lround(2.0 * std::pow(static_cast<double>(n), 0.4)));
    bins = std::clamp<std::size_t>(moore, 5, 100);
    bins = std::min(bins, max_bins);
  } else if (bins < kMinBins || bins > max_bins) {
    throw std::invalid_argument("the chi-square normality test needs a number of bins in [" + std::to_string(kMinBins) +
                                ", n/5 = " + std::to_string(max_bins) + "], got " + std::to_string(bins));
  }

  // Maximum-likelihood estimates (divisor n), the usual choice for the χ² test with
  // estimated parameters; dof = bins − 1 − 2 estimated parameters.
  const double mean = meanOf(x);
  double ss = 0.0;
  for (double v : x) ss += (v - mean) * (v - mean);
  const double sd = std::sqrt(ss / static_cast<double>(n));
  if (!(sd > 0.0))
    throw std::invalid_argument(
        "the chi-square normality test needs samples that vary; these are constant (every value " +
        std::to_string(mean) + ")");

  // Inner class boundaries mean + sd·Φ⁻¹(k/bins), k = 1..bins−1; each class has probability 1/bins.
  std::vector<double> edges(bins - 1);
  for (std::size_t k = 1; k < bins; ++k)
    edges[k - 1] = mean + sd * normalQuantile(static_cast<double>(k) / static_cast<double>(bins));
  std::vector<std::size_t> observed(bins, 0);
  const EqualCellIndex index(edges);
  for (double v : x) ++observed[index.classOf(v)];
  const double expected = static_cast<double>(n) / static_cast<double>(bins);
  ChiSquareNormalityTest t;
  t.bins = bins;
  for (std::size_t c : observed) {
    const double d = static_cast<double>(c) - expected;
    t.chi2 += d * d / expected;
  }
  t.dof = bins - 3;
  t.critical = chiSquareQuantile(0.95, static_cast<double>(t.dof));
  t.p_value = 1.0 - chiSquareCdf(t.chi2, static_cast<double>(t.dof));
  t.normal = t.chi2 < t.critical;
  return t;
}

}  // namespace gyrod::processing
