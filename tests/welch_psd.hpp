#pragma once
// Welch's averaged periodogram for the tests that look for a narrowband line in a stream:
// Hann-windowed segments of a power-of-two length, overlapping by half, their periodograms
// averaged into a one-sided power spectral density [unit²/Hz] (so that Σ psd·Δf is the
// variance). A radix-2 FFT of its own keeps the tests independent of the model check's.
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstddef>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace gyrod::test {

struct WelchSpectrum {
  std::vector<double> psd;  // bins k = 0..segment/2, at k·bin_hz
  double bin_hz = 0.0;
  std::size_t segments = 0;  // periodograms averaged
};

inline void radix2FftInPlace(std::vector<std::complex<double>>& x) {
  const std::size_t n = x.size();
  for (std::size_t i = 1, j = 0; i < n; ++i) {
    std::size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(x[i], x[j]);
  }
  for (std::size_t len = 2; len <= n; len <<= 1) {
    const double angle = -2.0 * std::numbers::pi / static_cast<double>(len);
    for (std::size_t start = 0; start < n; start += len) {
      for (std::size_t k = 0; k < len / 2; ++k) {
        const std::complex<double> w = std::polar(1.0, angle * static_cast<double>(k));
        const std::complex<double> u = x[start + k], v = x[start + k + len / 2] * w;
        x[start + k] = u + v;
        x[start + k + len / 2] = u - v;
      }
    }
  }
}

// `segment` a power of two no longer than x; each segment's mean is removed.
inline WelchSpectrum welchPsd(const std::vector<double>& x, double rate_hz, std::size_t segment) {
  if (segment < 4 || (segment & (segment - 1)) != 0 || segment > x.size())
    throw std::invalid_argument("welchPsd: segment must be a power of two within the data");
  std::vector<double> window(segment);
  double window_power = 0.0;
  for (std::size_t i = 0; i < segment; ++i) {
    window[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(segment));
    window_power += window[i] * window[i];
  }
  WelchSpectrum out;
  out.psd.assign(segment / 2 + 1, 0.0);
  out.bin_hz = rate_hz / static_cast<double>(segment);
  std::vector<std::complex<double>> buffer(segment);
  for (std::size_t start = 0; start + segment <= x.size(); start += segment / 2) {
    double mean = 0.0;
    for (std::size_t i = 0; i < segment; ++i) mean += x[start + i];
    mean /= static_cast<double>(segment);
    for (std::size_t i = 0; i < segment; ++i) buffer[i] = (x[start + i] - mean) * window[i];
    radix2FftInPlace(buffer);
    for (std::size_t k = 0; k < out.psd.size(); ++k) {
      // One-sided: the negative frequencies folded onto the positive ones, except at 0 and rate/2.
      const double fold = (k == 0 || k == segment / 2) ? 1.0 : 2.0;
      out.psd[k] += fold * std::norm(buffer[k]) / (rate_hz * window_power);
    }
    ++out.segments;
  }
  for (double& p : out.psd) p /= static_cast<double>(out.segments);
  return out;
}

// The peak of a spectrum near `around_hz` (searched within ±search_hz) and its half-power
// points, each crossing interpolated linearly between bins. The peak is the largest three-bin
// mean, whose scatter is 1/√3 of a single bin's, at the cost of a percent or two of the
// level of a peak several bins wide.
struct SpectralPeak {
  double level = 0.0;
  double max_bin_hz = 0.0;  // the middle bin of the largest three-bin mean
  double lower_half_power_hz = 0.0, upper_half_power_hz = 0.0;
  double centreHz() const { return 0.5 * (lower_half_power_hz + upper_half_power_hz); }
  double widthHz() const { return upper_half_power_hz - lower_half_power_hz; }
};

inline SpectralPeak spectralPeakNear(const WelchSpectrum& s, double around_hz, double search_hz) {
  const auto bin = [&](double f) {
    return static_cast<std::size_t>(std::clamp(std::round(f / s.bin_hz), 1.0, static_cast<double>(s.psd.size() - 2)));
  };
  const std::size_t lo = bin(around_hz - search_hz), hi = bin(around_hz + search_hz);
  std::size_t top = lo;
  double best = -1.0;
  for (std::size_t k = lo; k <= hi; ++k) {
    const double three = (s.psd[k - 1] + s.psd[k] + s.psd[k + 1]) / 3.0;
    if (three > best) {
      best = three;
      top = k;
    }
  }
  SpectralPeak p;
  p.level = best;
  p.max_bin_hz = static_cast<double>(top) * s.bin_hz;
  const double half = 0.5 * best;
  std::size_t k = top;
  while (k > 0 && s.psd[k - 1] >= half) --k;
  p.lower_half_power_hz =
      k == 0 ? 0.0 : s.bin_hz * (static_cast<double>(k - 1) + (half - s.psd[k - 1]) / (s.psd[k] - s.psd[k - 1]));
  k = top;
  while (k + 1 < s.psd.size() && s.psd[k + 1] >= half) ++k;
  p.upper_half_power_hz = k + 1 == s.psd.size()
                              ? s.bin_hz * static_cast<double>(k)
                              : s.bin_hz * (static_cast<double>(k) + (s.psd[k] - half) / (s.psd[k] - s.psd[k + 1]));
  return p;
}

}  // namespace gyrod::test
