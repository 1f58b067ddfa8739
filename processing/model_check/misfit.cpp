// The misfit of the model the check ends with: the two tests (held-out whiteness, Allan band)
// and where it misses (τ range of the Allan curve, frequency band of the innovations).
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <unsupported/Eigen/FFT>

#include "processing/base/distributions.hpp"
#include "processing/model_check/pipeline.hpp"

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

}  // namespace gyrod::processing

namespace gyrod::processing::model_check_detail {

ModelMisfit judgeMisfit(double ljung_box_p_held_out, const AllanBand& band, double in_band,
                        std::span<const double> held_out_innovations, double rate_hz) {
  ModelMisfit m;
  m.ljung_box_p_held_out = ljung_box_p_held_out;
  m.in_band = in_band;
  m.whiteness_fails = !(ljung_box_p_held_out >= kMisfitWhitenessP);
  m.band_fails = !(in_band >= kMisfitInBand);
  if (!m.fails()) return m;
  if (m.band_fails) {
    double farthest = -1.0;
    for (std::size_t j = 0; j < band.tau_s.size(); ++j) {
      if (band.measured[j] >= band.lo[j] && band.measured[j] <= band.hi[j]) continue;
      if (!(m.tau_lo_s <= band.tau_s[j])) m.tau_lo_s = band.tau_s[j];
      m.tau_hi_s = band.tau_s[j];
      const double ratio = band.measured[j] / band.median[j];
      if (std::fabs(std::log(ratio)) > farthest) {
        farthest = std::fabs(std::log(ratio));
        m.adev_ratio = ratio;
      }
    }
  }
  const SpectralExcess excess = innovationSpectralExcess(held_out_innovations, rate_hz);
  if (excess.found) {
    m.freq_lo_hz = excess.freq_lo_hz;
    m.freq_hi_hz = excess.freq_hi_hz;
    m.power_ratio = excess.power_ratio;
  }
  return m;
}

}  // namespace gyrod::processing::model_check_detail
