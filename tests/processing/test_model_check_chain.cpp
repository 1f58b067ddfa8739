// The acquisition chain in the model check's base model (docs/model-check.md, "The acquisition
// chain"): the white-noise shape of each DLPF setting against the simulator's own DLPF, the
// replicas' white noise against that shape, and clean gyrod-like recordings made through every
// DLPF setting, which must come back with no effect.
#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"
#include "processing/model_check/pipeline.hpp"
#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod::processing;

namespace {

std::string describeChain(const AxisModelCheck& r) {
  std::string s;
  for (const DetectedEffect& e : r.effects)
    s += std::string(modelEffectName(e.effect)) + " (statistic " + std::to_string(e.evidence.statistic) +
         ", threshold " + std::to_string(e.evidence.threshold) + ") ";
  return s.empty() ? "(no effect)" : s;
}

// Mean over seeds of the overlapping Allan variance of white rate noise (ARW only) through the
// simulator's DLPF and decimation, as a multiple of F²·N²/τ (the long-τ value).
std::vector<double> simulatedWhiteShape(int cfg, double rate, const std::vector<std::size_t>& ms, int seeds,
                                        std::vector<double>& standard_error) {
  SimulationModel m;
  m.rate_hz = rate;
  m.dlpf_cfg = cfg;
  m.axes[0].terms.arw_deg_per_sqrt_h = 1.0;
  const double n2 = allanVarianceCoefficient(NoiseTerm::AngleRandomWalk, 1.0);
  const double f = aliasedWhiteNoiseFactor(cfg, rate);
  std::vector<double> sum(ms.size(), 0.0), sum2(ms.size(), 0.0);
  const std::size_t n = 20000;
  for (int s = 0; s < seeds; ++s) {
    NoiseSimulator sim(m, static_cast<double>(n) / rate, 100 + static_cast<std::uint64_t>(s));
    std::vector<double> x(n);
    for (double& v : x) v = sim.next().rate_dps[0];
    const std::vector<double> v = overlappingAllanVariances(x, ms);
    for (std::size_t j = 0; j < ms.size(); ++j) {
      const double r = v[j] * static_cast<double>(ms[j]) / rate / (f * f * n2);
      sum[j] += r;
      sum2[j] += r * r;
    }
  }
  std::vector<double> mean(ms.size());
  standard_error.assign(ms.size(), 0.0);
  for (std::size_t j = 0; j < ms.size(); ++j) {
    mean[j] = sum[j] / seeds;
    standard_error[j] = std::sqrt((sum2[j] / seeds - mean[j] * mean[j]) / (seeds - 1));
  }
  return mean;
}

}  // namespace

TEST(ModelCheckChain, WhiteShapeIsOneWithoutDlpfAndTendsToOneAtLongTau) {
  const std::vector<std::size_t> ms{1, 2, 4, 16, 64, 1024};
  for (double s : chainWhiteNoiseShape({}, 50.0, ms)) EXPECT_EQ(s, 1.0);
  for (double s : chainWhiteNoiseShape({std::nullopt, 0}, 50.0, ms)) EXPECT_EQ(s, 1.0);
  const std::vector<double> s4 = chainWhiteNoiseShape({4, std::nullopt}, 50.0, ms);
  // docs/simulator.md, "DLPF and the shortest τ": the PSD integral gives 0.8735, 1.014 and
  // 1.150 × N²/τ at m = 1, 2, 16 for DLPF_CFG 4 at 50 Hz, and F = 1.0814.
  const double f2 = 1.0814 * 1.0814;
  EXPECT_NEAR(s4[0], 0.8735 / f2, 0.004);
  EXPECT_NEAR(s4[1], 1.014 / f2, 0.004);
  EXPECT_NEAR(s4[3], 1.150 / f2, 0.004);
  EXPECT_NEAR(s4[5], 1.0, 1e-3);
}

// The shape against the simulator's own DLPF at the internal rate, for every setting, within
// 4 standard errors of the mean over seeds.
TEST(ModelCheckChain, WhiteShapeMatchesTheSimulatorsDlpfForEverySetting) {
  const std::vector<std::pair<int, double>> settings{{0, 1000.0}, {1, 500.0}, {2, 200.0}, {3, 100.0},
                                                     {4, 50.0},   {5, 50.0},  {6, 50.0}};
  const std::vector<std::size_t> ms{1, 2, 3, 5, 10, 30};
  for (const auto& [cfg, rate] : settings) {
    std::vector<double> se;
    const std::vector<double> sim = simulatedWhiteShape(cfg, rate, ms, 12, se);
    const std::vector<double> s = chainWhiteNoiseShape({cfg, std::nullopt}, rate, ms);
    for (std::size_t j = 0; j < ms.size(); ++j)
      EXPECT_NEAR(sim[j], s[j], 4.0 * se[j] + 1e-3) << "DLPF_CFG " << cfg << " at " << rate << " Hz, m " << ms[j];
  }
}

// The replicas draw the chain's white noise at the output rate (a moving average): its Allan
// curve must be the shape too.
TEST(ModelCheckChain, ReplicaWhiteNoiseHasTheChainsShape) {
  using namespace model_check_detail;
  const std::vector<std::size_t> ms{1, 2, 3, 5, 10, 30};
  for (int cfg : {4, 6}) {
    const ChainModel chain = makeChainModel({cfg, std::nullopt}, 50.0, ms);
    std::vector<double> mean(ms.size(), 0.0);
    const int seeds = 12;
    for (int s = 0; s < seeds; ++s) {
      std::vector<double> x(40000, 0.0);
      addChainWhiteNoise(x, chain, 1.0, 7 + static_cast<std::uint64_t>(s));
      const std::vector<double> v = overlappingAllanVariances(x, ms);
      for (std::size_t j = 0; j < ms.size(); ++j) mean[j] += v[j] * static_cast<double>(ms[j]) / 50.0 / seeds;
    }
    for (std::size_t j = 0; j < ms.size(); ++j)
      EXPECT_NEAR(mean[j], chain.white_shape[j], 0.03 * chain.white_shape[j]) << "DLPF_CFG " << cfg << ", m " << ms[j];
  }
}

TEST(ModelCheckChain, ARateTheDlpfCannotMakeIsRejected) {
  std::vector<double> x(3000, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(0.1 * static_cast<double>(i));
  AxisModelCheckInput in{x, 30.0, {}, {}, {4, std::nullopt}};
  try {
    checkAxisModel(in);
    FAIL() << "accepted 30 Hz with DLPF_CFG 4";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("acquisition chain"), std::string::npos) << e.what();
  }
  in.chain = {std::nullopt, 7};
  EXPECT_THROW(checkAxisModel(in), std::invalid_argument);
}

// The flicker (bias instability) term through the chain: the simulator's DLPF at the internal
// rate against the same flicker made at the output rate, and the replicas' output-rate filter
// against the shape. DLPF_CFG 6 at 50 Hz filters it most (5 Hz against a 25 Hz Nyquist).
TEST(ModelCheckChain, FlickerThroughTheDlpfHasTheChainsShape) {
  using namespace model_check_detail;
  const std::vector<std::size_t> ms{1, 2, 3, 5, 10, 30};
  const ChainModel chain = makeChainModel({6, std::nullopt}, 50.0, ms);
  EXPECT_LT(chain.flicker_shape[0], 0.6);  // most of the flicker's short-τ variance is filtered
  EXPECT_NEAR(chain.flicker_shape[5], 1.0, 0.03);
  const std::size_t n = 20000, lead = chain.flicker_ma.size() - 1;
  std::vector<double> chip(ms.size(), 0.0), plain(ms.size(), 0.0), replica(ms.size(), 0.0);
  for (int s = 0; s < 12; ++s) {
    SimulationModel m;
    m.rate_hz = 50.0;
    m.axes[0].terms.bias_instability_deg_per_h = 10.0;
    NoiseSimulator out_rate(m, static_cast<double>(n + lead) / 50.0, 500 + static_cast<std::uint64_t>(s));
    m.dlpf_cfg = 6;
    NoiseSimulator through(m, static_cast<double>(n) / 50.0, 900 + static_cast<std::uint64_t>(s));
    std::vector<double> a(n), b(n + lead);
    for (double& v : a) v = through.next().rate_dps[0];
    for (double& v : b) v = out_rate.next().rate_dps[0];
    const std::vector<double> filtered = filterChainFlicker(b, chain, n);
    const std::vector<double> va = overlappingAllanVariances(a, ms),
                              vb = overlappingAllanVariances(std::span<const double>(b).subspan(lead), ms),
                              vf = overlappingAllanVariances(filtered, ms);
    for (std::size_t j = 0; j < ms.size(); ++j) {
      chip[j] += va[j];
      plain[j] += vb[j];
      replica[j] += vf[j];
    }
  }
  // The shape is that of ideal 1/f noise; the simulator's flicker (two Gauss–Markov processes
  // per decade from 1.2 τ0 up) is not 1/f within a factor of ~3 of its own Nyquist frequency,
  // at either rate, so at m = 1, 2 the simulated ratios are 10–25 % above the ideal shape
  // (measured: 0.145 and 0.132 against 0.118 at m = 1); from m = 3 on they agree within 6 %.
  for (std::size_t j = 0; j < ms.size(); ++j) {
    const double tolerance = (ms[j] < 3 ? 0.3 : 0.06) * chain.flicker_shape[j];
    EXPECT_NEAR(chip[j] / plain[j], chain.flicker_shape[j], tolerance) << "m " << ms[j];
    EXPECT_NEAR(replica[j] / plain[j], chain.flicker_shape[j], tolerance) << "m " << ms[j];
  }
}

// The case: gyrod's default DLPF_CFG 4 at 50 Hz, nothing else, came back with a
// Gauss–Markov process on every axis, outliers and `unexplained`. Clean data made through the
// DLPF settings (at rates they allow), three axes each, must come back with no effect,
// DLPF_CFG 6 included (it named a Gauss–Markov process on half the axes while the chain
// filtered only the white noise; docs/model-check.md, "False discoveries through every DLPF
// setting").
TEST(ModelCheckChain, CleanDataThroughEveryDlpfSettingHasNoEffect) {
  const std::vector<std::pair<int, double>> settings{{0, 100.0}, {1, 200.0}, {2, 200.0}, {3, 100.0},
                                                     {4, 50.0},  {5, 50.0},  {6, 50.0}};
  for (const auto& [cfg, rate] : settings) {
    HiddenEffectGenerator gen(40 + static_cast<std::uint64_t>(cfg));
    gen.dlpf_cfg = cfg;
    const GeneratedRecording g = gen.generate(600.0 * 50.0 / rate, rate, {});
    for (std::size_t a = 0; a < 3; ++a) {
      ModelCheckOptions o;
      o.seed = 3;
      o.threads = 2;
      const AxisModelCheck r = checkAxisModel({g.axes[a], g.rate_hz, g.temp, g.t, {cfg, 0}}, o);
      EXPECT_TRUE(r.effects.empty()) << "DLPF_CFG " << cfg << " at " << rate << " Hz, axis " << a << ": "
                                     << describeChain(r);
      EXPECT_EQ(r.chain.dlpf_cfg, cfg);
    }
  }
}

// Without the chain in the model, the same DLPF_CFG 4 data show the roll-off as effects (what
// the issue found), and the estimate from the Allan curve finds the setting.
TEST(ModelCheckChain, TheDlpfIsEstimatedFromTheRollOff) {
  for (int cfg : {3, 4, 5, 6}) {  // NOLINT(readability-magic-numbers)
    const double rate = cfg == 3 ? 100.0 : 50.0;
    HiddenEffectGenerator gen(60 + static_cast<std::uint64_t>(cfg));
    gen.dlpf_cfg = cfg;
    const GeneratedRecording g = gen.generate(300.0, rate, {});
    std::vector<DlpfCandidate> candidates = dlpfCandidates(rate);
    for (std::size_t a = 0; a < 3; ++a) scoreDlpfCandidates(g.axes[a], rate, candidates);
    std::string scores;
    for (const DlpfCandidate& c : candidates)
      scores += (c.dlpf_cfg ? std::to_string(*c.dlpf_cfg) : std::string("none")) + ": " + std::to_string(c.chi2) + " ";
    EXPECT_EQ(chooseDlpf(candidates, 3), cfg) << "DLPF_CFG " << cfg << "; " << scores;
  }
  HiddenEffectGenerator gen(70);
  const GeneratedRecording g = gen.generate(300.0, 50.0, {});
  std::vector<DlpfCandidate> candidates = dlpfCandidates(50.0);
  for (std::size_t a = 0; a < 3; ++a) scoreDlpfCandidates(g.axes[a], 50.0, candidates);
  EXPECT_EQ(chooseDlpf(candidates, 3), std::nullopt) << "no DLPF";
}
