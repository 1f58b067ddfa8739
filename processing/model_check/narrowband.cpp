// The model check's narrowband lines: spectral peaks wider than a periodogram bin, whose
// frequency wanders (simulation/narrowband_line.hpp), told apart from fixed sinusoids, fitted
// by the Whittle likelihood and taken out of the working series by a Wiener-type shrink.
#include <algorithm>
#include <array>
#include <boost/math/special_functions/gamma.hpp>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <numbers>
#include <unsupported/Eigen/FFT>

#include "processing/model_check/pipeline.hpp"

namespace gyrod::processing::model_check_detail {
namespace {

// Variance of a sum of w bins of a Hann periodogram of white noise, per bin and in units of
// one bin's: 1 + 2·(4/9) + 2·(1/36). Adjacent bins of a Hann-tapered DFT correlate with
// coefficient −2/3, bins two apart with 1/6 (the Fourier coefficients of w² over Σw²).
constexpr double kHannSumVarianceFactor = 1.0 + 8.0 / 9.0 + 1.0 / 18.0;
// The scan's widest band [Hz]: the lines seen on real MPU6050 records are 0.1–2 Hz wide.
constexpr double kWidestScanHz = 1.0;
// Widths below this many bins are not resolved: a fixed sinusoid through the Hann window has
// a half-power full width of 1.44 bins, and an estimated width scatters around it.
constexpr double kResolvedBins = 4.0;
// Wider than this it is broadband colour, not a line: the widest lines seen on real MPU6050
// records (a mount's resonance near 11.6 Hz) are 1.7 Hz wide.
constexpr double kWidestLineHz = 2.0;
// Nor is a peak wider than this share of its centre frequency (a resonance of quality factor
// below 2, hardly a peak at all): at low frequency such a bump is the slow noise's colour
// (flicker, random walk) that a block median follows poorly. The real lines are narrower than
// a sixth of their centre (the mount resonance: 1.8 Hz at 11.9 Hz).
constexpr double kWidestLineShareOfCentre = 0.5;

// −ln Q(a, x), Q the regularised upper incomplete gamma function, without underflow.
double minusLogGammaQ(double a, double x) {
  const double q = boost::math::gamma_q(a, x);
  if (q > 1e-300) return -std::log(q);
  return x - (a - 1.0) * std::log(x) + std::lgamma(a);  // the leading term of its asymptote
}

}  // namespace

std::vector<std::size_t> lineScanScales(std::size_t bins, double df) {
  std::vector<std::size_t> scales;
  for (std::size_t w = 4; static_cast<double>(w) * df <= kWidestScanHz && 16 * w <= bins; w *= 2) scales.push_back(w);
  return scales;
}

std::size_t lineBackgroundBlock(double df) {
  // Four times the widest scan, so that a line covers at most a quarter of its block's median.
  return std::max<std::size_t>(256, static_cast<std::size_t>(std::ceil(4.0 * kWidestScanHz / df)));
}

std::vector<double> blockMedianBackground(const std::vector<double>& power, std::size_t block) {
  return blockMedianLevels(
      power, [block](std::size_t) { return block; }, block / 2);
}

LineScan scanForLines(const std::vector<double>& power, const std::vector<double>& background, std::size_t k_lo,
                      std::size_t k_hi, const std::vector<std::size_t>& scales) {
  LineScan best;
  k_hi = std::min(k_hi, power.size() - 1);
  if (k_hi <= k_lo) return best;
  const std::size_t m = k_hi - k_lo + 1;
  std::vector<double> prefix(m + 1, 0.0);
  for (std::size_t i = 0; i < m; ++i) prefix[i + 1] = prefix[i] + power[k_lo + i] / background[k_lo + i];
  best.statistic = 0.0;
  for (std::size_t w : scales) {
    if (w > m) break;
    double top = -1.0;
    std::size_t at = 0;
    for (std::size_t i = 0; i + w <= m; ++i) {
      const double s = prefix[i + w] - prefix[i];
      if (s > top) {
        top = s;
        at = i;
      }
    }
    // The mean of w bins of unit mean: approximately Gamma(w/κ, κ/w), κ the Hann factor.
    const double shape = static_cast<double>(w) / kHannSumVarianceFactor;
    const double stat = minusLogGammaQ(shape, shape * top / static_cast<double>(w));
    if (stat > best.statistic) {
      best.statistic = stat;
      best.centre_bin = k_lo + at + w / 2;
      best.width_bins = w;
    }
  }
  return best;
}

std::vector<LineScanSegment> lineScanHalves(std::size_t n, double rate) {
  std::vector<LineScanSegment> halves;
  const std::size_t length = n / 2;
  const auto [nfft, k_lo, k_hi] = searchedBins(length);  // the whole record's limits, on the half's bins
  const double df = rate / static_cast<double>(nfft);
  if (k_hi <= k_lo) return halves;
  const std::vector<std::size_t> scales = lineScanScales(k_hi - k_lo, df);
  if (scales.empty()) return halves;
  for (std::size_t h = 0; h < 2; ++h)
    halves.push_back({h * length, length, k_lo, k_hi, scales, lineBackgroundBlock(df)});
  return halves;
}

HalfLineScan scanHalvesForLines(std::span<const double> x, const Context& c) {
  HalfLineScan best;
  for (std::size_t h = 0; h < c.line_halves.size(); ++h) {
    const LineScanSegment& seg = c.line_halves[h];
    const Periodogram p = hannPeriodogram(x.subspan(seg.offset, seg.length));
    const LineScan scan =
        scanForLines(p.power, blockMedianBackground(p.power, seg.background_block), seg.k_lo, seg.k_hi, seg.scales);
    if (scan.statistic <= best.statistic) continue;
    const double df = c.rate / static_cast<double>(p.nfft);
    best.statistic = scan.statistic;
    best.centre_hz = static_cast<double>(scan.centre_bin) * df;
    best.width_hz = static_cast<double>(scan.width_bins) * df;
    best.half = h;
  }
  return best;
}

namespace {

// The periodogram near a line, grouped into at most kMaxGroups bands of equal width for the
// fit (the Whittle likelihood of a mean of m bins is m times that of one bin at its mean).
constexpr std::size_t kMaxGroups = 1500;

struct LineWindow {
  std::vector<double> freq, mean_psd, background, weight;  // per group
  std::vector<double> c1, s1, c2, s2;                      // cos ω, sin ω, cos 2ω, sin 2ω
  std::vector<double> log_offset;                          // ln(f / centre guess), the background's abscissa
  double centre_guess = 0.0, half_width = 0.0;
  double background_level = 0.0;  // geometric mean of the background over the window
};

LineWindow lineWindow(const std::vector<double>& psd, const std::vector<double>& background, double df, double rate,
                      std::size_t centre_bin, std::size_t width_bins, std::size_t k_lo, std::size_t k_hi,
                      bool economical) {
  // Wide enough that the line's Lorentzian tails fall below the background within it: else
  // tails and background trade off in the fit.
  // At low frequency no further than half the centre: below it flicker and random walk make
  // the background steeper than the fit's curved power law follows.
  const double centre_hz = static_cast<double>(centre_bin) * df;
  const double half_hz =
      std::min(std::clamp(12.0 * static_cast<double>(width_bins) * df, std::max(3.0, 64.0 * df), 5.0),
               std::max(0.5 * centre_hz, 8.0 * static_cast<double>(width_bins) * df));
  const auto half = static_cast<std::size_t>(std::ceil(half_hz / df));
  const std::size_t lo = centre_bin > k_lo + half ? centre_bin - half : k_lo;
  const std::size_t hi = std::min(k_hi, centre_bin + half);
  // A refit near a known line needs only groups a quarter of its width (at least 200).
  const std::size_t bins = hi - lo + 1;
  const std::size_t max_groups =
      economical ? std::clamp<std::size_t>(4 * bins / std::max<std::size_t>(1, width_bins), 200, kMaxGroups)
                 : kMaxGroups;
  const std::size_t group = (bins + max_groups - 1) / max_groups;
  LineWindow w;
  w.centre_guess = static_cast<double>(centre_bin) * df;
  w.half_width = static_cast<double>(half) * df;
  for (std::size_t k = lo; k + group <= hi + 1; k += group) {
    double p = 0.0, b = 0.0;
    for (std::size_t j = k; j < k + group; ++j) {
      p += psd[j];
      b += background[j];
    }
    const double f = (static_cast<double>(k) + 0.5 * static_cast<double>(group - 1)) * df;
    const double om = 2.0 * std::numbers::pi * f / rate;
    w.freq.push_back(f);
    w.mean_psd.push_back(p / static_cast<double>(group));
    w.background.push_back(b / static_cast<double>(group));
    w.weight.push_back(static_cast<double>(group));
    w.log_offset.push_back(std::log(f / w.centre_guess));
    w.c1.push_back(std::cos(om));
    w.s1.push_back(std::sin(om));
    w.c2.push_back(std::cos(2.0 * om));
    w.s2.push_back(std::sin(2.0 * om));
  }
  double log_sum = 0.0;
  for (double b : w.background) log_sum += std::log(b);
  w.background_level = std::exp(log_sum / static_cast<double>(std::max<std::size_t>(1, w.background.size())));
  return w;
}

// Parameters of the fit: centre [Hz], ln width [Hz], ln rms [°/s], and the background's ln
// level (relative to the block medians' mean level), slope and curvature in ln f across the
// window: a power law bent by flicker and random walk at low frequency or a DLPF near
// Nyquist. Not the block medians' own shape: a block holding the line has its median raised
// by the line's tails, and that bump would be taken for background.
using LineParameters = std::array<double, 6>;

double lineNegLogLikelihood(const LineWindow& w, const LineParameters& p, double rate, double df) {
  const double centre = p[0], width = std::exp(p[1]), rms = std::exp(p[2]);
  if (!(centre > w.freq.front() && centre < w.freq.back() && width > 0.2 * df && width < 2.0 * w.half_width))
    return std::numeric_limits<double>::infinity();
  // The background within a factor 10 of the block medians' level: a line strong enough that
  // its tails fill the window would otherwise explain it all, the background would go to 0,
  // and the shrink would take the whole band out with the line.
  if (!(std::fabs(p[3]) <= std::log(10.0) && std::fabs(p[4]) <= 10.0 && std::fabs(p[5]) <= 20.0))
    return std::numeric_limits<double>::infinity();
  NarrowbandLineRecursion r;
  try {
    r = narrowbandLineRecursion({centre, width, rms}, rate);
  } catch (const std::invalid_argument&) {
    return std::numeric_limits<double>::infinity();
  }
  double nll = 0.0;
  for (std::size_t g = 0; g < w.freq.size(); ++g) {
    const double re = 1.0 - r.a1 * w.c1[g] - r.a2 * w.c2[g];
    const double im = r.a1 * w.s1[g] + r.a2 * w.s2[g];
    const double line = 2.0 * r.drive_var / rate / (re * re + im * im);
    const double u = w.log_offset[g];
    const double s = w.background_level * std::exp(p[3] + u * (p[4] + u * p[5])) + line;
    nll += w.weight[g] * (std::log(s) + w.mean_psd[g] / s);
  }
  return nll;
}

// Nelder–Mead on the six parameters (standard coefficients 1, 2, ½, ½).
LineParameters nelderMead(const std::function<double(const LineParameters&)>& f, LineParameters start,
                          const LineParameters& step, int iterations) {
  constexpr std::size_t d = std::tuple_size_v<LineParameters>;
  std::array<LineParameters, d + 1> x;
  std::array<double, d + 1> fx{};
  x[0] = start;
  for (std::size_t i = 0; i < d; ++i) {
    x[i + 1] = start;
    x[i + 1][i] += step[i];
  }
  for (std::size_t i = 0; i <= d; ++i) fx[i] = f(x[i]);
  for (int it = 0; it < iterations; ++it) {
    std::array<std::size_t, d + 1> order{};
    for (std::size_t i = 0; i <= d; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return fx[a] < fx[b]; });
    const std::size_t best = order[0], worst = order[d], second = order[d - 1];
    if (std::fabs(fx[worst] - fx[best]) < 1e-9 * (1.0 + std::fabs(fx[best]))) break;
    LineParameters centroid{};
    for (std::size_t i = 0; i <= d; ++i)
      if (i != worst)
        for (std::size_t j = 0; j < d; ++j) centroid[j] += x[i][j] / static_cast<double>(d);
    auto toward = [&](double t) {
      LineParameters y;
      for (std::size_t j = 0; j < d; ++j) y[j] = centroid[j] + t * (x[worst][j] - centroid[j]);
      return y;
    };
    const LineParameters xr = toward(-1.0);
    const double fr = f(xr);
    if (fr < fx[best]) {
      const LineParameters xe = toward(-2.0);
      const double fe = f(xe);
      x[worst] = fe < fr ? xe : xr;
      fx[worst] = std::min(fe, fr);
    } else if (fr < fx[second]) {
      x[worst] = xr;
      fx[worst] = fr;
    } else {
      const LineParameters xc = toward(fr < fx[worst] ? -0.5 : 0.5);
      const double fc = f(xc);
      if (fc < std::min(fr, fx[worst])) {
        x[worst] = xc;
        fx[worst] = fc;
      } else {
        for (std::size_t i = 0; i <= d; ++i) {
          if (i == best) continue;
          for (std::size_t j = 0; j < d; ++j) x[i][j] = x[best][j] + 0.5 * (x[i][j] - x[best][j]);
          fx[i] = f(x[i]);
        }
      }
    }
  }
  std::size_t best = 0;
  for (std::size_t i = 1; i <= d; ++i)
    if (fx[i] < fx[best]) best = i;
  return x[best];
}

}  // namespace

NarrowbandFit fitNarrowbandLine(const std::vector<double>& psd, const std::vector<double>& background, double df,
                                double rate, std::size_t centre_bin, std::size_t width_bins, std::size_t k_lo,
                                std::size_t k_hi, LineFitEffort effort) {
  const bool economical = effort == LineFitEffort::Refit;
  const int iterations = economical ? 150 : 400;
  const LineWindow w = lineWindow(psd, background, df, rate, centre_bin, width_bins, k_lo, k_hi, economical);
  NarrowbandFit out;
  if (w.freq.size() < 8) return out;
  // Start: the scan's centre and width, and the power above the background in the window.
  double excess = 0.0;
  for (std::size_t g = 0; g < w.freq.size(); ++g)
    excess += std::max(0.0, w.mean_psd[g] - w.background_level) * w.weight[g] * df;
  const double width0 = std::max(static_cast<double>(width_bins) * df / 2.0, 1.5 * df);
  const LineParameters start{w.centre_guess, std::log(width0), 0.5 * std::log(std::max(excess, 1e-30)), 0.0, 0.0, 0.0};
  const LineParameters step{0.5 * width0, 0.7, 0.5, 0.1, 0.5, 2.0};
  const auto nll = [&](const LineParameters& p) { return lineNegLogLikelihood(w, p, rate, df); };
  // Two restarts from the optimum: Nelder–Mead can stall on a ridge of centre against width.
  LineParameters p = nelderMead(nll, start, step, iterations);
  if (!economical) p = nelderMead(nll, p, step, iterations);
  if (!std::isfinite(nll(p))) return out;
  out.fitted = true;
  out.centre_hz = p[0];
  out.width_hz = std::exp(p[1]);
  out.rms_dps = std::exp(p[2]);
  const double u = std::log(out.centre_hz / w.centre_guess);
  out.background_psd = w.background_level * std::exp(p[3] + u * (p[4] + u * p[5]));
  out.resolved = out.width_hz > kResolvedBins * df;
  out.broadband = out.width_hz > kWidestLineHz || out.width_hz > kWidestLineShareOfCentre * out.centre_hz;
  return out;
}

std::vector<double> onesidedPsd(const Periodogram& p, std::vector<double> level, double rate) {
  const double scale = 2.0 / (rate * p.window_power);
  for (double& v : level) v *= scale;
  return level;
}

std::vector<double> onesidedPsd(const Periodogram& p, double rate) { return onesidedPsd(p, p.power, rate); }

void shrinkNarrowbandLine(std::vector<double>& x, const NarrowbandLine& line, double background_psd, double rate) {
  const NarrowbandLineRecursion r = narrowbandLineRecursion(line, rate);
  const std::size_t n = x.size();
  // Zero padding past the filter's memory (its impulse response decays as e^{−π·width·t}),
  // so that the end of the record does not wrap onto its start.
  const auto memory = static_cast<std::size_t>(std::ceil(3.0 * rate / line.width_hz));
  const std::size_t nfft = fftLength(n + std::min(n, memory));
  std::vector<double> in(nfft, 0.0);
  std::copy(x.begin(), x.end(), in.begin());
  std::vector<std::complex<double>> spectrum;
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  fft.fwd(spectrum, in);
  const double df = rate / static_cast<double>(nfft);
  for (std::size_t k = 0; k < spectrum.size(); ++k) {
    const double l = narrowbandLinePsd(r, rate, static_cast<double>(k) * df);
    spectrum[k] *= std::sqrt(background_psd / (background_psd + l));
  }
  std::vector<double> back;
  fft.inv(back, spectrum);
  std::copy(back.begin(), back.begin() + static_cast<std::ptrdiff_t>(n), x.begin());
}

}  // namespace gyrod::processing::model_check_detail
