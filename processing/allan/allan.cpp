#include "processing/allan/allan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iomanip>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "processing/allan/allan_kernels.hpp"
#include "processing/allan/allan_noise_type.hpp"
#include "processing/base/distributions.hpp"
#include "processing/base/parallel_share.hpp"

namespace gyrod::processing {
namespace {

using allan_detail::formatNumber;
using allan_detail::requireClusterSize;

using allan_noise_type::lag1NoiseId;
using allan_noise_type::noiseTypesForTable;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The series' mean from its double-double sum, with the sums of its runs, which spare the
// phase integration a pass (allan_kernels::sumRuns, both cores). Throws on a non-finite sample
// so that no estimator ever silently turns a NaN reading into a number; only a non-finite sum
// sends it through the serial loop that names the sample.
struct CheckedSums {
  double mean = 0.0;
  std::vector<allan_kernels::RunSum> runs;
};

CheckedSums checkedSums(std::span<const double> rate, const char* where) {
  if (rate.empty()) return {};
  CheckedSums sums;
  sums.runs = allan_kernels::sumRuns(rate.data(), rate.size());
  const double sum = allan_kernels::totalOfRuns(sums.runs);
  sums.mean = sum / static_cast<double>(rate.size());
  if (std::isfinite(sum)) return sums;
  for (std::size_t i = 0; i < rate.size(); ++i) {
    const double v = rate[i];
    if (!std::isfinite(v)) {
      throw std::invalid_argument(std::string(where) + " cannot use rate sample " + std::to_string(i) +
                                  ": it is not finite (" + formatNumber(v) + ")");
    }
  }
  return sums;  // finite samples whose sum overflows
}

double checkedMean(std::span<const double> rate, const char* where) { return checkedSums(rate, where).mean; }

// Sum of squares accumulated in blocks: four interleaved partial sums inside a block
// (independent chains the compiler can vectorise), block totals added with Neumaier
// compensation, so the rounding error grows with the block length, not with M.
class SumOfSquares {
 public:
  void add(double block_total) {
    const double t = sum_ + block_total;
    compensation_ += std::abs(sum_) >= std::abs(block_total) ? (sum_ - t) + block_total : (block_total - t) + sum_;
    sum_ = t;
  }
  double total() const { return sum_ + compensation_; }

 private:
  double sum_ = 0.0;
  double compensation_ = 0.0;
};

constexpr std::size_t kSumBlock = 4096;
// Relative change of a block's sum of squares up to which the multi-m sweep may leave the
// phase's lo parts out (IntegratedPhase::highOnlySuffices).
constexpr double kHighOnlyTolerance = 1e-13;
// The largest m whose block sums in the multi-m sweep read the block's lo parts widened once
// (a block and 2·kWideReach phase points past it).
constexpr std::size_t kWideReach = 64;

// The phase (integrated rate, NIST SP 1065 x_k with x₀ = 0 and τ0 = 1 sample) of the
// mean-removed series, held as an unevaluated sum hi[k] + lo[k]. Removing the mean keeps
// |x| small (Allan variance is blind to a constant rate); the running sum is double-double,
// so its integration error stays at ~ε² of |x| even when x grows quadratically (a rate
// ramp). lo is stored as a float (12 bytes a point instead of 16): |lo| ≤ ulp(hi)/2, so
// rounding it costs at most 2⁻²⁴·ulp(hi)/2 ≈ 2⁻⁷⁷·|x|, and a second difference is off by
// at most 4·2⁻⁷⁷·max|x| (plus its own rounding): for the 10⁷-sample random walk of the
// tests, max|x| ≈ 10¹⁰·σ gives ≤ 3·10⁻¹³·σ against differences of order σ. (A float lo
// flushes to zero below ~10⁻⁴⁵, far below any rate a gyro reports.)
class IntegratedPhase {
 public:
  explicit IntegratedPhase(std::span<const double> rate, const char* where)
      : IntegratedPhase(rate, checkedSums(rate, where)) {}
  // With the mean and run sums already formed (by checkedSums, which has checked every sample).
  IntegratedPhase(std::span<const double> rate, const CheckedSums& sums)
      : IntegratedPhase(rate, sums, allan_kernels::allocatePhaseStorage<double>(rate.size() + 1),
                        allan_kernels::allocatePhaseStorage<float>(rate.size() + 1)) {}
  // In storage the caller keeps (at least rate.size() + 1 points each). The rate may lie at
  // hi + 1 itself: each sample is read before the phase point written over it.
  IntegratedPhase(std::span<const double> rate, const CheckedSums& sums, double* hi, float* lo)
      : rate_count_(rate.size()), mean_(sums.mean), hi_(hi), lo_(lo) {
    integrate(rate, sums.runs);
  }

  std::size_t rateCount() const { return rate_count_; }
  double mean() const { return mean_; }

 private:
  IntegratedPhase(std::span<const double> rate, const CheckedSums& sums, allan_kernels::PhaseStorage<double> hi,
                  allan_kernels::PhaseStorage<float> lo)
      : rate_count_(rate.size()),
        mean_(sums.mean),
        owned_hi_(std::move(hi)),
        owned_lo_(std::move(lo)),
        hi_(owned_hi_.get()),
        lo_(owned_lo_.get()) {
    integrate(rate, sums.runs);
  }

  void integrate(std::span<const double> rate, std::span<const allan_kernels::RunSum> run_sums) {
    const float max_abs_lo = allan_kernels::integratePhase(rate.data(), rate.size(), mean_, run_sums, hi_, lo_);
    // Each lo combination (lc − lb) − (lb − la) of four floats is at most 4·max|lo| (its
    // two roundings in double add at most 2⁻⁵² of that; the margin covers them).
    lo_term_bound_ = 4.0 * static_cast<double>(max_abs_lo) * (1.0 + 1e-12);
  }

 public:
  // x_{i+2m} − 2·x_{i+m} + x_i = m·(ȳ over [i+m, i+2m) − ȳ over [i, i+m)). The hi
  // parts are differenced first (each difference is a window sum, small), then the lo
  // corrections are added.
  double secondDifference(std::size_t i, std::size_t m) const {
    const double* h = hi_;
    const float* l = lo_;
    const double la = l[i], lb = l[i + m], lc = l[i + 2 * m];
    return ((h[i + 2 * m] - h[i + m]) - (h[i + m] - h[i])) + ((lc - lb) - (lb - la));
  }

  // Σ over `count` second differences starting at 0, 0+stride, ... of their squares.
  double sumSquaredSecondDifferences(std::size_t m, std::size_t stride, std::size_t count) const {
    SumOfSquares total;
    std::size_t k = 0;
    while (k < count) {
      const std::size_t block_end = std::min(count, k + kSumBlock);
      total.add(stride == 1 ? overlappingBlockTotal(m, k, block_end) : stridedBlockTotal(m, stride, k, block_end));
      k = block_end;
    }
    return total.total();
  }

  // One block of the overlapping sum, terms [k, block_end) (allan_kernels: the same bits
  // on every ISA).
  double overlappingBlockTotal(std::size_t m, std::size_t k, std::size_t block_end) const {
    return allan_kernels::overlappingBlockTotal(hi_, lo_, m, k, block_end);
  }

  double stridedBlockTotal(std::size_t m, std::size_t stride, std::size_t k, std::size_t block_end) const {
    double p0 = 0.0, p1 = 0.0, p2 = 0.0, p3 = 0.0;
    for (; k + 4 <= block_end; k += 4) {
      const double d0 = secondDifference((k + 0) * stride, m);
      const double d1 = secondDifference((k + 1) * stride, m);
      const double d2 = secondDifference((k + 2) * stride, m);
      const double d3 = secondDifference((k + 3) * stride, m);
      p0 += d0 * d0;
      p1 += d1 * d1;
      p2 += d2 * d2;
      p3 += d3 * d3;
    }
    for (; k < block_end; ++k) {
      const double d = secondDifference(k * stride, m);
      p0 += d * d;
    }
    return (p0 + p1) + (p2 + p3);
  }

  // Whether a block's hi-only total (`high`, of `terms` squared differences) may stand for
  // its full total: leaving the lo parts out moves each difference by at most E =
  // lo_term_bound_, so ‖d − d̂‖ ≤ e = √terms·E and ‖d‖ ≥ ‖d̂‖ − e; with a = ‖d̂‖ = √high,
  // |‖d‖² − ‖d̂‖²| ≤ 2ae + e². Accepted when that is at most kHighOnlyTolerance·(a − e)²,
  // i.e. kHighOnlyTolerance of the block's exact total.
  bool highOnlySuffices(double high, std::size_t terms) const {
    const double e = std::sqrt(static_cast<double>(terms)) * lo_term_bound_;
    const double a = std::sqrt(high);
    if (!(a > e)) return false;
    const double gap = a - e;
    return 2.0 * a * e + e * e <= kHighOnlyTolerance * gap * gap;
  }

  // One block's total for the multi-m sweep: the hi-only total where highOnlySuffices says
  // it may stand for the full one, else the full total (overlappingBlockTotal's bits). The
  // hi-only total is the same bits from either kernel, so the result depends only on the
  // block, never on `try_high_first` (a guess from the share's previous block that spares
  // the lo reads when the hi-only total is likely to suffice). `wide`, given only when the guess
  // is the full kernel, holds the block's lo parts from lo[k] on widened to double (the same
  // values, so the same bits).
  double sweepBlockTotal(std::size_t m, std::size_t k, std::size_t block_end, bool& try_high_first,
                         const double* wide) const {
    const std::size_t terms = block_end - k;
    if (try_high_first) {
      const double high = allan_kernels::overlappingHighTotal(hi_, m, k, block_end);
      if (highOnlySuffices(high, terms)) return high;
      try_high_first = false;
      return overlappingBlockTotal(m, k, block_end);
    }
    const allan_kernels::BlockTotals t = wide != nullptr
                                             ? allan_kernels::overlappingBlockTotals(hi_ + k, wide, m, 0, terms)
                                             : allan_kernels::overlappingBlockTotals(hi_, lo_, m, k, block_end);
    if (highOnlySuffices(t.high, terms)) {
      try_high_first = true;
      return t.high;
    }
    return t.full;
  }

  // The overlapping variances at every m of `ms` in one cache-blocked sweep: for each block
  // of kSumBlock start indices, every m reads the phase at the block, m and 2m further on.
  // For octave m the offsets coincide (2·m_k = m_{k+1}), so the block and the nearer
  // offsets are still in cache when the next m needs them. The blocks are shared among
  // threads; each block's total (sweepBlockTotal: hi-only where that is proven within
  // kHighOnlyTolerance) is kept and the totals are added in block order, so the result is
  // the same bits for any number of threads. The m up to kWideReach that need the lo parts
  // share one widening of the block's lo floats to double (the float-to-double conversions
  // cost more than the rest of those sums).
  std::vector<double> overlappingAllanVariances(std::span<const std::size_t> ms) const {
    const std::size_t block_count = (rate_count_ + kSumBlock - 1) / kSumBlock;
    std::vector<double> block_totals(ms.size() * block_count, 0.0);
    const auto sweep = [&](std::size_t first_block, std::size_t end_block) {
      std::vector<char> try_high_first(ms.size(), 0);
      std::vector<double> wide(kSumBlock + 2 * kWideReach);
      for (std::size_t b = first_block; b < end_block; ++b) {
        const std::size_t k = b * kSumBlock;
        bool widened = false;
        for (std::size_t j = 0; j < ms.size(); ++j) {
          const std::size_t terms = overlappingTerms(ms[j]);
          if (k < terms) {
            bool guess = try_high_first[j] != 0;
            const double* block_wide = nullptr;
            if (ms[j] <= kWideReach && !guess) {
              if (!widened) {
                // Phase points k … k + kSumBlock + 2·kWideReach − 1, as far as they go (the
                // last is x_M, M = rate_count_).
                allan_kernels::widenLo(lo_ + k, std::min(wide.size(), rate_count_ + 1 - k), wide.data());
                widened = true;
              }
              block_wide = wide.data();
            }
            block_totals[j * block_count + b] =
                sweepBlockTotal(ms[j], k, std::min(terms, k + kSumBlock), guess, block_wide);
            try_high_first[j] = guess ? 1 : 0;
          }
        }
      }
    };
    forEachShare(block_count, sweep);
    std::vector<double> variances(ms.size(), kNaN);
    for (std::size_t j = 0; j < ms.size(); ++j) {
      const std::size_t terms = overlappingTerms(ms[j]);
      if (terms == 0) continue;
      SumOfSquares total;
      for (std::size_t b = 0; b * kSumBlock < terms; ++b) total.add(block_totals[j * block_count + b]);
      const double md = static_cast<double>(ms[j]);
      variances[j] = total.total() / (2.0 * md * md * static_cast<double>(terms));
    }
    return variances;
  }

  // M − 2m + 1, or 0 when 2m > M.
  std::size_t overlappingTerms(std::size_t m) const { return 2 * m > rate_count_ ? 0 : rate_count_ - 2 * m + 1; }

  // Non-overlapping: K = ⌊M/m⌋ cluster means, K − 1 differences (paper eq. 2).
  double allanVariance(std::size_t m) const {
    const std::size_t clusters = rate_count_ / m;
    if (clusters < 2) return kNaN;
    const double md = static_cast<double>(m);
    return sumSquaredSecondDifferences(m, m, clusters - 1) / (2.0 * md * md * static_cast<double>(clusters - 1));
  }

  // Overlapping: N − 2m = M − 2m + 1 second differences of N = M + 1 phase points
  // (NIST SP 1065 eq. 11), σ² = Σ (x_{i+2m} − 2x_{i+m} + x_i)² / (2 m² (N − 2m)).
  double overlappingAllanVariance(std::size_t m) const {
    if (2 * m > rate_count_) return kNaN;
    const std::size_t terms = rate_count_ - 2 * m + 1;
    const double md = static_cast<double>(m);
    return sumSquaredSecondDifferences(m, 1, terms) / (2.0 * md * md * static_cast<double>(terms));
  }

 private:
  std::size_t rate_count_;
  double mean_;
  // Written once in full by the constructor: not zero-filled first (one pass less over
  // 12 bytes a point).
  allan_kernels::PhaseStorage<double> owned_hi_;  // empty when the caller keeps the storage
  allan_kernels::PhaseStorage<float> owned_lo_;
  double* hi_;
  float* lo_;
  double lo_term_bound_ = 0.0;  // bound on |(lc − lb) − (lb − la)| over the phase
};

// Noise identification at m for a series of ≥ 3 finite samples with the given mean.
// `phase` is needed only for series shorter than kMinAveragedPointsForNoiseId.
int identifyWithMean(std::span<const double> rate, std::size_t m, double mean, const IntegratedPhase* phase) {
  const std::size_t count = rate.size();
  if (count / m >= kMinAveragedPointsForNoiseId) return lag1NoiseId(rate, m, mean);
  // Too few averaged points at this m: use the longest averaging that still has enough
  // (the nearest τ below), assuming the noise type does not change beyond it.
  if (count >= kMinAveragedPointsForNoiseId) return lag1NoiseId(rate, count / kMinAveragedPointsForNoiseId, mean);
  // Very short series: the local log-log slope μ of the overlapping Allan variance,
  // σ² ∝ τ^μ with μ = −α − 1 for α ≤ 1. μ = −2 cannot tell white from flicker PM
  // (both give μ ≈ −2); it is reported as flicker PM (α = 1), which has the smaller edf.
  const std::size_t m_max = count / 2;  // ≥ 1 since count ≥ 3
  const std::size_t m_a = std::min(m, m_max);
  const std::size_t m_b = (m_a + 1 <= m_max) ? m_a + 1 : m_a - 1;
  if (m_b == 0) {
    throw std::invalid_argument("the power-law noise identification needs more samples for a slope (" +
                                std::to_string(count) + " samples)");
  }
  const double va = phase->overlappingAllanVariance(m_a);
  const double vb = phase->overlappingAllanVariance(m_b);
  if (!(va > 0.0 && vb > 0.0)) return 0;  // constant series: σ² = 0, nothing to identify
  const double mu = std::log(vb / va) / std::log(static_cast<double>(m_b) / static_cast<double>(m_a));
  return static_cast<int>(std::clamp(std::round(-mu - 1.0), -2.0, 1.0));
}

// The non-overlapping variances at every m of `ms`, on both cores for a long series. Each m's
// sum is its own, so how the m are shared (greedily by their cost, M/m terms) changes only
// the time.
std::vector<double> nonOverlappingVariances(const IntegratedPhase& phase, std::span<const std::size_t> ms) {
  std::vector<double> variances(ms.size());
  std::array<std::vector<std::size_t>, 2> shares;
  std::array<double, 2> costs = {0.0, 0.0};
  for (std::size_t j = 0; j < ms.size(); ++j) {
    const std::size_t lighter = costs[0] <= costs[1] ? 0 : 1;
    shares[lighter].push_back(j);
    costs[lighter] += 1.0 / static_cast<double>(ms[j]);
  }
  const auto run = [&](const std::vector<std::size_t>& share) {
    for (std::size_t j : share) variances[j] = phase.allanVariance(ms[j]);
  };
  constexpr std::size_t kParallelSamples = std::size_t{1} << 16;
  if (phase.rateCount() < kParallelSamples) {
    run(shares[0]);
    run(shares[1]);
  } else {
    runBoth([&] { run(shares[1]); }, [&] { run(shares[0]); });
  }
  return variances;
}

}  // namespace

// ---- cluster sizes -----------------------------------------------------------------

std::vector<std::size_t> octaveClusterSizes(std::size_t sample_count) {
  std::vector<std::size_t> ms;
  for (std::size_t m = 1; m <= sample_count / 2; m *= 2) ms.push_back(m);
  return ms;
}

std::vector<std::size_t> denseClusterSizes(std::size_t sample_count, std::size_t per_decade) {
  if (per_decade == 0) throw std::invalid_argument("the Allan tau grid needs at least 1 tau per decade (got 0)");
  std::vector<std::size_t> ms;
  const std::size_t m_max = sample_count / 2;
  for (std::size_t k = 0;; ++k) {
    const double exact = std::pow(10.0, static_cast<double>(k) / static_cast<double>(per_decade));
    const auto m = static_cast<std::size_t>(std::llround(exact));
    if (m > m_max || exact > static_cast<double>(m_max) + 0.5) break;
    if (ms.empty() || m != ms.back()) ms.push_back(m);
  }
  return ms;
}

std::vector<std::size_t> clusterSizesForTaus(std::span<const double> taus_s, double tau0_s, std::size_t sample_count) {
  if (!(std::isfinite(tau0_s) && tau0_s > 0.0)) {
    throw std::invalid_argument("the Allan taus need a sample interval tau0 that is a finite positive time in s (got " +
                                formatNumber(tau0_s) + ")");
  }
  std::vector<std::size_t> ms;
  ms.reserve(taus_s.size());
  for (double tau : taus_s) {
    if (!(std::isfinite(tau) && tau > 0.0)) {
      throw std::invalid_argument("the Allan deviation at tau " + formatNumber(tau) +
                                  " s cannot be computed: tau is not a finite positive time");
    }
    const double samples = tau / tau0_s;
    const double whole = std::round(samples);
    if (whole < 1.0 || std::abs(samples - whole) > 1e-9 * samples) {
      throw std::invalid_argument("the Allan deviation at tau " + formatNumber(tau) +
                                  " s cannot be computed: tau is not a whole number of samples (tau0 = " +
                                  formatNumber(tau0_s) + " s gives " + formatNumber(samples) + " samples)");
    }
    // m may be at most floor(N/2): two clusters must fit.
    if (whole > static_cast<double>(sample_count / 2)) {  // NOLINT(bugprone-integer-division)
      throw std::invalid_argument("the Allan deviation at tau " + formatNumber(tau) + " s (m = " + formatNumber(whole) +
                                  " samples) is too long for " + std::to_string(sample_count) +
                                  " samples: the overlapping estimator needs 2*m <= sample count");
    }
    ms.push_back(static_cast<std::size_t>(whole));
  }
  return ms;
}

// ---- estimators ----------------------------------------------------------------------

double allanVariance(std::span<const double> rate, std::size_t m) {
  requireClusterSize(m, "the Allan variance");
  if (rate.size() / m < 2) {
    checkedMean(rate, "the Allan variance");  // still reject non-finite input
    return kNaN;
  }
  return IntegratedPhase(rate, "the Allan variance").allanVariance(m);
}

double overlappingAllanVariance(std::span<const double> rate, std::size_t m) {
  requireClusterSize(m, "the overlapping Allan variance");
  if (2 * m > rate.size()) {
    checkedMean(rate, "the overlapping Allan variance");
    return kNaN;
  }
  return IntegratedPhase(rate, "the overlapping Allan variance").overlappingAllanVariance(m);
}

std::vector<double> overlappingAllanVariances(std::span<const double> rate, std::span<const std::size_t> ms) {
  for (std::size_t m : ms) requireClusterSize(m, "the overlapping Allan variances");
  const IntegratedPhase phase(rate, "the overlapping Allan variances");
  return phase.overlappingAllanVariances(ms);
}

int identifyPowerLawNoise(std::span<const double> rate, std::size_t m) {
  requireClusterSize(m, "the power-law noise identification");
  if (rate.size() < 3) {
    throw std::invalid_argument("the power-law noise identification needs at least 3 samples (got " +
                                std::to_string(rate.size()) + ")");
  }
  const double mean = checkedMean(rate, "the power-law noise identification");
  if (rate.size() >= kMinAveragedPointsForNoiseId) return identifyWithMean(rate, m, mean, nullptr);
  const IntegratedPhase phase(rate, "the power-law noise identification");
  return identifyWithMean(rate, m, mean, &phase);
}

namespace {

// Where a table's phase goes: storage of its own, or a workspace's (the rate maybe in it).
struct PhasePlace {
  double* hi = nullptr;  // null: the table allocates its own
  float* lo = nullptr;
  bool rate_in_place = false;                        // the rate lies at hi + 1 and becomes the phase
  const std::function<void()>* alongside = nullptr;  // run beside the noise types (in place only)
};

std::vector<AllanPoint> tableWithPhaseAt(std::span<const double> rate, double tau0_s, std::span<const std::size_t> ms,
                                         const AllanOptions& options, PhasePlace place) {
  if (!(std::isfinite(tau0_s) && tau0_s > 0.0)) {
    throw std::invalid_argument(
        "the Allan deviation table needs a sample interval tau0 that is a finite positive time in s (got " +
        formatNumber(tau0_s) + ")");
  }
  if (!(options.confidence > 0.0 && options.confidence < 1.0)) {
    throw std::invalid_argument("the Allan deviation table needs a confidence in (0, 1) (got " +
                                formatNumber(options.confidence) + ")");
  }
  if (rate.size() < 3) {
    throw std::invalid_argument("the Allan deviation table needs at least 3 rate samples (got " +
                                std::to_string(rate.size()) + ")");
  }
  for (std::size_t m : ms) requireClusterSize(m, "the Allan deviation table");

  const std::size_t count = rate.size();
  const CheckedSums sums = checkedSums(rate, "the Allan deviation table");  // one pass for both
  const double mean = sums.mean;
  std::vector<int> alphas;
  std::optional<IntegratedPhase> integrated;
  std::vector<double> overlapping, non_overlapping;
  const auto phaseAndSweeps = [&] {
    if (place.hi != nullptr)
      integrated.emplace(rate, sums, place.hi, place.lo);
    else
      integrated.emplace(rate, sums);
    overlapping = integrated->overlappingAllanVariances(ms);
    non_overlapping = nonOverlappingVariances(*integrated, ms);
  };
  if (place.rate_in_place) {
    // The noise types read the rate, which the phase then overwrites.
    alphas =
        noiseTypesForTable(rate, ms, mean, place.alongside != nullptr ? *place.alongside : std::function<void()>());
    phaseAndSweeps();
  } else {
    // The noise types (the lag-1 method averages the rate itself) beside the phase and its
    // sweeps, which share the cores among themselves.
    runBoth([&] { alphas = noiseTypesForTable(rate, ms, mean); }, phaseAndSweeps);
  }
  const IntegratedPhase& phase = *integrated;

  std::vector<AllanPoint> table;
  table.reserve(ms.size());
  for (std::size_t j = 0; j < ms.size(); ++j) {
    const std::size_t m = ms[j];
    AllanPoint p;
    p.m = m;
    p.tau_s = static_cast<double>(m) * tau0_s;
    p.adev = std::sqrt(non_overlapping[j]);
    p.adev_terms = count / m >= 1 ? count / m - 1 : 0;
    p.oadev = std::sqrt(overlapping[j]);
    p.oadev_terms = phase.overlappingTerms(m);
    // Empty alphas: a series too short for the lag-1 method, identified from the phase
    // alone (identifyWithMean reads only the rate's length then).
    p.noise_alpha = alphas.empty() ? identifyWithMean(rate, m, phase.mean(), &phase) : alphas[j];
    if (p.oadev_terms >= 1) {
      p.edf = overlappingAllanEdf(p.noise_alpha, count + 1, m);
      const DeviationInterval interval = allanDeviationConfidenceInterval(p.oadev, p.edf, options.confidence);
      p.oadev_lo = interval.lo;
      p.oadev_hi = interval.hi;
    } else {
      p.edf = kNaN;
      p.oadev_lo = kNaN;
      p.oadev_hi = kNaN;
    }
    table.push_back(p);
  }
  return table;
}

void requireCapacity(const AllanWorkspace& workspace, std::size_t count) {
  if (count > workspace.capacity())
    throw std::invalid_argument("the Allan deviation table needs a workspace for " + std::to_string(count) +
                                " samples, this one holds " + std::to_string(workspace.capacity()));
}

}  // namespace

AllanWorkspace::AllanWorkspace(std::size_t capacity) : AllanWorkspace(capacity, std::vector<double>()) {}

AllanWorkspace::AllanWorkspace(std::size_t capacity, std::vector<double>&& reused)
    : capacity_(capacity), lo_(allan_kernels::allocatePhaseStorage<float>(capacity + 1)) {
  if (reused.capacity() >= capacity + 1) {
    reused_hi_ = std::move(reused);
    reused_hi_.resize(capacity + 1);  // within its capacity: the column's memory, no new
    hi_ = reused_hi_.data();
  } else {
    reused = std::vector<double>();  // lost either way, as the caller was told
    owned_hi_ = allan_kernels::allocatePhaseStorage<double>(capacity + 1);
    hi_ = owned_hi_.get();
  }
}

std::vector<AllanPoint> allanDeviationTable(std::span<const double> rate, double tau0_s,
                                            std::span<const std::size_t> ms, const AllanOptions& options) {
  return tableWithPhaseAt(rate, tau0_s, ms, options, {});
}

std::vector<AllanPoint> allanDeviationTable(std::span<const double> rate, double tau0_s,
                                            std::span<const std::size_t> ms, const AllanOptions& options,
                                            AllanWorkspace& workspace) {
  requireCapacity(workspace, rate.size());
  return tableWithPhaseAt(rate, tau0_s, ms, options, {workspace.phaseHi(), workspace.phaseLo(), false});
}

std::vector<AllanPoint> allanDeviationTableInPlace(AllanWorkspace& workspace, std::size_t count, double tau0_s,
                                                   std::span<const std::size_t> ms, const AllanOptions& options,
                                                   const std::function<void()>& alongside) {
  requireCapacity(workspace, count);
  return tableWithPhaseAt(workspace.rateSlots().first(count), tau0_s, ms, options,
                          {workspace.phaseHi(), workspace.phaseLo(), true, alongside ? &alongside : nullptr});
}

std::vector<double> overlappingAllanVariances(std::span<const double> rate, std::span<const std::size_t> ms,
                                              AllanWorkspace& workspace) {
  for (std::size_t m : ms) requireClusterSize(m, "the overlapping Allan variances");
  requireCapacity(workspace, rate.size());
  const IntegratedPhase phase(rate, checkedSums(rate, "the overlapping Allan variances"), workspace.phaseHi(),
                              workspace.phaseLo());
  return phase.overlappingAllanVariances(ms);
}

}  // namespace gyrod::processing
