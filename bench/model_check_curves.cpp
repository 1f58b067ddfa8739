// Detection curves of the model check: for each effect of the catalogue that has a size
// (bias step, sinusoid, temperature response, Gauss–Markov), the probability that the blind
// check (processing/model_check/model_check.hpp) names it, against the effect's size and the record's
// length, beside the detector that knows the effect's form (processing/model_check/known_form_detectors.hpp)
// on the same records at a 1 % false-alarm threshold calibrated on clean records.
// Not a unit test (minutes); scripts/model-check-curves.sh runs it and draws the PNGs of
// docs/model-check.md; ctest runs its --quick mode (scripts/check-model-check-curves.sh).
//
//   model_check_curves [--quick] [--trials N] [--first-trial J] [--durations S,S] [--effects a,b]
//                      [--replicas R] [--calibration M] [--scan-calibration K] [--clean C]
//                      [--data DIR] [--explain]
//
// Records: one axis at 50 Hz of fixed base noise (Q 2 µrad, N 0.5 °/√h, B 10 °/h,
// K 3 °/h^1.5, quantised at 131 LSB per °/s) with a temperature channel (warm-up + room
// cycle + noise). Trial j of a duration has its own noise, step time, frequency, phase and
// Gauss–Markov realisation; only the size changes along a curve (common random numbers).
// Output: per curve, lines "size trials blind lo hi optimal lo hi" (Wilson 95 % intervals),
// then "bound lo hi", the blind bound: the check's own statistic with the noise known, at the
// check's rate (steps: its scan, calibrated on K clean records; temperature: the known-form
// statistic; sinusoid: its periodogram peak over the clean records' mean periodogram;
// Gauss–Markov: the known-spectrum score scanned over its correlation times, K clean
// records); then a "summary" line; false discoveries on clean records; --data DIR writes each
// curve as DIR/<effect>-<duration>.dat for gnuplot; --explain prints, per step or temperature
// trial and size, the check's statistic beside the bound's.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "processing/base/distributions.hpp"
#include "processing/base/noise_terms.hpp"
#include "processing/base/portable_random.hpp"
#include "processing/model_check/detail.hpp"
#include "processing/model_check/known_form_detectors.hpp"
#include "processing/model_check/model_check.hpp"
#include "processing/model_check/pipeline.hpp"
#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod;
using namespace gyrod::processing;

namespace {

constexpr double kRate = 50.0;
constexpr double kLsb = 131.0;
constexpr double kFalseAlarm = 0.01;

NoiseTerms baseTerms() {
  NoiseTerms t;
  t.quantization_urad = 2.0;
  t.arw_deg_per_sqrt_h = 0.5;
  t.bias_instability_deg_per_h = 10.0;
  t.rrw_deg_per_h_sqrt_h = 3.0;
  return t;
}
double whiteSd() { return baseTerms().arw_deg_per_sqrt_h / 60.0 * std::sqrt(kRate); }
double adevFloor() {  // smallest base Allan deviation over τ = 2..128 s, as the generator sizes steps
  double f = 1e300;
  for (double tau = 2.0; tau <= 128.0; tau *= 2.0) f = std::min(f, std::sqrt(allanVarianceOfTerms(baseTerms(), tau)));
  return f;
}

enum class Kind { Step, Sinusoid, Temperature, GaussMarkov };
struct Curve {
  Kind kind;
  std::string name;          // file and table name
  std::string size_what;     // what the size is
  double gm_fraction = 0.0;  // Gauss–Markov: T / duration
  std::vector<double> sizes;
};

// What a trial draws once, whatever the size.
struct TrialShape {
  std::vector<double> noise;  // base noise, unquantised
  std::vector<double> temp;   // measured temperature
  double step_time = 0.0, step_sign = 1.0, freq = 0.0, phase = 0.0;
  std::vector<double> gm_unit;  // unit-variance Gauss–Markov realisation (when needed)
};

struct Records {
  double duration = 0.0;
  std::size_t n = 0;
  std::vector<double> true_temp, t;
  double temp_range = 0.0;  // peak-to-peak of the detrended true temperature
};

Records makeRecords(double duration) {
  Records r;
  r.duration = duration;
  r.n = static_cast<std::size_t>(duration * kRate);
  r.true_temp.resize(r.n);
  r.t.resize(r.n);
  for (std::size_t i = 0; i < r.n; ++i) {
    const double t = static_cast<double>(i) / kRate;
    r.t[i] = t;
    r.true_temp[i] =
        23.0 + 6.0 * (1.0 - std::exp(-t / 500.0)) + 0.8 * std::sin(2.0 * std::numbers::pi * t / 2700.0 + 1.0);
  }
  std::vector<double> d = r.true_temp;
  model_check_detail::removeLineInPlace(d);
  r.temp_range = *std::max_element(d.begin(), d.end()) - *std::min_element(d.begin(), d.end());
  return r;
}

TrialShape drawTrial(const Records& rec, std::uint64_t seed, double gm_tau) {
  SplitMix64 seeder(seed);
  TrialShape s;
  SimulationModel model;
  model.rate_hz = kRate;
  model.axes[0].terms = baseTerms();
  NoiseSimulator sim(model, rec.duration, seeder.next());
  s.noise.resize(rec.n);
  for (double& v : s.noise) v = sim.next().rate_dps[0];
  NormalGenerator tn(seeder.next());
  s.temp.resize(rec.n);
  for (std::size_t i = 0; i < rec.n; ++i) s.temp[i] = std::round((rec.true_temp[i] + 0.02 * tn.next()) * 340.0) / 340.0;
  Xoshiro256StarStar u(seeder.next());
  s.step_time = (0.2 + 0.6 * u.uniform()) * rec.duration;
  s.step_sign = u.uniform() < 0.5 ? -1.0 : 1.0;
  s.freq = std::exp(std::log(0.2) + u.uniform() * std::log(0.4 * kRate / 0.2));
  s.phase = 2.0 * std::numbers::pi * u.uniform();
  if (gm_tau > 0.0) {
    NormalGenerator g(seeder.next());
    const double rho = std::exp(-1.0 / (kRate * gm_tau)), q = std::sqrt(1.0 - rho * rho);
    s.gm_unit.resize(rec.n);
    double x = g.next();
    for (double& v : s.gm_unit) {
      v = x;
      x = rho * x + q * g.next();
    }
  }
  return s;
}

// σ of a Gauss–Markov process of correlation time T whose Allan-deviation peak is `ratio`
// times the base model's there (as the hidden-effect generator sizes it).
double gmSigmaForPeak(double tau, double ratio) {
  double peak = 0.0;
  for (double t = tau / 10.0; t < tau * 10.0; t *= 1.05)
    peak = std::max(peak, gaussMarkovAllanVariance(t, tau, 1.0) / allanVarianceOfTerms(baseTerms(), t));
  return ratio / std::sqrt(peak);
}

std::vector<double> withEffect(const Records& rec, const TrialShape& s, const Curve& c, double size) {
  std::vector<double> x = s.noise;
  const double tr = c.kind == Kind::GaussMarkov ? gmSigmaForPeak(c.gm_fraction * rec.duration, size) : 0.0;
  double temp_mean = 0.0;
  for (double v : rec.true_temp) temp_mean += v / static_cast<double>(rec.n);
  const double k = size * adevFloor() / rec.temp_range;
  for (std::size_t i = 0; i < rec.n; ++i) {
    const double t = rec.t[i];
    switch (c.kind) {
      case Kind::Step: x[i] += t >= s.step_time ? s.step_sign * size * adevFloor() : 0.0; break;
      case Kind::Sinusoid: x[i] += size * whiteSd() * std::sin(2.0 * std::numbers::pi * s.freq * t + s.phase); break;
      case Kind::Temperature: x[i] += k * (rec.true_temp[i] - temp_mean); break;
      case Kind::GaussMarkov: x[i] += tr * s.gm_unit[i]; break;
    }
  }
  for (double& v : x) v = std::round(v * kLsb) / kLsb;
  return x;
}

// A trial's record with no effect.
std::vector<double> cleanRecord(const Records& rec, const TrialShape& s) {
  return withEffect(rec, s, {Kind::Step, "", "", 0.0, {}}, 0.0);
}

// The Hann periodogram of x with its line removed, as the check takes it.
model_check_detail::Periodogram linelessPeriodogram(const std::vector<double>& x) {
  std::vector<double> y = x;
  model_check_detail::removeLineInPlace(y);
  return model_check_detail::hannPeriodogram(y);
}

// ---- the known-form detector, calibrated on clean records ------------------------------

struct Oracle {
  std::vector<double> step_sd;     // per dyadic window
  std::vector<double> base_power;  // expected Hann periodogram of the clean record
  std::vector<double> gm_shape;    // of the curve's T
  double threshold = 0.0;
  double clean_rms = 0.0;             // of the statistic on the clean records that set the threshold
  std::size_t block = 50;             // 1 s blocks
  std::size_t nfft = 0;               // of the periodograms (sinusoid, Gauss–Markov)
  std::size_t k_lo = 0, k_hi = 0;     // the periodogram bins the check searches for a sinusoid
  double spectrum_scan_median = NAN;  // of knownSpectrumScanStatistic on those clean records
};

// The sinusoid's blind bound: the check's peak statistic with the background known, the
// largest ratio of the record's Hann periodogram (line removed) to the clean records' mean
// periodogram over the bins the check searches.
double knownSpectrumScanStatistic(const Oracle& o, const std::vector<double>& x) {
  const auto p = linelessPeriodogram(x);
  double best = 0.0;
  for (std::size_t k = o.k_lo; k <= o.k_hi && k < p.power.size(); ++k)
    if (o.base_power[k] > 0.0) best = std::max(best, p.power[k] / o.base_power[k]);
  return best;
}

// The (1 − α) quantile of the largest of n independent Exp(1) variables (a periodogram's bins
// over their mean, in Gaussian noise), n fitted to the median: (1 − e^−m)^n = 1/2.
double exponentialMaximaQuantile(double median, double alpha) {
  const double n = std::log(0.5) / std::log1p(-std::exp(-median));
  return -std::log(-std::expm1(std::log1p(-alpha) / n));
}

double oracleStatistic(const Oracle& o, const Curve& c, const TrialShape& s, const std::vector<double>& x) {
  switch (c.kind) {
    case Kind::Step:
      return knownStepStatistic(
          knownStepDifferences(x, static_cast<std::size_t>(std::ceil(s.step_time * kRate)), o.block), o.step_sd);
    case Kind::Sinusoid: return knownSinusoidStatistic(x, kRate, s.freq);
    case Kind::Temperature: return knownTemperatureStatistic(x, s.temp, o.block);
    case Kind::GaussMarkov: return spectralScoreStatistic(linelessPeriodogram(x).power, o.base_power, o.gm_shape);
  }
  return 0.0;
}

// Calibration: the first half of the clean records sets what the detector knows of the noise
// (step windows' sd, the expected periodogram), the second half its 1 % threshold.
Oracle calibrate(const Records& rec, const Curve& c, std::size_t records, std::uint64_t seed_base) {
  Oracle o;
  std::vector<TrialShape> shapes;
  std::vector<std::vector<double>> clean;
  for (std::size_t j = 0; j < records; ++j) {
    shapes.push_back(drawTrial(rec, seed_base + j, 0.0));
    clean.push_back(cleanRecord(rec, shapes.back()));
  }
  const std::size_t half = records / 2;
  if (c.kind == Kind::Step) {
    std::vector<double> sum2;
    std::vector<std::size_t> count;
    for (std::size_t j = 0; j < half; ++j) {
      const auto d =
          knownStepDifferences(clean[j], static_cast<std::size_t>(std::ceil(shapes[j].step_time * kRate)), o.block);
      if (d.size() > sum2.size()) {
        sum2.resize(d.size(), 0.0);
        count.resize(d.size(), 0);
      }
      for (std::size_t w = 0; w < d.size(); ++w) {
        sum2[w] += d[w] * d[w];
        ++count[w];
      }
    }
    for (std::size_t w = 0; w < sum2.size(); ++w)
      o.step_sd.push_back(count[w] > 4 ? std::sqrt(sum2[w] / static_cast<double>(count[w])) : 0.0);
  }
  if (c.kind == Kind::GaussMarkov || c.kind == Kind::Sinusoid) {
    for (std::size_t j = 0; j < half; ++j) {
      const auto p = linelessPeriodogram(clean[j]);
      if (o.base_power.empty()) {
        o.base_power.assign(p.power.size(), 0.0);
        o.nfft = p.nfft;
        if (c.kind == Kind::GaussMarkov)
          o.gm_shape = gaussMarkovSpectralShape(c.gm_fraction * rec.duration, kRate, p.nfft);
      }
      for (std::size_t k = 0; k < p.power.size(); ++k) o.base_power[k] += p.power[k] / static_cast<double>(half);
    }
    o.base_power[0] = 0.0;  // the mean, removed
    const model_check_detail::SearchedBins bins = model_check_detail::searchedBins(rec.n);
    o.k_lo = bins.k_lo;
    o.k_hi = bins.k_hi;
  }
  if (c.kind == Kind::Sinusoid) {
    std::vector<double> scans;
    for (std::size_t j = half; j < records; ++j) scans.push_back(knownSpectrumScanStatistic(o, clean[j]));
    std::sort(scans.begin(), scans.end());
    o.spectrum_scan_median = model_check_detail::sortedQuantile(scans, 0.5);
  }
  std::vector<double> values;
  for (std::size_t j = half; j < records; ++j) values.push_back(oracleStatistic(o, c, shapes[j], clean[j]));
  o.threshold = calibratedThreshold(values, kFalseAlarm);
  double ss = 0.0;
  for (double v : values) ss += v * v;
  o.clean_rms = std::sqrt(ss / static_cast<double>(values.size()));
  return o;
}

// ---- the blind bound, measured: the check's own statistics with the noise known -----------
// Steps: the check's scan (steps.cpp), the largest |D_W(t)| / sd_W over dyadic widths W and
// every boundary t of 1 s block means (D_W(t) the mean of the W blocks from t less the mean of
// the W before), with sd_W known from clean records of the generator's model instead of fitted
// to the record. Two reaches: ScanReach::Check, the check's widths (2 blocks up to 1/16 of the
// record, inside the τ range of its Allan fit) with its line removed; ScanReach::All, every width
// from 1 block to 1/4 of the record with no line removed, what knowing the noise at widths a
// record of this length cannot measure would give. Threshold: the empirical (1 − α) quantile
// at the check's rate for its step scan, on further clean records.
enum class ScanReach { Check, All };
struct KnownNoiseScan {
  ScanReach reach = ScanReach::Check;
  std::vector<std::size_t> widths;
  std::vector<double> sd;
  double threshold = 0.0;
};

// Per width: the largest |D_W(t)| over t, and the sum of squares and the count of D_W(t).
struct ScanMoments {
  std::vector<double> max_abs, sum_sq;
  std::vector<std::size_t> count;
};

ScanMoments scanMoments(const KnownNoiseScan& k, const std::vector<double>& x) {
  std::vector<double> y = model_check_detail::blockMeans(x, static_cast<std::size_t>(kRate));
  if (k.reach == ScanReach::Check) model_check_detail::removeLineInPlace(y);
  std::vector<double> prefix(y.size() + 1, 0.0);
  for (std::size_t i = 0; i < y.size(); ++i) prefix[i + 1] = prefix[i] + y[i];
  ScanMoments m{std::vector<double>(k.widths.size(), 0.0), std::vector<double>(k.widths.size(), 0.0),
                std::vector<std::size_t>(k.widths.size(), 0)};
  for (std::size_t j = 0; j < k.widths.size(); ++j) {
    const std::size_t w = k.widths[j];
    for (std::size_t t = w; t + w <= y.size(); ++t) {
      const double d = (prefix[t + w] - 2.0 * prefix[t] + prefix[t - w]) / static_cast<double>(w);
      m.max_abs[j] = std::max(m.max_abs[j], std::fabs(d));
      m.sum_sq[j] += d * d;
      ++m.count[j];
    }
  }
  return m;
}

double knownNoiseScanStatistic(const KnownNoiseScan& k, const std::vector<double>& x) {
  const ScanMoments m = scanMoments(k, x);
  double z = 0.0;
  for (std::size_t j = 0; j < k.widths.size(); ++j)
    if (k.sd[j] > 0.0) z = std::max(z, m.max_abs[j] / k.sd[j]);
  return z;
}

// The check's per-statistic false-alarm rates: its step scan at 10 × the default 1e-4
// (steps.cpp, kStepAlphaFactor), the temperature slope two-sided at the default.
constexpr double kCheckStepRate = 1e-3;
constexpr double kCheckTemperatureRate = 1e-4;
constexpr double kCheckSinusoidRate = 1e-4;
constexpr double kCheckGaussMarkovRate = 1e-3;  // gauss_markov.cpp: 10 × the default 1e-4

// The Gauss–Markov process's blind bound: the known-form score (the base spectrum known) at
// each correlation time of the check's grid (3 samples up to a fifteenth of the record, five
// per decade), the largest over the grid.
std::vector<std::vector<double>> gaussMarkovScanShapes(const Records& rec, std::size_t nfft) {
  std::vector<std::vector<double>> shapes;
  for (double t = 3.0 / kRate; t <= rec.duration / 15.0; t *= std::pow(10.0, 0.2))
    shapes.push_back(gaussMarkovSpectralShape(t, kRate, nfft));
  return shapes;
}

double gaussMarkovScanStatistic(const std::vector<double>& base_power, const std::vector<std::vector<double>>& shapes,
                                const std::vector<double>& x) {
  const auto p = linelessPeriodogram(x);
  double best = -std::numeric_limits<double>::infinity();
  for (const std::vector<double>& shape : shapes)
    best = std::max(best, spectralScoreStatistic(p.power, base_power, shape));
  return best;
}

// sd_W from the first tenth of `records` clean records (pooled over positions), the threshold
// from the rest.
KnownNoiseScan calibrateKnownNoiseScan(const Records& rec, ScanReach reach, std::size_t records,
                                       std::uint64_t seed_base) {
  KnownNoiseScan k;
  k.reach = reach;
  const std::size_t blocks = rec.n / static_cast<std::size_t>(kRate);
  const std::size_t first = reach == ScanReach::Check ? 2 : 1, share = reach == ScanReach::Check ? 16 : 4;
  for (std::size_t w = first; share * w <= blocks; w *= 2) k.widths.push_back(w);
  k.sd.assign(k.widths.size(), 1.0);
  auto clean = [&](std::size_t j) { return cleanRecord(rec, drawTrial(rec, seed_base + j, 0.0)); };
  const std::size_t for_sd = std::max<std::size_t>(records / 10, 20);
  std::vector<double> sum_sq(k.widths.size(), 0.0), count(k.widths.size(), 0.0);
  for (std::size_t j = 0; j < for_sd; ++j) {
    const ScanMoments m = scanMoments(k, clean(j));
    for (std::size_t s = 0; s < k.widths.size(); ++s) {
      sum_sq[s] += m.sum_sq[s];
      count[s] += static_cast<double>(m.count[s]);
    }
  }
  for (std::size_t s = 0; s < k.widths.size(); ++s) k.sd[s] = std::sqrt(sum_sq[s] / count[s]);
  std::vector<double> values;
  for (std::size_t j = 0; j < records; ++j) values.push_back(knownNoiseScanStatistic(k, clean(for_sd + j)));
  k.threshold = calibratedThreshold(values, kCheckStepRate);
  return k;
}

// ---- tallies -------------------------------------------------------------------------

struct Wilson {
  double p = 0.0, lo = 0.0, hi = 0.0;
};
Wilson wilson(std::size_t k, std::size_t n) {
  if (n == 0) return {NAN, NAN, NAN};
  const double z = 1.959964, nn = static_cast<double>(n), p = static_cast<double>(k) / nn;
  const double den = 1.0 + z * z / nn, mid = (p + z * z / (2.0 * nn)) / den;
  const double half = z * std::sqrt(p * (1.0 - p) / nn + z * z / (4.0 * nn * nn)) / den;
  return {p, std::max(0.0, mid - half), std::min(1.0, mid + half)};
}

// Size where the detection fraction first reaches 0.5, interpolated in log size; NaN when it
// never does, the smallest size (as negative) when it already does there.
double size50(const std::vector<double>& sizes, const std::vector<double>& p) {
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p[i] < 0.5) continue;
    if (i == 0) return -sizes[0];
    const double f = (0.5 - p[i - 1]) / (p[i] - p[i - 1]);
    return std::exp(std::log(sizes[i - 1]) + f * (std::log(sizes[i]) - std::log(sizes[i - 1])));
  }
  return NAN;
}

std::string formatSize(double s) {
  char buf[32];
  if (std::isnan(s)) return ">max";
  if (s < 0) {
    std::snprintf(buf, sizeof buf, "<%.3g", -s);
    return buf;
  }
  std::snprintf(buf, sizeof buf, "%.3g", s);
  return buf;
}

bool blindNames(const AxisModelCheck& r, Kind k) {
  const ModelEffect want = k == Kind::Step          ? ModelEffect::BiasSteps
                           : k == Kind::Sinusoid    ? ModelEffect::Sinusoid
                           : k == Kind::Temperature ? ModelEffect::TemperatureBias
                                                    : ModelEffect::GaussMarkov;
  for (const DetectedEffect& e : r.effects)
    if (e.effect == want) return true;
  return false;
}

struct Options {
  std::size_t trials = 16, calibration = 300, clean = 40, replicas = 40;
  std::size_t scan_calibration = 4000;  // clean records that set the measured bounds' thresholds (0: none)
  std::size_t first_trial = 0;
  std::vector<double> durations = {600.0, 3600.0};
  std::vector<std::string> effects = {"bias_steps", "sinusoid", "temperature_bias", "gauss_markov_short",
                                      "gauss_markov_long"};
  std::string data_dir;
  bool quick = false;
  bool explain = false;  // per step or temperature trial: the check's statistic beside the bound's
};

std::vector<Curve> curvesFor(double duration, const Options& opt) {
  auto grid = [&](double lo, double factor) {
    std::vector<double> g;
    const std::size_t count = opt.quick ? 2 : 8;
    const double f = opt.quick ? factor * factor * factor * factor : factor;
    for (std::size_t i = 0; i < count; ++i)
      g.push_back(lo * std::pow(f, static_cast<double>(i)) * (opt.quick ? 2.0 : 1.0));
    return g;
  };
  const double sin_scale = std::sqrt(600.0 / duration);  // a coherent detector's reach grows as √n
  // Each grid spans the known-form detector's rise to the blind check's (pilot runs).
  std::vector<Curve> all = {
      {Kind::Step, "bias_steps", "step / ADEV floor", 0.0, grid(2.0, std::sqrt(2.0))},
      {Kind::Sinusoid, "sinusoid", "amplitude / white sd", 0.0, grid(0.01 * sin_scale, std::sqrt(2.0))},
      {Kind::Temperature, "temperature_bias", "k x temperature range / ADEV floor", 0.0,
       grid(2.0 * std::sqrt(2.0), std::sqrt(2.0))},
      {Kind::GaussMarkov, "gauss_markov_short", "GM ADEV peak / base (T = duration/300)", 1.0 / 300.0,
       grid(0.5, std::sqrt(2.0))},
      {Kind::GaussMarkov, "gauss_markov_long", "GM ADEV peak / base (T = duration/60)", 1.0 / 60.0,
       grid(1.0, std::sqrt(2.0))},
  };
  std::vector<Curve> out;
  for (const Curve& c : all)
    if (std::find(opt.effects.begin(), opt.effects.end(), c.name) != opt.effects.end()) out.push_back(c);
  return out;
}

// --explain: one line per step or temperature trial and size, where the check loses against
// the blind bound: its statistic (the step scan's largest z, or the temperature slope less its
// null median) and threshold, whether that came from a further look, the effects it named, the
// bound's statistic and threshold, and the base fit's B and K (the generator's: 10 °/h,
// 3 °/h^1.5).
void explainTrial(const AxisModelCheck& r, const Curve& c, std::size_t trial, double size, double bound_value,
                  double bound_threshold, const std::vector<KnownNoiseScan>& scans, const std::vector<double>& x) {
  const std::string prefix = c.kind == Kind::Step ? "step_scan_max_z" : "temperature_slope_dps_per_c";
  double value = NAN, threshold = NAN;
  std::string look = "first";
  for (const CheckStatistic& st : r.statistics)
    if (st.name.rfind(prefix, 0) == 0) {
      value = c.kind == Kind::Step ? st.value : std::fabs(st.value - st.null_median);
      threshold = c.kind == Kind::Step ? st.threshold : st.threshold - st.null_median;  // two-sided: |v − median|
      if (st.name.find("second look") != std::string::npos) look = "further";
    }
  std::printf("explain trial %zu size %.3g check %.4g / %.4g %s look, named:", trial, size, value, threshold,
              look.c_str());
  for (const DetectedEffect& e : r.effects) std::printf(" %s", std::string(modelEffectName(e.effect)).c_str());
  if (r.effects.empty()) std::printf(" none");
  if (c.kind == Kind::Temperature) std::printf("; bound %.3f / %.3f", bound_value, bound_threshold);
  for (const KnownNoiseScan& k : scans)
    std::printf("; known-noise-%s %.2f / %.2f", k.reach == ScanReach::Check ? "check" : "all",
                knownNoiseScanStatistic(k, x), k.threshold);
  std::printf("; base B %.3g K %.3g\n", r.base_fit.value.bias_instability_deg_per_h,
              r.base_fit.value.rrw_deg_per_h_sqrt_h);
}

ModelCheckOptions checkOptions(const Options& opt, std::uint64_t seed) {
  ModelCheckOptions o;
  o.replicas = opt.replicas;
  o.seed = seed;
  return o;
}

// The blind bound's detectors: steps, the two known-noise scans (check's widths, all widths);
// temperature, the known-form statistic at the check's two-sided rate; sinusoid, the
// known-background peak scan at the check's rate; Gauss–Markov, the known-spectrum score
// scanned over the check's correlation times, its threshold the empirical quantile of clean
// records at the check's rate. `threshold` is the last three's.
struct Bounds {
  std::vector<KnownNoiseScan> scans;
  std::vector<std::vector<double>> gm_shapes;  // the Gauss–Markov scan's, one per correlation time
  double threshold = NAN;
  bool measured() const { return !scans.empty() || !std::isnan(threshold); }
};

Bounds calibrateBounds(const Records& rec, const Curve& c, const Oracle& oracle, const Options& opt) {
  Bounds b;
  const auto dur = static_cast<std::uint64_t>(rec.duration);
  if (c.kind == Kind::Step && opt.scan_calibration > 0) {
    b.scans.push_back(calibrateKnownNoiseScan(rec, ScanReach::Check, opt.scan_calibration, 3000000 + dur * 1000));
    b.scans.push_back(calibrateKnownNoiseScan(rec, ScanReach::All, opt.scan_calibration, 4000000 + dur * 1000));
  }
  if (c.kind == Kind::Temperature) b.threshold = oracle.clean_rms * normalQuantile(1.0 - 0.5 * kCheckTemperatureRate);
  if (c.kind == Kind::Sinusoid)
    b.threshold = exponentialMaximaQuantile(oracle.spectrum_scan_median, kCheckSinusoidRate);
  if (c.kind == Kind::GaussMarkov && opt.scan_calibration > 0) {
    b.gm_shapes = gaussMarkovScanShapes(rec, oracle.nfft);
    std::vector<double> values;
    for (std::size_t k = 0; k < opt.scan_calibration; ++k) {
      const TrialShape clean = drawTrial(rec, 5000000 + dur * 1000 + k, 0.0);
      values.push_back(gaussMarkovScanStatistic(oracle.base_power, b.gm_shapes, cleanRecord(rec, clean)));
    }
    b.threshold = calibratedThreshold(values, kCheckGaussMarkovRate);
  }
  return b;
}

void printCurveTable(const Curve& c, const Records& rec, const Options& opt, const Oracle& oracle, const Bounds& bounds,
                     const std::vector<std::array<std::size_t, 4>>& hits) {
  const auto dur = static_cast<std::uint64_t>(rec.duration);
  const bool with_bound = bounds.measured();
  std::printf("# curve %s duration %.0f s: size = %s; %zu trials per size; optimal threshold %.4g", c.name.c_str(),
              rec.duration, c.size_what.c_str(), opt.trials, oracle.threshold);
  for (const KnownNoiseScan& k : bounds.scans)
    std::printf("; known-noise scan (%s) threshold %.3f", k.reach == ScanReach::Check ? "check's widths" : "all widths",
                k.threshold);
  if (!std::isnan(bounds.threshold)) std::printf("; bound threshold %.4g", bounds.threshold);
  std::printf("\n#   size  trials  blind    lo     hi   optimal  lo     hi%s\n",
              with_bound ? "   bound   lo     hi" : "");
  std::FILE* dat = nullptr;
  if (!opt.data_dir.empty()) {
    const std::string path = opt.data_dir + "/" + c.name + "-" + std::to_string(dur) + ".dat";
    dat = std::fopen(path.c_str(), "w");
    if (!dat) {
      std::fprintf(stderr, "cannot write %s\n", path.c_str());
      std::exit(1);
    }
    std::fprintf(dat, "# %s, %.0f s: size blind lo hi optimal lo hi%s\n", c.size_what.c_str(), rec.duration,
                 with_bound ? " bound lo hi" : "");
  }
  std::vector<double> pb, po, pbound, pall;
  for (std::size_t i = 0; i < c.sizes.size(); ++i) {
    const Wilson b = wilson(hits[i][0], opt.trials), o = wilson(hits[i][1], opt.trials);
    const Wilson d = wilson(hits[i][2], opt.trials), a = wilson(hits[i][3], opt.trials);
    pb.push_back(b.p);
    po.push_back(o.p);
    pbound.push_back(d.p);
    pall.push_back(a.p);
    std::printf("%8.4g %6zu %6.3f %6.3f %6.3f %6.3f %6.3f %6.3f", c.sizes[i], opt.trials, b.p, b.lo, b.hi, o.p, o.lo,
                o.hi);
    if (with_bound) std::printf(" %6.3f %6.3f %6.3f", d.p, d.lo, d.hi);
    std::printf("\n");
    if (dat) {
      std::fprintf(dat, "%g %g %g %g %g %g %g", c.sizes[i], b.p, b.lo, b.hi, o.p, o.lo, o.hi);
      if (with_bound) std::fprintf(dat, " %g %g %g", d.p, d.lo, d.hi);
      std::fprintf(dat, "\n");
    }
  }
  if (dat) std::fclose(dat);
  const double b50 = size50(c.sizes, pb), o50 = size50(c.sizes, po);
  // Detection above twice the blind 50 % size, pooled over those sizes.
  std::size_t above_k = 0, above_n = 0;
  if (!std::isnan(b50))
    for (std::size_t i = 0; i < c.sizes.size(); ++i)
      if (c.sizes[i] >= 2.0 * std::fabs(b50)) {
        above_k += hits[i][0];
        above_n += opt.trials;
      }
  const Wilson above = wilson(above_k, above_n);
  auto ratio = [](double x, double y) { return (std::isnan(x) || std::isnan(y)) ? NAN : std::fabs(x) / std::fabs(y); };
  std::printf("summary %s %.0f blind50 %s optimal50 %s ratio %.3g above2x %zu/%zu (%.3f, %.3f..%.3f)", c.name.c_str(),
              rec.duration, formatSize(b50).c_str(), formatSize(o50).c_str(), ratio(b50, o50), above_k, above_n,
              above.p, above.lo, above.hi);
  if (with_bound) {
    const double d50 = size50(c.sizes, pbound);
    std::printf(" bound50 %s check/bound %.3g", formatSize(d50).c_str(), ratio(b50, d50));
  }
  if (bounds.scans.size() > 1) {
    const double a50 = size50(c.sizes, pall);
    std::printf(" bound_all_widths50 %s check/bound_all_widths %.3g", formatSize(a50).c_str(), ratio(b50, a50));
  }
  std::printf("\n\n");
}

void runCurve(const Records& rec, const Curve& c, const Options& opt, double& check_seconds, std::size_t& checks) {
  const auto dur = static_cast<std::uint64_t>(rec.duration);
  const Oracle oracle = calibrate(rec, c, opt.calibration, 1000000 + dur * 1000);
  const Bounds bounds = calibrateBounds(rec, c, oracle, opt);
  // Per size: the check, the known-form detector, the bound (check's widths), the bound (all widths).
  std::vector<std::array<std::size_t, 4>> hits(c.sizes.size(), {0, 0, 0, 0});
  for (std::size_t j = opt.first_trial; j < opt.first_trial + opt.trials; ++j) {
    const std::uint64_t seed = 7000000 + dur * 1000 + j;
    const TrialShape s = drawTrial(rec, seed, c.gm_fraction * rec.duration);
    for (std::size_t i = 0; i < c.sizes.size(); ++i) {
      const std::vector<double> x = withEffect(rec, s, c, c.sizes[i]);
      const double known = oracleStatistic(oracle, c, s, x);
      hits[i][1] += known > oracle.threshold ? 1 : 0;
      const double bound_value = c.kind == Kind::Sinusoid ? knownSpectrumScanStatistic(oracle, x)
                                 : !bounds.gm_shapes.empty()
                                     ? gaussMarkovScanStatistic(oracle.base_power, bounds.gm_shapes, x)
                                     : known;
      hits[i][2] += bound_value > bounds.threshold ? 1 : 0;  // false when NaN
      for (std::size_t k = 0; k < bounds.scans.size(); ++k)
        hits[i][2 + k] += knownNoiseScanStatistic(bounds.scans[k], x) > bounds.scans[k].threshold ? 1 : 0;
      const auto t0 = std::chrono::steady_clock::now();
      const AxisModelCheck r = checkAxisModel({x, kRate, s.temp, rec.t, {}}, checkOptions(opt, seed));
      check_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      ++checks;
      hits[i][0] += blindNames(r, c.kind) ? 1 : 0;
      if (opt.explain && (c.kind == Kind::Step || c.kind == Kind::Temperature))
        explainTrial(r, c, j, c.sizes[i], bound_value, bounds.threshold, bounds.scans, x);
    }
  }
  printCurveTable(c, rec, opt, oracle, bounds, hits);
}

void runClean(const Records& rec, const Options& opt, double& check_seconds, std::size_t& checks) {
  const auto dur = static_cast<std::uint64_t>(rec.duration);
  std::size_t with_effect = 0;
  std::map<std::string, std::size_t> names;
  for (std::size_t j = 0; j < opt.clean; ++j) {
    const std::uint64_t seed = 9000000 + dur * 1000 + j;
    const TrialShape s = drawTrial(rec, seed, 0.0);
    const std::vector<double> x = cleanRecord(rec, s);
    const auto t0 = std::chrono::steady_clock::now();
    const AxisModelCheck r = checkAxisModel({x, kRate, s.temp, rec.t, {}}, checkOptions(opt, seed));
    check_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++checks;
    with_effect += r.effects.empty() ? 0 : 1;
    for (const DetectedEffect& e : r.effects) ++names[std::string(modelEffectName(e.effect))];
  }
  const Wilson w = wilson(with_effect, opt.clean);
  std::printf("clean %.0f false_discoveries %zu/%zu (%.3f, %.3f..%.3f)", rec.duration, with_effect, opt.clean, w.p,
              w.lo, w.hi);
  for (const auto& [name, count] : names) std::printf(" %s:%zu", name.c_str(), count);
  std::printf("\n\n");
}

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= s.size()) {
    const std::size_t comma = s.find(',', start);
    out.push_back(s.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

Options parseOptions(int argc, char** argv) {
  Options opt;
  for (int i = 1; i < argc; ++i) {
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", argv[i]);
        std::exit(2);
      }
      return argv[++i];
    };
    const std::string a = argv[i];
    if (a == "--quick") {
      opt.quick = true;
      opt.trials = 2;
      opt.calibration = 40;
      opt.clean = 2;
      opt.replicas = 16;
      opt.durations = {120.0};
    } else if (a == "--trials") {
      opt.trials = std::strtoull(next().c_str(), nullptr, 10);
    } else if (a == "--calibration") {
      opt.calibration = std::strtoull(next().c_str(), nullptr, 10);
    } else if (a == "--clean") {
      opt.clean = std::strtoull(next().c_str(), nullptr, 10);
    } else if (a == "--replicas") {
      opt.replicas = std::strtoull(next().c_str(), nullptr, 10);
    } else if (a == "--durations") {
      opt.durations.clear();
      for (const std::string& d : splitList(next())) opt.durations.push_back(std::atof(d.c_str()));
    } else if (a == "--effects") {
      opt.effects = splitList(next());
    } else if (a == "--data") {
      opt.data_dir = next();
    } else if (a == "--explain") {
      opt.explain = true;
    } else if (a == "--first-trial") {
      opt.first_trial = std::strtoull(next().c_str(), nullptr, 10);
    } else if (a == "--scan-calibration") {
      opt.scan_calibration = std::strtoull(next().c_str(), nullptr, 10);
    } else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      std::exit(2);
    }
  }
  if (opt.quick) opt.scan_calibration = std::min<std::size_t>(opt.scan_calibration, 200);
  if (opt.trials == 0 || opt.calibration < 4) {
    std::fprintf(stderr, "--trials must be > 0 and --calibration ≥ 4\n");
    std::exit(2);
  }
  return opt;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parseOptions(argc, argv);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // tables appear as each curve ends
  std::printf(
      "model_check_curves: base Q 2 urad, N 0.5 deg/rt-h, B 10 deg/h, K 3 deg/h^1.5 at 50 Hz; white sd %.4g, "
      "ADEV floor %.4g deg/s; %zu replicas; optimal threshold at %.0f %% false alarm from %zu clean records\n\n",
      whiteSd(), adevFloor(), opt.replicas, 100.0 * kFalseAlarm, opt.calibration / 2);
  double check_seconds = 0.0;
  std::size_t checks = 0;
  const auto start = std::chrono::steady_clock::now();
  for (double duration : opt.durations) {
    const Records rec = makeRecords(duration);
    for (const Curve& c : curvesFor(duration, opt)) runCurve(rec, c, opt, check_seconds, checks);
    if (opt.clean > 0) runClean(rec, opt, check_seconds, checks);
  }
  std::printf("checks %zu, mean %.2f s per check, total %.0f s\n", checks,
              checks ? check_seconds / static_cast<double>(checks) : 0.0,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return 0;
}
