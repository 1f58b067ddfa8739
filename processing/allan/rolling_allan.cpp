#include "processing/allan/rolling_allan.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace gyrod::processing {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string formatNumber(double v) {
  std::ostringstream os;
  os << std::setprecision(17) << v;
  return os.str();
}

// Unevaluated double-double sum hi + lo with |lo| ≤ ulp(hi)/2.
struct DoubleDouble {
  double hi = 0.0;
  double lo = 0.0;
};

// Knuth's TwoSum: s + e == a + b exactly.
DoubleDouble twoSum(double a, double b) {
  const double s = a + b;
  const double bv = s - a;
  const double e = (a - (s - bv)) + (b - bv);
  return {s, e};
}

// FastTwoSum renormalisation, valid when |a| ≥ |b| or a = 0.
DoubleDouble fastTwoSum(double a, double b) {
  const double s = a + b;
  return {s, b - (s - a)};
}

// a − b in double-double (hi parts differenced exactly, lo parts added once): absolute
// error ~2⁻¹⁰⁴·max(|a|, |b|), so nothing is lost to cancellation between nearby phases.
DoubleDouble difference(double a_hi, double a_lo, double b_hi, double b_lo) {
  const DoubleDouble s = twoSum(a_hi, -b_hi);
  return fastTwoSum(s.hi, s.lo + (a_lo - b_lo));
}

}  // namespace

// ---- ExactNonNegativeSum ---------------------------------------------------------------

ExactNonNegativeSum::Digits ExactNonNegativeSum::digitsOf(double v) {
  constexpr std::uint64_t kLow32 = 0xffffffffULL;
  // v = mantissa · 2^(position − 1074) with a 53-bit integer mantissa (IEEE 754 binary64;
  // v = 0 gives mantissa 0, all digits 0).
  const auto bits = std::bit_cast<std::uint64_t>(v);
  const auto biased_exponent = static_cast<unsigned>((bits >> 52) & 0x7ffU);
  std::uint64_t mantissa = bits & ((std::uint64_t{1} << 52) - 1);
  if (biased_exponent != 0) mantissa |= std::uint64_t{1} << 52;  // normal: implicit 1
  const unsigned position = biased_exponent == 0 ? 0U : biased_exponent - 1U;
  const unsigned offset = position % 32;
  // The mantissa shifted by `offset` spans three 32-bit digits.
  const std::uint64_t low = (mantissa & kLow32) << offset;  // < 2⁶⁴
  const std::uint64_t high = (mantissa >> 32) << offset;    // < 2⁵³
  Digits d;
  d.limb = position / 32;
  d.digit[0] = static_cast<std::int64_t>(low & kLow32);
  d.digit[1] = static_cast<std::int64_t>((low >> 32) + (high & kLow32));
  d.digit[2] = static_cast<std::int64_t>(high >> 32);
  return d;
}

void ExactNonNegativeSum::propagateCarries() {
  // Floor division by 2³² moves each digit's excess (or deficit) up; the total is ≥ 0
  // (only values added before are subtracted), so the top digit ends ≥ 0.
  for (std::size_t k = 0; k + 1 < kLimbs; ++k) {
    const std::int64_t carry = limbs_[k] >> 32;  // arithmetic shift: floor(limb / 2³²)
    limbs_[k] &= static_cast<std::int64_t>(0xffffffffLL);
    limbs_[k + 1] += carry;
  }
  pending_ = 0;
}

double ExactNonNegativeSum::value() const {
  ExactNonNegativeSum normal = *this;
  normal.propagateCarries();
  const auto& limbs = normal.limbs_;
  std::size_t top = kLimbs;
  while (top > 0 && limbs[top - 1] == 0) --top;
  if (top == 0) return 0.0;
  // The three highest digits from the top non-zero one carry ≥ 65 significant bits, more
  // than a double holds; the rest changes the result by < 2⁻⁶⁴ relative.
  const std::size_t base = top >= 3 ? top - 3 : 0;
  double r = 0.0;
  for (std::size_t k = top; k-- > base;) r = r * 4294967296.0 + static_cast<double>(limbs[k]);
  return std::ldexp(r, static_cast<int>(32 * base) - 1074);
}

// ---- RollingOverlappingAllan -----------------------------------------------------------

static_assert(sizeof(DoubleDouble) == RollingOverlappingAllan::kBytesPerWindowSample);

namespace {

std::vector<std::size_t> octaveFactorsForWindow(std::size_t window_samples) {
  if (window_samples < 2) {
    throw std::invalid_argument("the live Allan window needs at least 2 samples (got " +
                                std::to_string(window_samples) + "): m = 1 needs 2 samples");
  }
  std::vector<std::size_t> ms;
  for (std::size_t m = 1; m <= window_samples / 2; m *= 2) ms.push_back(m);
  return ms;
}

}  // namespace

RollingOverlappingAllan::RollingOverlappingAllan(std::size_t window_samples)
    : RollingOverlappingAllan(window_samples, octaveFactorsForWindow(window_samples)) {}

RollingOverlappingAllan::RollingOverlappingAllan(std::size_t window_samples, std::span<const std::size_t> cluster_sizes)
    : window_capacity_(window_samples), cluster_sizes_(cluster_sizes.begin(), cluster_sizes.end()) {
  if (window_samples < 2) {
    throw std::invalid_argument("the live Allan window needs at least 2 samples (got " +
                                std::to_string(window_samples) + "): m = 1 needs 2 samples");
  }
  if (cluster_sizes_.empty()) {
    throw std::invalid_argument("the live Allan variance needs at least one averaging factor m; none given");
  }
  for (std::size_t i = 0; i < cluster_sizes_.size(); ++i) {
    const std::size_t m = cluster_sizes_[i];
    if (m == 0) {
      throw std::invalid_argument("the live Allan variance needs averaging factors m >= 1; number " +
                                  std::to_string(i + 1) + " is 0");
    }
    if (m > window_samples / 2) {
      throw std::invalid_argument("the live Allan variance's averaging factor m = " + std::to_string(m) + " (number " +
                                  std::to_string(i + 1) + ") is too long for a window of " +
                                  std::to_string(window_samples) + " samples (need 2*m <= window)");
    }
    if (i > 0 && m <= cluster_sizes_[i - 1]) {
      throw std::invalid_argument(
          "the live Allan variance needs strictly increasing averaging factors (m = " + std::to_string(m) +
          " at index " + std::to_string(i) + " follows " + std::to_string(cluster_sizes_[i - 1]) + ")");
    }
  }
  window_sums_.resize(cluster_sizes_.size());
  since_start_sums_.resize(cluster_sizes_.size());
  ring_.resize(window_samples + 1);
}

void RollingOverlappingAllan::reset() {
  for (auto& s : window_sums_) s.clear();
  for (auto& s : since_start_sums_) s.clear();
  for (auto& x : ring_) x = {};
  head_ = 0;
  total_count_ = 0;
  reference_ = 0.0;
  ++resets_;
}

void RollingOverlappingAllan::beginCopyFrom(const RollingOverlappingAllan& source) {
  if (source.window_capacity_ != window_capacity_ || source.cluster_sizes_ != cluster_sizes_)
    throw std::invalid_argument("a rolling Allan window can be copied in steps only from one of the same window (" +
                                std::to_string(window_capacity_) + " samples) and cluster sizes; the source has " +
                                std::to_string(source.window_capacity_) + " samples");
  window_sums_ = source.window_sums_;  // same sizes: no allocation
  since_start_sums_ = source.since_start_sums_;
  head_ = source.head_;
  total_count_ = source.total_count_;
  reference_ = source.reference_;
  copy_source_resets_ = source.resets_;
  copy_next_ = 0;
}

RollingOverlappingAllan::CopyStep RollingOverlappingAllan::continueCopyFrom(const RollingOverlappingAllan& source,
                                                                            std::size_t points) {
  if (!copy_source_resets_ || source.window_capacity_ != window_capacity_)
    throw std::logic_error("continueCopyFrom without a beginCopyFrom from the same window");
  if (source.resets_ != *copy_source_resets_ || source.total_count_ < total_count_) return CopyStep::Overrun;
  // Push k after the beginning overwrote the point k − 1 places after the oldest one.
  if (source.total_count_ - total_count_ > copy_next_) return CopyStep::Overrun;
  const std::size_t size = ring_.size();
  const std::size_t end = std::min(size, copy_next_ + points);
  for (std::size_t offset = copy_next_; offset < end;) {  // at most two contiguous runs
    const std::size_t slot = (head_ + 1 + offset) % size;
    const std::size_t run = std::min(end - offset, size - slot);
    const auto from = source.ring_.begin() + static_cast<std::ptrdiff_t>(slot);
    std::copy(from, from + static_cast<std::ptrdiff_t>(run), ring_.begin() + static_cast<std::ptrdiff_t>(slot));
    offset += run;
  }
  copy_next_ = end;
  if (copy_next_ < size) return CopyStep::Copying;
  copy_source_resets_.reset();
  return CopyStep::Done;
}

std::size_t RollingOverlappingAllan::windowCount() const {
  return total_count_ < window_capacity_ ? static_cast<std::size_t>(total_count_) : window_capacity_;
}

double RollingOverlappingAllan::secondDifference(std::size_t back, std::size_t m) const {
  const PhasePoint& x2 = ring_[slotBack(back)];          // x_{j+2m}
  const PhasePoint& x1 = ring_[slotBack(back + m)];      // x_{j+m}
  const PhasePoint& x0 = ring_[slotBack(back + 2 * m)];  // x_j
  // The hi parts are differenced exactly (TwoSum); what is left is d = A + c with
  // A = later.hi − earlier.hi, rounded once (error ≤ 2⁻⁵³·|A|, and A ≈ d, or A is exact by
  // Sterbenz when the window sums nearly cancel), and c of order 2⁻⁵³·|x_{j+2m} − x_{j+m}|
  // from the low parts. So d carries ~2 roundings of its own size plus ~2⁻¹⁰⁴·|x|, however
  // large the phase or the window sums are.
  const DoubleDouble later = twoSum(x2.hi, -x1.hi);
  const DoubleDouble earlier = twoSum(x1.hi, -x0.hi);
  const double low_parts = (later.lo - earlier.lo) + ((x2.lo - x1.lo) - (x1.lo - x0.lo));
  return (later.hi - earlier.hi) + low_parts;
}

void RollingOverlappingAllan::push(double rate) {
  if (!std::isfinite(rate) || std::abs(rate) > kMaxAbsRate) {
    throw std::invalid_argument("the live Allan variance cannot take rate " + formatNumber(rate) +
                                " is not a finite number of magnitude <= 1e100 (sample " +
                                std::to_string(total_count_) + ")");
  }
  const std::size_t count = cluster_sizes_.size();
  // The oldest term of a full window leaves: j = total − W, whose x_{j+2m} lies W − 2m
  // before the newest point. It is recomputed from the same stored points before x_j's
  // slot is overwritten, so it is bit for bit the value that was added.
  if (total_count_ >= window_capacity_) {
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t m = cluster_sizes_[i];
      const double d = secondDifference(window_capacity_ - 2 * m, m);
      window_sums_[i].subtract(ExactNonNegativeSum::digitsOf(d * d));
    }
  }
  if (total_count_ == 0) reference_ = rate;
  const double v = rate - reference_;

  // x_{n+1} = x_n + v, double-double running sum (TwoSum, then renormalise).
  const PhasePoint& x = ring_[head_];
  const DoubleDouble s = twoSum(x.hi, v);
  const DoubleDouble next = fastTwoSum(s.hi, x.lo + s.lo);
  head_ = head_ + 1 == ring_.size() ? 0 : head_ + 1;
  ring_[head_] = {next.hi, next.lo};
  ++total_count_;

  // The newest term of each m: j = total − 2m, once 2m samples have arrived.
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t m = cluster_sizes_[i];
    if (2 * static_cast<std::uint64_t>(m) > total_count_) break;  // cluster sizes increase
    const double d = secondDifference(0, m);
    const ExactNonNegativeSum::Digits d2 = ExactNonNegativeSum::digitsOf(d * d);
    window_sums_[i].add(d2);
    since_start_sums_[i].add(d2);
  }
}

void RollingOverlappingAllan::requireIndex(std::size_t index, const char* where) const {
  if (index >= cluster_sizes_.size()) {
    throw std::out_of_range(std::string("the live Allan variance's ") + where + ": index " + std::to_string(index) +
                            " is not below the number of cluster sizes (" + std::to_string(cluster_sizes_.size()) +
                            ")");
  }
}

std::size_t RollingOverlappingAllan::windowTerms(std::size_t index) const {
  requireIndex(index, "noise terms over the window");
  const std::size_t n = windowCount();
  const std::size_t m = cluster_sizes_[index];
  return 2 * m <= n ? n - 2 * m + 1 : 0;
}

std::uint64_t RollingOverlappingAllan::sinceStartTerms(std::size_t index) const {
  requireIndex(index, "noise terms since the start");
  const std::uint64_t m = cluster_sizes_[index];
  return 2 * m <= total_count_ ? total_count_ - 2 * m + 1 : 0;
}

// NIST SP 1065 eq. 11: σ² = Σ d_j² / (2 m² (M − 2m + 1)).
double RollingOverlappingAllan::windowVariance(std::size_t index) const {
  const std::size_t terms = windowTerms(index);
  if (terms == 0) return kNaN;
  const double m = static_cast<double>(cluster_sizes_[index]);
  return window_sums_[index].value() / (2.0 * m * m * static_cast<double>(terms));
}

double RollingOverlappingAllan::sinceStartVariance(std::size_t index) const {
  const std::uint64_t terms = sinceStartTerms(index);
  if (terms == 0) return kNaN;
  const double m = static_cast<double>(cluster_sizes_[index]);
  return since_start_sums_[index].value() / (2.0 * m * m * static_cast<double>(terms));
}

std::size_t RollingOverlappingAllan::stateBytes() const {
  return sizeof(*this) + cluster_sizes_.capacity() * sizeof(std::size_t) +
         (window_sums_.capacity() + since_start_sums_.capacity()) * sizeof(ExactNonNegativeSum) +
         ring_.capacity() * sizeof(PhasePoint);
}

RollingOverlappingAllan::Snapshot RollingOverlappingAllan::snapshot(double tau0_s, const AllanOptions& options) const {
  if (!(std::isfinite(tau0_s) && tau0_s > 0.0)) {
    throw std::invalid_argument(
        "the live Allan table needs a sample interval tau0 that is a finite positive time in s (got " +
        formatNumber(tau0_s) + ")");
  }
  if (!(options.confidence > 0.0 && options.confidence < 1.0)) {
    throw std::invalid_argument("the live Allan table needs a confidence in (0, 1) (got " +
                                formatNumber(options.confidence) + ")");
  }
  // The window's rates (minus the reference, which the mean-removed noise identification
  // does not see), as differences of consecutive phase points.
  const std::size_t n = windowCount();
  std::vector<double> rates(n);
  for (std::size_t k = 0; k < n; ++k) {
    const PhasePoint& newer = ring_[slotBack(n - k - 1)];
    const PhasePoint& older = ring_[slotBack(n - k)];
    rates[k] = difference(newer.hi, newer.lo, older.hi, older.lo).hi;
  }
  // identifyPowerLawNoise's short-series slope method needs two factors m ≤ M/2, i.e.
  // M ≥ 4 samples.
  constexpr std::size_t kMinSamplesForNoiseId = 4;
  const bool identifiable = n >= kMinSamplesForNoiseId;

  Snapshot snap;
  snap.window.reserve(cluster_sizes_.size());
  snap.since_start.reserve(cluster_sizes_.size());
  for (std::size_t i = 0; i < cluster_sizes_.size(); ++i) {
    const std::size_t m = cluster_sizes_[i];
    AllanPoint w;
    w.tau_s = static_cast<double>(m) * tau0_s;
    w.m = m;
    w.adev = kNaN;
    w.adev_terms = 0;
    w.noise_alpha = identifiable ? identifyPowerLawNoise(rates, m) : 0;
    AllanPoint s = w;

    w.oadev = std::sqrt(windowVariance(i));
    w.oadev_terms = windowTerms(i);
    s.oadev = std::sqrt(sinceStartVariance(i));
    const std::uint64_t since_terms = sinceStartTerms(i);
    s.oadev_terms = static_cast<std::size_t>(since_terms);

    auto fillConfidence = [&](AllanPoint& p, std::uint64_t sample_count, std::uint64_t terms) {
      if (!identifiable || terms == 0) {
        p.edf = kNaN;
        p.oadev_lo = kNaN;
        p.oadev_hi = kNaN;
        return;
      }
      p.edf = overlappingAllanEdf(p.noise_alpha, static_cast<std::size_t>(sample_count + 1), m);
      const DeviationInterval interval = allanDeviationConfidenceInterval(p.oadev, p.edf, options.confidence);
      p.oadev_lo = interval.lo;
      p.oadev_hi = interval.hi;
    };
    fillConfidence(w, n, w.oadev_terms);
    fillConfidence(s, total_count_, since_terms);
    snap.window.push_back(w);
    snap.since_start.push_back(s);
  }
  return snap;
}

}  // namespace gyrod::processing
