// The acquisition chain in the model check's base model: the chip's DLPF at its internal rate,
// the decimation to the output rate (SMPLRT_DIV) and the quantisation to the FS_SEL LSB.
//
// The five terms are fitted in the output's units (what the recording shows at long τ), and
// the chain changes only the white rate noise at short τ: the DLPF removes its power there,
// the decimation folds the aliases back. So the white term's Allan variance is c_w·s(m)/τ
// with a shape s(m) → 1 at long τ (s from the filter's impulse response, exactly), and the
// replicas draw that noise at the output rate as a moving average whose autocovariance is the
// chain's (docs/model-check.md, "The acquisition chain"). Simulating the chain at the internal
// rate instead (the simulator's own DLPF) would cost 20–160 × more per replica.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "processing/base/detrend.hpp"
#include "processing/model_check/pipeline.hpp"
#include "processing/simulation/sensor_model.hpp"

namespace gyrod::processing::model_check_detail {
namespace {

constexpr std::size_t kMaxImpulseLength = 200000;
constexpr std::size_t kMaxInnovationSteps = 3000;

// Impulse response of the DLPF at its internal rate (unit DC gain), until it has decayed.
std::vector<double> dlpfImpulseResponse(int cfg) {
  DigitalLowPassFilter f(cfg);
  f.reset(0.0);
  std::vector<double> h;
  double peak = 0.0;
  for (std::size_t i = 0; i < kMaxImpulseLength; ++i) {
    const double y = f.update(i == 0 ? 1.0 : 0.0);
    h.push_back(y);
    peak = std::max(peak, std::fabs(y));
    if (i > 8 && std::fabs(y) < 1e-12 * peak) break;
  }
  return h;
}

// Autocovariance of the decimated filtered unit white noise, at output lags 0..q.
std::vector<double> decimatedAutocovariance(const std::vector<double>& h, std::size_t decimation) {
  std::vector<double> gamma;
  for (std::size_t lag = 0; lag * decimation < h.size(); ++lag) {
    double s = 0.0;
    for (std::size_t j = 0; j + lag * decimation < h.size(); ++j) s += h[j] * h[j + lag * decimation];
    gamma.push_back(s);
  }
  while (gamma.size() > 1 && std::fabs(gamma.back()) < 1e-14 * gamma[0]) gamma.pop_back();
  return gamma;
}

// Allan variance × τ of a stationary process of autocovariance γ at cluster size m:
// σ²(m) = (1/(2m²))·Σ_ℓ a_m(ℓ)·γ(|ℓ|), a_m the autocorrelation of (−1 ×m, +1 ×m).
double allanTimesTau(const std::vector<double>& gamma, std::size_t m, double tau0) {
  const auto mm = static_cast<double>(m);
  double s = 2.0 * mm * gamma[0];
  for (std::size_t l = 1; l < gamma.size() && l < 2 * m; ++l) {
    const auto ll = static_cast<double>(l);
    const double a = l <= m ? 2.0 * mm - 3.0 * ll : -(2.0 * mm - ll);
    s += 2.0 * a * gamma[l];
  }
  return s / (2.0 * mm * mm) * mm * tau0;
}

// Moving-average coefficients g (y_k = Σ g_j e_{k−j}, e ~ N(0, 1)) of autocovariance γ, by the
// innovations algorithm run until its rows settle (the stationary, invertible factor).
std::vector<double> movingAverageFactor(const std::vector<double>& gamma) {
  const std::size_t q = gamma.size() - 1;
  if (q == 0) return {std::sqrt(gamma[0])};
  const std::size_t steps = std::clamp<std::size_t>(50000000 / ((q + 1) * (q + 1)), 50, kMaxInnovationSteps);
  std::vector<std::vector<double>> theta(steps + 1, std::vector<double>(q + 1, 0.0));  // theta[n][lag]
  std::vector<double> v(steps + 1, 0.0);
  v[0] = gamma[0];
  std::size_t last = 0;
  for (std::size_t n = 1; n <= steps; ++n) {
    const std::size_t k0 = n > q ? n - q : 0;
    for (std::size_t k = k0; k < n; ++k) {
      double acc = gamma[n - k];
      for (std::size_t j = k0; j < k; ++j)
        if (k - j <= q) acc -= theta[k][k - j] * theta[n][n - j] * v[j];
      theta[n][n - k] = acc / v[k];
    }
    double vn = gamma[0];
    for (std::size_t j = k0; j < n; ++j) vn -= theta[n][n - j] * theta[n][n - j] * v[j];
    v[n] = std::max(vn, 1e-300);
    last = n;
    if (n > 2 * q) {
      double change = 0.0;
      for (std::size_t i = 1; i <= q; ++i) change = std::max(change, std::fabs(theta[n][i] - theta[n - 1][i]));
      if (change < 1e-10) break;
    }
  }
  std::vector<double> g(q + 1);
  const double sd = std::sqrt(v[last]);
  g[0] = sd;
  for (std::size_t i = 1; i <= q; ++i) g[i] = theta[last][i] * sd;
  return g;
}

// |G(f)|² of the chain for flicker (1/f) rate noise at output frequencies `freqs` (0 < f <
// rate/2): the output spectrum over the input's, Σ_k |H(f + k·rate)|²·f/|f + k·rate| over the
// aliases the decimation folds back from the internal band. 1 at f → 0.
std::vector<double> flickerGain(int cfg, double rate_hz, std::span<const double> freqs) {
  const DigitalLowPassFilter f(cfg);
  const double nyquist_in = f.setting().internal_rate_hz / 2.0;
  const auto d = static_cast<long>(sampleRateDivisor(cfg, rate_hz));
  std::vector<double> gain(freqs.size(), 0.0);
  for (std::size_t i = 0; i < freqs.size(); ++i) {
    for (long k = -d; k <= d; ++k) {
      const double fk = std::fabs(freqs[i] + static_cast<double>(k) * rate_hz);
      if (fk > nyquist_in || fk == 0.0) continue;
      gain[i] += std::norm(f.frequencyResponse(fk)) * freqs[i] / fk;
    }
  }
  return gain;
}

constexpr std::size_t kFlickerGrid = 8192;       // midpoints on (0, rate/2)
constexpr std::size_t kFlickerMaxLag = 64;       // of the output-rate filter's autocovariance
constexpr std::size_t kFlickerMaxCluster = 256;  // the shape is 1 beyond (or once it is within 1e-6)

// The flicker (bias instability) term through the chain: its Allan shape s_B(m), the ratio of
// the filtered flicker's Allan variance to the unfiltered one's at the output rate (the
// replicas' flicker), and an output-rate moving average g whose |G|² is the chain's gain, by
// which the replicas' flicker is filtered. Both from the same |G|², by midpoint sums.
void addFlickerChain(int cfg, double rate_hz, std::span<const std::size_t> ms, ChainModel& m) {
  std::vector<double> freqs(kFlickerGrid);
  const double df = rate_hz / 2.0 / static_cast<double>(kFlickerGrid);
  for (std::size_t i = 0; i < kFlickerGrid; ++i) freqs[i] = (static_cast<double>(i) + 0.5) * df;
  const std::vector<double> gain = flickerGain(cfg, rate_hz, freqs);
  m.flicker_shape.assign(ms.size(), 1.0);
  for (std::size_t j = 0; j < ms.size() && ms[j] <= kFlickerMaxCluster; ++j) {
    // Discrete Allan kernel 2·sin⁴(πfmτ0)/(m·sin(πfτ0))² against S(f) = 1/f.
    double filtered = 0.0, plain = 0.0;
    const auto mm = static_cast<double>(ms[j]);
    for (std::size_t i = 0; i < kFlickerGrid; ++i) {
      const double x = std::numbers::pi * freqs[i] / rate_hz;
      const double sm = std::sin(mm * x), s1 = std::sin(x);
      const double kernel = 2.0 * sm * sm * sm * sm / (mm * mm * s1 * s1) / freqs[i];
      plain += kernel;
      filtered += kernel * gain[i];
    }
    m.flicker_shape[j] = filtered / plain;
    if (std::fabs(m.flicker_shape[j] - 1.0) < 1e-6) break;
  }
  // γ(ℓ) = (2/rate)·∫ |G|² cos(2πfℓ/rate) df, tapered where it has decayed.
  std::vector<double> gamma;
  for (std::size_t lag = 0; lag <= kFlickerMaxLag; ++lag) {
    double acc = 0.0;
    for (std::size_t i = 0; i < kFlickerGrid; ++i)
      acc += gain[i] * std::cos(2.0 * std::numbers::pi * freqs[i] * static_cast<double>(lag) / rate_hz);
    gamma.push_back(acc * df * 2.0 / rate_hz);
    if (lag > 0 && std::fabs(gamma.back()) < 1e-7 * gamma[0]) break;
  }
  m.flicker_ma = movingAverageFactor(gamma);
}

}  // namespace

ChainModel makeChainModel(const AcquisitionChain& chain, double rate_hz, std::span<const std::size_t> ms) {
  ChainModel m;
  m.dlpf_cfg = chain.dlpf_cfg;
  m.fs_sel = chain.fs_sel;
  const double tau0 = 1.0 / rate_hz;
  m.white_shape.assign(ms.size(), 1.0);
  m.flicker_shape.assign(ms.size(), 1.0);
  if (chain.fs_sel) {
    m.lsb_dps = 1.0 / gyroSensitivityLsbPerDps(*chain.fs_sel);
    m.quantisation_white = m.lsb_dps * m.lsb_dps * tau0 / 12.0;
  }
  if (!chain.dlpf_cfg) return m;
  const std::size_t decimation = sampleRateDivisor(*chain.dlpf_cfg, rate_hz);
  std::vector<double> gamma = decimatedAutocovariance(dlpfImpulseResponse(*chain.dlpf_cfg), decimation);
  // Normalised to a unit long-τ white coefficient: S(0) = τ0·Σ_ℓ γ(ℓ) = 1.
  double sum = gamma[0];
  for (std::size_t l = 1; l < gamma.size(); ++l) sum += 2.0 * gamma[l];
  for (double& g : gamma) g /= sum * tau0;
  for (std::size_t j = 0; j < ms.size(); ++j) m.white_shape[j] = allanTimesTau(gamma, ms[j], tau0);
  m.white_ma = movingAverageFactor(gamma);
  addFlickerChain(*chain.dlpf_cfg, rate_hz, ms, m);
  return m;
}

double whiteCoefficientOf(const NoiseTerms& terms) {
  return allanVarianceCoefficient(NoiseTerm::AngleRandomWalk, terms.get(NoiseTerm::AngleRandomWalk));
}

std::vector<double> chainCorrectedVariances(std::span<const double> variance, const Context& c,
                                            const NoiseTerms& terms) {
  std::vector<double> v(variance.begin(), variance.end());
  const double filtered = std::max(0.0, whiteCoefficientOf(terms) - c.chain.quantisation_white);
  const double flicker = allanVarianceCoefficient(NoiseTerm::BiasInstability, terms.get(NoiseTerm::BiasInstability));
  for (std::size_t j = 0; j < v.size(); ++j)
    v[j] += filtered * (1.0 - c.chain.white_shape[j]) / c.taus[j] + flicker * (1.0 - c.chain.flicker_shape[j]);
  return v;
}

NoiseTermFit fitChainTerms(const std::vector<AllanPoint>& curve, const Context& c) {
  if (!c.chain.dlpf_cfg) return fitNoiseTerms(curve);
  // Through a DLPF the white and flicker terms reach the output with their chain shapes (the
  // model stays linear in the coefficients); the quantisation's white noise is not filtered,
  // so what it adds beyond the filtered white term's share is a known variance.
  NoiseTermShapes shapes;
  shapes[static_cast<std::size_t>(NoiseTerm::AngleRandomWalk)] = c.chain.white_shape;
  shapes[static_cast<std::size_t>(NoiseTerm::BiasInstability)] = c.chain.flicker_shape;
  std::vector<double> known(curve.size(), 0.0);
  for (std::size_t j = 0; j < curve.size() && j < c.taus.size(); ++j)
    known[j] = c.chain.quantisation_white * (1.0 - c.chain.white_shape[j]) / c.taus[j];
  return fitShapedNoiseTerms(curve, &shapes, known);
}

double chainFitChi2(const std::vector<AllanPoint>& curve, const Context& c) {
  return fitChainTerms(curve, c).reduced_chi2;
}

void addChainWhiteNoise(std::vector<double>& x, const ChainModel& chain, double white_coefficient, std::uint64_t seed) {
  const double scale = std::sqrt(std::max(0.0, white_coefficient - chain.quantisation_white));
  if (chain.white_ma.empty() || scale == 0.0) return;
  const std::vector<double>& g = chain.white_ma;
  NormalGenerator normal(seed ^ 0x2545F4914F6CDD1DULL);
  std::vector<double> history(g.size());  // e_{k}, e_{k−1}, … in a ring
  for (double& e : history) e = normal.next();
  std::size_t head = 0;
  for (double& xi : x) {
    head = head == 0 ? history.size() - 1 : head - 1;
    history[head] = normal.next();
    double y = 0.0;
    for (std::size_t j = 0, p = head; j < g.size(); ++j, p = p + 1 == history.size() ? 0 : p + 1)
      y += g[j] * history[p];
    xi += scale * y;
  }
}

std::vector<double> filterChainFlicker(std::span<const double> x, const ChainModel& chain, std::size_t n) {
  const std::vector<double>& g = chain.flicker_ma;
  const std::size_t lead = g.size() - 1;
  std::vector<double> y(n, 0.0);
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t j = 0; j < g.size(); ++j) y[k] += g[j] * x[k + lead - j];
  return y;
}

void quantiseLikeTheChip(std::vector<double>& x, const ChainModel& chain, std::uint64_t seed) {
  if (!(chain.lsb_dps > 0.0)) return;
  // The recording's bias puts the rounding grid anywhere against the noise: a random offset.
  SplitMix64 mix(seed ^ 0x9E3779B97F4A7C15ULL);
  const double offset = static_cast<double>(mix.next() >> 11) * 0x1.0p-53 * chain.lsb_dps;
  for (double& v : x) v = std::round((v + offset) / chain.lsb_dps) * chain.lsb_dps;
}

}  // namespace gyrod::processing::model_check_detail

namespace gyrod::processing {

std::vector<double> chainWhiteNoiseShape(const AcquisitionChain& chain, double rate_hz,
                                         std::span<const std::size_t> ms) {
  return model_check_detail::makeChainModel(chain, rate_hz, ms).white_shape;
}

std::vector<DlpfCandidate> dlpfCandidates(double rate_hz) {
  std::vector<DlpfCandidate> out;
  out.push_back({});
  for (int cfg = 0; cfg <= 6; ++cfg) {
    try {
      sampleRateDivisor(cfg, rate_hz);
    } catch (const std::invalid_argument&) {
      continue;  // this rate cannot be made with that setting
    }
    out.push_back({cfg, 0.0});
  }
  return out;
}

void scoreDlpfCandidates(std::span<const double> rate_dps, double rate_hz, std::vector<DlpfCandidate>& candidates) {
  using namespace model_check_detail;
  AxisModelCheckInput in;
  in.rate_dps = rate_dps;
  in.rate_hz = rate_hz;
  std::vector<double> xd(rate_dps.begin(), rate_dps.end());
  removeLinearTrend(xd, 1.0 / rate_hz);
  std::vector<AllanPoint> curve;
  Context c = makeContext(in, xd, curve);
  std::vector<double> axis_chi2;
  double none = std::numeric_limits<double>::infinity();
  for (DlpfCandidate& cand : candidates) {
    c.chain = makeChainModel({cand.dlpf_cfg, std::nullopt}, rate_hz, c.ms);
    const double chi2 = chainFitChi2(curve, c);
    axis_chi2.push_back(std::isfinite(chi2) ? chi2 : std::numeric_limits<double>::infinity());
    cand.chi2 += axis_chi2.back();
    if (!cand.dlpf_cfg) none = axis_chi2.back();
  }
  for (std::size_t k = 0; k < candidates.size(); ++k)
    if (candidates[k].dlpf_cfg && axis_chi2[k] <= 0.8 * none) ++candidates[k].axes_preferring;
}

std::optional<int> chooseDlpf(const std::vector<DlpfCandidate>& scored, std::size_t axes_scored) {
  double none = std::numeric_limits<double>::infinity();
  const DlpfCandidate* best = nullptr;
  for (const DlpfCandidate& cand : scored) {
    if (!cand.dlpf_cfg)
      none = cand.chi2;
    else if (!best || cand.chi2 < best->chi2)
      best = &cand;
  }
  // The reduced χ² of a right model through a narrow DLPF stays well above 1 (the points'
  // weights assume white noise, whose short-τ estimates are more precise than filtered
  // noise's), so the rule is relative: the best must beat none clearly.
  const auto axes = static_cast<double>(std::max<std::size_t>(1, axes_scored));
  if (best && best->chi2 <= 0.8 * none && none - best->chi2 > 3.0 * axes &&
      2 * best->axes_preferring >= std::max<std::size_t>(1, axes_scored))
    return best->dlpf_cfg;
  return std::nullopt;
}

}  // namespace gyrod::processing
