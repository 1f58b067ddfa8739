// The model check's Gauss–Markov detector at the edge of its reach (docs/model-check.md,
// "Detection curves"): a process of correlation time duration/300 whose Allan-deviation peak
// is 1.6 × the base model's there, between the 50 %-detection sizes of the null drawn from the
// five-term fit (2.0) and of the null drawn from the terms fitted jointly with the
// Gauss–Markov column (1.26). Records: the curves' base model (Q 2 µrad, N 0.5 °/√h,
// B 10 °/h, K 3 °/h^1.5, 50 Hz, 131 LSB per °/s), 10 minutes, seeded; the check sees only the
// series.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "processing/base/noise_terms.hpp"
#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"
#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod::processing;

namespace {

constexpr double kGaussMarkovRate = 50.0;
constexpr double kGaussMarkovDuration = 600.0;

NoiseTerms baseTerms() {
  NoiseTerms t;
  t.quantization_urad = 2.0;
  t.arw_deg_per_sqrt_h = 0.5;
  t.bias_instability_deg_per_h = 10.0;
  t.rrw_deg_per_h_sqrt_h = 3.0;
  return t;
}

// σ of a Gauss–Markov process of correlation time T whose Allan-deviation peak is `ratio`
// times the base model's there (as bench/model_check_curves.cpp sizes it).
double sigmaForPeak(double tau, double ratio) {
  double peak = 0.0;
  for (double t = tau / 10.0; t < tau * 10.0; t *= 1.05)
    peak = std::max(peak, gaussMarkovAllanVariance(t, tau, 1.0) / allanVarianceOfTerms(baseTerms(), t));
  return ratio / std::sqrt(peak);
}

std::vector<double> record(std::uint64_t seed, double sigma) {
  SimulationModel m;
  m.rate_hz = kGaussMarkovRate;
  m.axes[0].terms = baseTerms();
  m.axes[0].extra.gauss_markov_tau_s = kGaussMarkovDuration / 300.0;
  m.axes[0].extra.gauss_markov_sigma_dps = sigma;
  NoiseSimulator sim(m, kGaussMarkovDuration, seed);
  std::vector<double> x(sim.sampleCount());
  for (double& v : x) v = std::round(sim.next().rate_dps[0] * 131.0) / 131.0;
  return x;
}

bool namesGaussMarkov(const std::vector<double>& x, std::uint64_t seed, std::string& log) {
  ModelCheckOptions o;
  o.replicas = 40;
  o.seed = seed;
  o.threads = 2;
  const AxisModelCheck r = checkAxisModel({x, kGaussMarkovRate, {}, {}, {}}, o);
  for (const CheckStatistic& s : r.statistics)
    if (s.name == "gauss_markov_sqrt_chi2_gain")
      log += "  statistic " + std::to_string(s.value) + ", threshold " + std::to_string(s.threshold) + "\n";
  return std::any_of(r.effects.begin(), r.effects.end(),
                     [](const DetectedEffect& e) { return e.effect == ModelEffect::GaussMarkov; });
}

}  // namespace

TEST(ModelCheckGaussMarkov, FindsAProcessBetweenTheOldAndNewHalfDetectionSizes) {
  // Six seeds: the five-term null alone names 2 of them (measured at c285c08), the joint null
  // 4 guarded by the five-term null at 100 α (4c35414). The same six records without the
  // process must stay clean.
  const double sigma = sigmaForPeak(kGaussMarkovDuration / 300.0, 1.6);
  std::size_t found = 0, false_found = 0;
  std::string log;
  for (std::uint64_t s = 0; s < 6; ++s) {
    found += namesGaussMarkov(record(1000 + s, sigma), 7 + s, log);
    false_found += namesGaussMarkov(record(1000 + s, 0.0), 7 + s, log);
  }
  EXPECT_GE(found, 4u) << log;
  EXPECT_EQ(false_found, 0u) << log;
}

TEST(ModelCheckGaussMarkov, CleanRecordsWithoutDlpfTheJointNullNamedStayMostlyClean) {
  // The four clean axes (generator seeds 1212, 1224, 1259, 1262, 10 minutes at 50 Hz, no
  // DLPF, as `model_check_dlpf_fdr --cfg none`) on which the joint-fit null alone named a
  // process (T 0.06–3.8 s), each with a rate random walk the five-term fit put at 0. With the
  // five-term null as a guard at 100 α, three are clean; the fourth (seed 1259 axis 1, statistic
  // 5.7 above both thresholds) is still named (docs/model-check.md "The Gauss–Markov null",
  // measured at 4c35414).
  // The power side: FindsAProcessBetweenTheOldAndNewHalfDetectionSizes above.
  const std::vector<std::pair<std::uint64_t, std::size_t>> axes{{1212, 1}, {1224, 2}, {1259, 1}, {1262, 0}};
  std::size_t named = 0;
  std::string log;
  for (const auto& [seed, axis] : axes) {
    HiddenEffectGenerator gen(seed);
    gen.dlpf_cfg = std::nullopt;
    const GeneratedRecording g = gen.generate(kGaussMarkovDuration, kGaussMarkovRate, {});
    ModelCheckOptions o;
    o.seed = seed;
    o.replicas = 40;
    o.threads = 2;
    const AxisModelCheck r = checkAxisModel({g.axes[axis], g.rate_hz, g.temp, g.t, {std::nullopt, 0}}, o);
    for (const CheckStatistic& st : r.statistics)
      if (st.name == "gauss_markov_sqrt_chi2_gain")
        log += "seed " + std::to_string(seed) + " axis " + std::to_string(axis) + ": statistic " +
               std::to_string(st.value) + ", threshold " + std::to_string(st.threshold) + "\n";
    named += std::any_of(r.effects.begin(), r.effects.end(),
                         [](const DetectedEffect& e) { return e.effect == ModelEffect::GaussMarkov; });
  }
  EXPECT_LE(named, 1u) << log;
}
