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
#include <stdexcept>

#include "processing/detrend.hpp"
#include "processing/model_check_pipeline.hpp"
#include "processing/sensor_model.hpp"

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

}  // namespace

ChainModel makeChainModel(const AcquisitionChain& chain, double rate_hz, std::span<const std::size_t> ms) {
  ChainModel m;
  m.dlpf_cfg = chain.dlpf_cfg;
  m.fs_sel = chain.fs_sel;
  const double tau0 = 1.0 / rate_hz;
  m.white_shape.assign(ms.size(), 1.0);
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
  return m;
}

double whiteCoefficientOf(const NoiseTerms& terms) {
  return allanVarianceCoefficient(NoiseTerm::AngleRandomWalk, terms.get(NoiseTerm::AngleRandomWalk));
}

std::vector<double> chainCorrectedVariances(std::span<const double> variance, const Context& c,
                                            double white_coefficient) {
  std::vector<double> v(variance.begin(), variance.end());
  const double filtered = std::max(0.0, white_coefficient - c.chain.quantisation_white);
  for (std::size_t j = 0; j < v.size(); ++j) v[j] += filtered * (1.0 - c.chain.white_shape[j]) / c.taus[j];
  return v;
}

NoiseTermFit fitChainTerms(const std::vector<AllanPoint>& curve, const Context& c) {
  NoiseTermFit fit = fitNoiseTerms(curve);
  if (!c.chain.dlpf_cfg) return fit;
  // The missing white power at short τ is added back with a white coefficient c; the fit of
  // the corrected curve gives a white coefficient g(c), and the answer is the fixed point
  // g(c) = c (the correction vanishes at long τ). g is nearly linear with a slope up to ~0.9
  // for the narrowest DLPF, so the fixed point is found by the secant method, not by
  // iterating g.
  std::vector<double> variance;
  variance.reserve(curve.size());
  for (const AllanPoint& p : curve) variance.push_back(p.oadev * p.oadev);
  auto refit = [&](double white) {
    const std::vector<double> corrected = chainCorrectedVariances(variance, c, white);
    std::vector<AllanPoint> adjusted = curve;
    for (std::size_t j = 0; j < adjusted.size(); ++j) adjusted[j].oadev = std::sqrt(corrected[j]);
    return fitNoiseTerms(adjusted);
  };
  double ca = whiteCoefficientOf(fit.value);
  fit = refit(ca);
  double ha = whiteCoefficientOf(fit.value) - ca;
  double cb = whiteCoefficientOf(fit.value);
  for (int pass = 0; pass < 12; ++pass) {
    fit = refit(cb);
    const double hb = whiteCoefficientOf(fit.value) - cb;
    if (std::fabs(hb) <= 1e-7 * std::max(cb, 1e-300) || hb == ha) break;
    const double next = std::max(0.0, cb - hb * (cb - ca) / (hb - ha));
    ca = cb;
    ha = hb;
    cb = next;
  }
  return fit;
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
  for (DlpfCandidate& cand : candidates) {
    c.chain = makeChainModel({cand.dlpf_cfg, std::nullopt}, rate_hz, c.ms);
    const double chi2 = chainFitChi2(curve, c);
    cand.chi2 += std::isfinite(chi2) ? chi2 : std::numeric_limits<double>::infinity();
  }
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
  if (best && best->chi2 <= 0.8 * none && none - best->chi2 > 3.0 * axes) return best->dlpf_cfg;
  return std::nullopt;
}

}  // namespace gyrod::processing
