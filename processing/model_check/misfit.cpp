// The misfit of the model the check ends with: the two tests (held-out whiteness, Allan band)
// and where it misses (τ range of the Allan curve, frequency band of the innovations).
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <unsupported/Eigen/FFT>

#include "processing/base/detrend.hpp"
#include "processing/base/distributions.hpp"
#include "processing/model_check/live_check.hpp"
#include "processing/model_check/pipeline.hpp"
#include "processing/paper/ar_model.hpp"

namespace gyrod::processing {

SpectralExcess innovationSpectralExcess(std::span<const double> x, double rate_hz, double family_alpha) {
  SpectralExcess out;
  const std::size_t n = x.size();
  std::size_t seg = 64;
  while (seg * 2 <= n / 16 && seg < 1024) seg *= 2;
  out.segment = seg;
  if (n < 2 * seg) return out;
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  std::vector<double> w(seg);
  for (std::size_t i = 0; i < seg; ++i)
    w[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(seg));
  const std::size_t hop = seg / 2, segments = (n - seg) / hop + 1;
  std::vector<double> power(seg / 2 + 1, 0.0), in(seg);
  std::vector<std::complex<double>> spec;
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  for (std::size_t s = 0; s < segments; ++s) {
    for (std::size_t i = 0; i < seg; ++i) in[i] = w[i] * (x[s * hop + i] - mean);
    fft.fwd(spec, in);
    for (std::size_t k = 0; k <= seg / 2; ++k) power[k] += std::norm(spec[k]);
  }
  // Bins 1..L/2−1: the DC and Nyquist bins of a real series have half the degrees of freedom.
  const std::size_t bins = seg / 2 - 1;
  std::vector<double> p(power.begin() + 1, power.begin() + 1 + static_cast<std::ptrdiff_t>(bins));
  // Equivalent degrees of freedom of Welch's estimate, Hann window, 50 % overlap
  // (Percival & Walden 1993, eq. 292b): ν = 36K²/(19K − 1).
  const double k = static_cast<double>(segments);
  const double nu = 36.0 * k * k / (19.0 * k - 1.0);
  std::vector<double> sorted = p;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(bins / 2), sorted.end());
  const double level = sorted[bins / 2] / (chiSquareQuantile(0.5, nu) / nu);
  if (!(level > 0.0)) return out;
  out.threshold = chiSquareQuantile(1.0 - family_alpha / static_cast<double>(bins), nu) / nu;
  const double df = rate_hz / static_cast<double>(seg);
  std::size_t best_lo = 0, best_hi = 0;
  double best_peak = 0.0;
  for (std::size_t j = 0; j < bins;) {
    if (p[j] / level <= out.threshold) {
      out.peak_ratio = std::max(out.peak_ratio, p[j] / level);
      ++j;
      continue;
    }
    std::size_t e = j;
    double peak = 0.0;
    while (e < bins && p[e] / level > out.threshold) peak = std::max(peak, p[e++] / level);
    out.peak_ratio = std::max(out.peak_ratio, peak);
    if (peak > best_peak) {
      best_peak = peak;
      best_lo = j;
      best_hi = e;
    }
    j = e;
  }
  if (best_peak == 0.0) return out;
  double sum = 0.0;
  for (std::size_t j = best_lo; j < best_hi; ++j) sum += p[j] / level;
  out.found = true;
  out.power_ratio = sum / static_cast<double>(best_hi - best_lo);
  // Bin j is frequency (j + 1)·df; the band runs half a bin either side of its bins.
  out.freq_lo_hz = (static_cast<double>(best_lo) + 0.5) * df;
  out.freq_hi_hz = (static_cast<double>(best_hi) + 0.5) * df;
  return out;
}

LjungBox blockLjungBox(std::span<const double> e, std::size_t lags, std::size_t block) {
  const std::size_t n = e.size();
  if (block < 4 * lags || n < 2 * block) return ljungBoxTest(e, lags, 0);
  const std::size_t blocks = n / block;
  std::vector<double> y(blocks * block);
  for (std::size_t b = 0; b < blocks; ++b) {
    double mean = 0.0;
    for (std::size_t i = 0; i < block; ++i) mean += e[b * block + i];
    mean /= static_cast<double>(block);
    for (std::size_t i = 0; i < block; ++i) y[b * block + i] = e[b * block + i] - mean;
  }
  double c0 = 0.0;
  for (double v : y) c0 += v * v;
  LjungBox lb;
  if (!(c0 > 0.0)) return lb;
  const double bb = static_cast<double>(block), nn = static_cast<double>(y.size());
  for (std::size_t k = 1; k <= lags; ++k) {
    // Four partial sums: the compiler may not reorder one floating-point sum, and these lags
    // over every replica's held-out half were ~3 % of a check.
    double part[4] = {0.0, 0.0, 0.0, 0.0};
    for (std::size_t b = 0; b < blocks; ++b) {
      std::size_t i = b * block + k;
      const std::size_t end = (b + 1) * block;
      for (; i + 4 <= end; i += 4)
        for (std::size_t u = 0; u < 4; ++u) part[u] += y[i + u] * y[i + u - k];
      for (; i < end; ++i) part[0] += y[i] * y[i - k];
    }
    const double ck = (part[0] + part[1]) + (part[2] + part[3]);
    // Removing each block's mean makes white noise's lag-k products −σ²/B on average:
    // E ρ̂_k = −(B − k)/(B(B − 1)), taken off.
    const double kk = static_cast<double>(k);
    const double rho = ck / c0 + (bb - kk) / (bb * (bb - 1.0));
    const double pairs = static_cast<double>(blocks) * (bb - kk);
    lb.q += rho * rho * nn * nn / pairs;
  }
  lb.dof = lags;
  lb.p_value = 1.0 - chiSquareCdf(lb.q, static_cast<double>(lags));
  return lb;
}

HeldOutWhiteness heldOutWhiteness(std::span<const double> fit, std::span<const double> score, std::size_t max_order,
                                  std::size_t lags) {
  HeldOutWhiteness out;
  std::vector<double> a(fit.begin(), fit.end()), b(score.begin(), score.end());
  constexpr std::size_t kBurnIn = 100;
  if (a.size() < 4 || b.size() <= kBurnIn + lags + 1) return out;
  removeLinearTrend(a, 1.0);
  removeLinearTrend(b, 1.0);
  const std::vector<ArModel> ar = yuleWalker(a, std::min(max_order, a.size() / 10 + 1));
  // BIC, not AIC: an order AIC picks for chance structure of one half (up to 29 of 32 on clean
  // records) colours the other half's errors, by about χ²(p) in Q.
  const ArModel& m = ar[orderByBic(ar) - 1];
  out.ar_order = m.order();
  const std::size_t p = m.order();
  out.errors.reserve(b.size() - kBurnIn);
  for (std::size_t i = std::max(p, kBurnIn); i < b.size(); ++i) {
    double pred = 0.0;
    for (std::size_t j = 0; j < p; ++j) pred += m.phi[j] * b[i - 1 - j];
    out.errors.push_back(b[i] - pred);
  }
  out.test = blockLjungBox(out.errors, lags, kWhitenessBlock);
  return out;
}

namespace {

// Sample autocorrelation of x at lags 1..lags.
std::vector<double> autocorrelation(const std::vector<double>& x, std::size_t lags) {
  std::vector<double> r(lags, 0.0);
  double c0 = 0.0;
  for (double v : x) c0 += v * v;
  if (!(c0 > 0.0)) return r;
  for (std::size_t k = 1; k <= lags && k < x.size(); ++k) {
    double ck = 0.0;
    for (std::size_t i = k; i < x.size(); ++i) ck += x[i] * x[i - k];
    r[k - 1] = ck / c0;
  }
  return r;
}

}  // namespace

HalvesChange halvesChange(std::span<const double> x, double rate_hz) {
  HalvesChange out;
  const std::size_t h = x.size() / 2;
  if (h < 128) return out;  // also more than 4 · kHalvesLags
  std::vector<double> a(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(h));
  std::vector<double> b(x.begin() + static_cast<std::ptrdiff_t>(h), x.begin() + static_cast<std::ptrdiff_t>(2 * h));
  removeLinearTrend(a, 1.0);
  removeLinearTrend(b, 1.0);
  const std::vector<double> ra = autocorrelation(a, kHalvesLags), rb = autocorrelation(b, kHalvesLags);
  double sum = 0.0;
  for (std::size_t k = 0; k < kHalvesLags; ++k) sum += (ra[k] - rb[k]) * (ra[k] - rb[k]);
  out.colour_q = sum * static_cast<double>(h) / 2.0;
  out.lag1_first = ra[0];
  out.lag1_second = rb[0];
  std::size_t seg = 64;
  while (seg * 2 <= h / 16 && seg < 1024) seg *= 2;
  if (h < 16 * seg) return out;
  std::size_t segments = 0;
  const std::vector<double> pa = welchPowerSum(a, seg, &segments), pb = welchPowerSum(b, seg, &segments);
  double best = -1.0;
  for (std::size_t k = 1; k < seg / 2; ++k) {  // DC and Nyquist left out (half the degrees of freedom)
    if (!(pa[k] > 0.0 && pb[k] > 0.0)) continue;
    const double d = std::fabs(std::log(pb[k] / pa[k]));
    if (d > best) {
      best = d;
      out.spectrum_hz = static_cast<double>(k) * rate_hz / static_cast<double>(seg);
      out.spectrum_ratio = pb[k] / pa[k];
    }
  }
  if (best >= 0.0) out.spectrum_stat = best;
  return out;
}

double gumbelNullP(double v, const std::vector<double>& null) {
  if (null.size() < 8 || !std::isfinite(v)) return std::numeric_limits<double>::quiet_NaN();
  std::vector<double> sorted = null;
  std::sort(sorted.begin(), sorted.end());
  const double q50 = model_check_detail::sortedQuantile(sorted, 0.5);
  const double q90 = model_check_detail::sortedQuantile(sorted, 0.9);
  const double beta = (q90 - q50) / 1.8839;  // as whiteNullP
  if (!(beta > 0.0)) return v > sorted.back() ? 0.0 : 1.0;
  const double mu = q50 - 0.3665 * beta;
  return -std::expm1(-std::exp(-(v - mu) / beta));
}

double whiteNullP(double q, const std::vector<double>& null_q, std::size_t lags) {
  if (null_q.size() < 8) return 1.0 - chiSquareCdf(q, static_cast<double>(lags));
  std::vector<double> sorted = null_q;
  std::sort(sorted.begin(), sorted.end());
  const double q50 = model_check_detail::sortedQuantile(sorted, 0.5);
  const double q90 = model_check_detail::sortedQuantile(sorted, 0.9);
  // Gumbel through the median and the 90 % point: F(x) = exp(−exp(−(x − μ)/β)), its median
  // μ + 0.3665β and 90 % point μ + 2.2504β.
  const double beta = (q90 - q50) / 1.8839;
  if (!(beta > 0.0)) return 1.0 - chiSquareCdf(q, static_cast<double>(lags));
  const double mu = q50 - 0.3665 * beta;
  return -std::expm1(-std::exp(-(q - mu) / beta));
}

}  // namespace gyrod::processing

namespace gyrod::processing::model_check_detail {

namespace {

// P(M ≥ m) for M beta-binomial over n trials with the mean and variance of `misses` (the
// replicas' counts, by moments); the overdispersion is kept in [1e-6, 0.99].
double betaBinomialUpperTail(std::size_t m, std::size_t n, const std::vector<double>& misses) {
  if (m == 0) return 1.0;
  if (m > n || misses.empty()) return 0.0;
  const double nn = static_cast<double>(n);
  double mean = 0.0, var = 0.0;
  for (double v : misses) mean += v;
  mean /= static_cast<double>(misses.size());
  for (double v : misses) var += (v - mean) * (v - mean);
  var /= std::max<double>(1.0, static_cast<double>(misses.size()) - 1.0);
  // Half a miss over all replicas keeps p > 0 when no replica missed.
  const double p =
      std::clamp((mean * static_cast<double>(misses.size()) + 0.5) / (nn * static_cast<double>(misses.size()) + 1.0),
                 1e-9, 1.0 - 1e-9);
  const double binomial_var = nn * p * (1.0 - p);
  const double rho = n > 1 ? std::clamp((var / binomial_var - 1.0) / (nn - 1.0), 1e-6, 0.99) : 1e-6;
  const double ab = (1.0 - rho) / rho, a = p * ab, b = (1.0 - p) * ab;
  const double log_beta_ab = std::lgamma(a) + std::lgamma(b) - std::lgamma(a + b);
  double tail = 0.0;
  for (std::size_t x = m; x <= n; ++x) {
    const double xx = static_cast<double>(x);
    const double log_choose = std::lgamma(nn + 1.0) - std::lgamma(xx + 1.0) - std::lgamma(nn - xx + 1.0);
    const double log_beta = std::lgamma(xx + a) + std::lgamma(nn - xx + b) - std::lgamma(nn + a + b);
    tail += std::exp(log_choose + log_beta - log_beta_ab);
  }
  return std::min(1.0, tail);
}

// The run of log bands where the record's power exceeds every base replica's, around the
// largest such excess over the replicas' median (band edges from the geometric centres).
void placeInSpectrum(const AxisModelCheck& s, ModelMisfit& m) {
  const std::size_t bands = s.spectrum_freq_hz.size();
  if (bands < 2 || s.spectrum_measured.size() != bands || s.spectrum_base_max.size() != bands) return;
  const auto excess = [&s](std::size_t j) {
    return std::isfinite(s.spectrum_measured[j]) && std::isfinite(s.spectrum_base_max[j]) &&
           s.spectrum_measured[j] > s.spectrum_base_max[j] && s.spectrum_base_median[j] > 0.0;
  };
  std::size_t best = bands;
  double best_ratio = 0.0;
  for (std::size_t j = 0; j < bands; ++j)
    if (excess(j) && s.spectrum_measured[j] / s.spectrum_base_median[j] > best_ratio) {
      best_ratio = s.spectrum_measured[j] / s.spectrum_base_median[j];
      best = j;
    }
  if (best == bands) return;
  std::size_t lo = best, hi = best;
  while (lo > 0 && excess(lo - 1)) --lo;
  while (hi + 1 < bands && excess(hi + 1)) ++hi;
  double sum = 0.0;
  for (std::size_t j = lo; j <= hi; ++j) sum += s.spectrum_measured[j] / s.spectrum_base_median[j];
  const double half_step = std::sqrt(s.spectrum_freq_hz[1] / s.spectrum_freq_hz[0]);
  m.freq_lo_hz = s.spectrum_freq_hz[lo] / half_step;
  m.freq_hi_hz = s.spectrum_freq_hz[hi] * half_step;
  m.power_ratio = sum / static_cast<double>(hi - lo + 1);
  m.power_against_replicas = true;
}

// The halves' change against the base replicas' (ModelMisfit::halves_*).
void judgeHalves(std::span<const double> residual, const AllanNull& base_null, double rate_hz, ModelMisfit& m) {
  const HalvesChange h = halvesChange(residual, rate_hz);
  m.halves_lag1_first = h.lag1_first;
  m.halves_lag1_second = h.lag1_second;
  m.halves_colour_p = std::isfinite(h.colour_q) ? whiteNullP(h.colour_q, base_null.halves_colour_q, kHalvesLags)
                                                : std::numeric_limits<double>::quiet_NaN();
  m.halves_spectrum_p = gumbelNullP(h.spectrum_stat, base_null.halves_spectrum_stat);
  m.halves_spectrum_hz = h.spectrum_hz;
  m.halves_spectrum_ratio = h.spectrum_ratio;
  m.halves_differ = m.halves_colour_p < kHalvesAlpha / 2 || m.halves_spectrum_p < kHalvesAlpha / 2;
}

}  // namespace

ModelMisfit judgeMisfit(std::span<const double> residual, const AllanBand& band, const AllanNull& base_null,
                        double rate_hz, const AxisModelCheck& spectra) {
  ModelMisfit m;
  const std::vector<double>& null_q = base_null.whiteness_q;
  const std::size_t half = residual.size() / 2;
  const HeldOutWhiteness w = heldOutWhiteness(residual.first(half), residual.subspan(half));
  m.ljung_box_p_held_out = w.errors.empty() ? 1.0 : whiteNullP(w.test.q, null_q);
  m.whiteness_q = w.test.q;
  if (!null_q.empty()) {
    std::vector<double> sorted = null_q;
    std::sort(sorted.begin(), sorted.end());
    m.whiteness_q_replica_median = sortedQuantile(sorted, 0.5);
  }
  m.whiteness_ar_order = w.ar_order;
  m.whiteness_fails = !(m.ljung_box_p_held_out >= kMisfitWhitenessP);
  // The whole curve is judged against the simultaneous band; with too few replicas to draw
  // one (tests with a handful), against the per-τ band.
  const bool joint = !band.joint_lo.empty();
  const std::vector<double>& lo = joint ? band.joint_lo : band.lo;
  const std::vector<double>& hi = joint ? band.joint_hi : band.hi;
  const std::vector<double>& replica_shares = joint ? band.replica_in_joint_band : band.replica_in_band;
  const std::size_t taus = band.tau_s.size();
  std::size_t inside = 0;
  for (std::size_t j = 0; j < taus; ++j) inside += (band.measured[j] >= lo[j] && band.measured[j] <= hi[j]) ? 1 : 0;
  const double in_band = taus > 0 ? static_cast<double>(inside) / static_cast<double>(taus) : 1.0;
  m.in_band = in_band;
  m.joint_band = joint;
  if (!replica_shares.empty() && taus > 0) {
    std::vector<double> shares = replica_shares, misses;
    std::sort(shares.begin(), shares.end());
    m.in_band_replica_median = sortedQuantile(shares, 0.5);
    m.in_band_replica_lowest = shares.front();
    for (double v : replica_shares) misses.push_back(std::round((1.0 - v) * static_cast<double>(taus)));
    const auto missed = static_cast<std::size_t>(std::lround((1.0 - in_band) * static_cast<double>(taus)));
    m.band_p = betaBinomialUpperTail(missed, taus, misses);
    m.band_fails = in_band < m.in_band_replica_lowest && m.band_p < kMisfitBandAlpha;
  }
  m.marginal = !m.whiteness_fails && !m.band_fails &&
               (m.ljung_box_p_held_out < kMarginalWhitenessP || in_band < kMarginalInBand);
  // The τ range is stated when the band test fails, or when the curve is in band less often
  // than every replica or than kMarginalInBand (a caller may add a failing test: the
  // acquisition chain).
  if (m.band_fails || in_band < m.in_band_replica_lowest || in_band < kMarginalInBand) {
    double farthest = -1.0;
    for (std::size_t j = 0; j < taus; ++j) {
      if (band.measured[j] >= lo[j] && band.measured[j] <= hi[j]) continue;
      if (!(m.tau_lo_s <= band.tau_s[j])) m.tau_lo_s = band.tau_s[j];
      m.tau_hi_s = band.tau_s[j];
      const double ratio = band.measured[j] / band.median[j];
      if (std::fabs(std::log(ratio)) > farthest) {
        farthest = std::fabs(std::log(ratio));
        m.adev_ratio = ratio;
      }
    }
  }
  if (!m.fails() && !m.marginal) return m;
  judgeHalves(residual, base_null, rate_hz, m);
  const SpectralExcess excess = innovationSpectralExcess(w.errors, rate_hz);
  if (excess.found) {
    m.freq_lo_hz = excess.freq_lo_hz;
    m.freq_hi_hz = excess.freq_hi_hz;
    m.power_ratio = excess.power_ratio;
    return m;
  }
  placeInSpectrum(spectra, m);
  return m;
}

}  // namespace gyrod::processing::model_check_detail
