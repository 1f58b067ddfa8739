// The noise simulator: model validation, reproducibility, the deterministic parts
// (bias, ramp, temperature, quantisation grid, saturation) against closed forms, the AR
// component against its theoretical autocovariance, the composition that the mock device
// relies on (the Allan evidence: test_noise_simulator_allan.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod::processing;

namespace {

SimulationModel pureModel(double rate_hz = 100.0) {
  SimulationModel m;
  m.rate_hz = rate_hz;
  return m;
}

// The paper's X axis (Table 2) on every axis, a bias, an AR(1) from Table 3, warm-up.
SimulationModel paperSensorModel() {
  SimulationModel m;
  m.rate_hz = 50.0;
  m.dlpf_cfg = 4;
  m.fs_sel = 0;
  for (auto& axis : m.axes) {
    axis.terms.quantization_urad = 0.1663;
    axis.terms.arw_deg_per_sqrt_h = 0.95164;
    axis.terms.bias_instability_deg_per_h = 0.60565;
    axis.terms.rrw_deg_per_h_sqrt_h = 0.07759;
    axis.terms.rate_ramp_deg_per_h2 = 0.43223;
    axis.ar.phi = {-0.2855};
    axis.ar.noise_var = 1e-4;
  }
  m.axes[0].bias_dps = 1.367;
  m.axes[1].bias_dps = -0.4;
  m.axes[2].bias_dps = 0.25;
  m.temperature = {24.0, 38.0, 900.0, 0.02};
  return m;
}

std::uint64_t bitsOf(double v) {
  std::uint64_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  return u;
}

// FNV-1a over the bit patterns of t, gx, gy, gz, temp of the first n samples.
std::uint64_t streamHash(NoiseSimulator& sim, int n) {
  std::uint64_t h = 0xCBF29CE484222325ULL;
  auto mix = [&h](double v) {
    const std::uint64_t u = bitsOf(v);
    for (int byte = 0; byte < 8; ++byte) {
      h ^= (u >> (8 * byte)) & 0xFF;
      h *= 0x100000001B3ULL;
    }
  };
  for (int i = 0; i < n; ++i) {
    const SimulatedSample s = sim.next();
    mix(s.t_s);
    for (double r : s.rate_dps) mix(r);
    mix(s.temperature_c);
  }
  return h;
}

std::string messageOf(const SimulationModel& m) {
  try {
    validateSimulationModel(m);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// ---- validation ----------------------------------------------------------------------

TEST(NoiseSimulatorModel, RateMustBeInternalRateOverInteger) {
  SimulationModel m = pureModel(300.0);
  m.dlpf_cfg = 3;  // 1 kHz / 300 is not an integer
  const std::string msg = messageOf(m);
  EXPECT_NE(msg.find("rate_hz"), std::string::npos) << msg;
  EXPECT_NE(msg.find("1+SMPLRT_DIV"), std::string::npos) << msg;
  m.rate_hz = 1000.0 / 257.0;  // SMPLRT_DIV would be 256: not 8-bit
  EXPECT_THROW(validateSimulationModel(m), std::invalid_argument);
  m.rate_hz = 2000.0;  // faster than the internal rate
  EXPECT_THROW(validateSimulationModel(m), std::invalid_argument);
  m.rate_hz = 1000.0 / 256.0;
  EXPECT_NO_THROW(validateSimulationModel(m));
  m.dlpf_cfg = 0;  // 8 kHz internal
  m.rate_hz = 8000.0 / 3.0;
  EXPECT_NO_THROW(validateSimulationModel(m));
  m.dlpf_cfg.reset();
  m.rate_hz = 300.0;  // no DLPF: any rate
  EXPECT_NO_THROW(validateSimulationModel(m));
  m.rate_hz = 0.0;
  EXPECT_THROW(validateSimulationModel(m), std::invalid_argument);
}

TEST(NoiseSimulatorModel, BadValuesNameTheParameter) {
  SimulationModel m = pureModel();
  m.axes[1].terms.arw_deg_per_sqrt_h = -0.1;
  std::string msg = messageOf(m);
  EXPECT_NE(msg.find("axis y"), std::string::npos) << msg;
  EXPECT_NE(msg.find("arw_deg_per_sqrt_h"), std::string::npos) << msg;

  m = pureModel();
  m.axes[2].terms.bias_instability_deg_per_h = std::nan("");
  msg = messageOf(m);
  EXPECT_NE(msg.find("bias_instability_deg_per_h"), std::string::npos) << msg;

  m = pureModel();
  m.dlpf_cfg = 7;
  EXPECT_NE(messageOf(m).find("DLPF_CFG"), std::string::npos);
  m = pureModel();
  m.fs_sel = 4;
  EXPECT_NE(messageOf(m).find("FS_SEL"), std::string::npos);
  m = pureModel();
  m.temperature.time_constant_s = 0.0;
  EXPECT_NE(messageOf(m).find("temperature.time_constant_s"), std::string::npos);
  m = pureModel();
  m.axes[0].ar.noise_var = -1.0;
  EXPECT_NE(messageOf(m).find("ar.noise_var"), std::string::npos);
  EXPECT_THROW(NoiseSimulator(pureModel(), 0.0, 1), std::invalid_argument);
  EXPECT_THROW(NoiseSimulator(pureModel(100.0), 0.005, 1), std::invalid_argument);  // < 1 sample
}

TEST(NoiseSimulatorModel, NonStationaryArIsRejected) {
  SimulationModel m = pureModel();
  m.axes[0].ar.noise_var = 1.0;
  m.axes[0].ar.phi = {1.2};
  EXPECT_NE(messageOf(m).find("ar.phi"), std::string::npos);
  m.axes[0].ar.phi = {1.0};  // unit root
  EXPECT_THROW(validateSimulationModel(m), std::invalid_argument);
  // AR(2) is stationary iff φ1 + φ2 < 1, φ2 − φ1 < 1, |φ2| < 1; (0.5, 0.6) breaks the first
  // although each |φ| < 1.
  m.axes[0].ar.phi = {0.5, 0.6};
  EXPECT_THROW(validateSimulationModel(m), std::invalid_argument);
  m.axes[0].ar.phi = {0.5, 0.45};
  EXPECT_NO_THROW(validateSimulationModel(m));
  m.axes[0].ar.phi = {-0.6, -0.6};  // φ2 − φ1 = 0 < 1, φ1 + φ2 < 1, |φ2| < 1
  EXPECT_NO_THROW(validateSimulationModel(m));
  m.axes[0].ar.phi = {-1.5, -0.4};  // φ2 − φ1 = 1.1
  EXPECT_THROW(validateSimulationModel(m), std::invalid_argument);
}

// ---- reproducibility -----------------------------------------------------------------

// The sample count is 64-bit on every ABI: on 32-bit ARM a std::size_t count would wrap (armhf's
// gyroctl simulate once reported 4294967295 samples for 1e7 s at 8 kHz). Nothing is generated here.
TEST(NoiseSimulatorModel, LongSimulationsCountPast32Bits) {
  EXPECT_EQ(NoiseSimulator(pureModel(8000.0), 1e7, 1).sampleCount(), std::uint64_t{80'000'000'000});
  EXPECT_EQ(NoiseSimulator(pureModel(50.0), 1e9, 1).sampleCount(), std::uint64_t{50'000'000'000});
  EXPECT_THROW(NoiseSimulator(pureModel(8000.0), 1e15, 1), std::invalid_argument);  // past 2^53 samples
}

TEST(NoiseSimulatorStream, SameSeedSameStreamDifferentSeedsDiffer) {
  const SimulationModel m = paperSensorModel();
  NoiseSimulator a(m, 600.0, 42), b(m, 600.0, 42), c(m, 600.0, 43);
  int differing = 0;
  for (int i = 0; i < 3000; ++i) {
    const SimulatedSample sa = a.next(), sb = b.next(), sc = c.next();
    ASSERT_EQ(bitsOf(sa.t_s), bitsOf(sb.t_s));
    for (std::size_t k = 0; k < 3; ++k) {
      ASSERT_EQ(bitsOf(sa.rate_dps[k]), bitsOf(sb.rate_dps[k])) << "sample " << i;
      differing += sa.rate_dps[k] != sc.rate_dps[k];
    }
    ASSERT_EQ(bitsOf(sa.temperature_c), bitsOf(sb.temperature_c));
  }
  EXPECT_GT(differing, 3000 * 3 * 9 / 10);  // quantised, so a few may coincide
}

TEST(NoiseSimulatorStream, RegressionPinOfSeed2024) {
  // A documented regression pin (docs/simulator.md): the FNV-1a hash of the bits of the
  // first 4000 samples (t, gx, gy, gz, temp) of the paper model with seed 2024, in sensor
  // mode and in pure mode. It must be the same on x86_64 and aarch64; it changes only when
  // the simulation method deliberately changes (then update it and say so in the commit).
  NoiseSimulator sensor(paperSensorModel(), 3600.0, 2024);
  EXPECT_EQ(streamHash(sensor, 4000), 0x6AD867A8BF514EA4ULL);
  SimulationModel pure = paperSensorModel();
  pure.dlpf_cfg.reset();
  pure.fs_sel.reset();
  NoiseSimulator pure_sim(pure, 3600.0, 2024);
  EXPECT_EQ(streamHash(pure_sim, 4000), 0x74A5C9855B905423ULL);
}

TEST(NoiseSimulatorStream, TermsUseIndependentStreams) {
  // Turning one term on must not change the realisation of another: ARW alone equals
  // (ARW + ramp) − ramp sample by sample, since the ramp consumes no random numbers.
  SimulationModel a = pureModel();
  a.axes[0].terms.arw_deg_per_sqrt_h = 1.0;
  SimulationModel b = a;
  b.axes[0].terms.bias_instability_deg_per_h = 3.0;  // draws from its own stream
  b.axes[1].terms.quantization_urad = 50.0;
  NoiseSimulator sa(a, 100.0, 9), sb(b, 100.0, 9);
  SimulationModel c = a;
  c.axes[0].terms.arw_deg_per_sqrt_h = 0.0;
  c.axes[0].terms.bias_instability_deg_per_h = 3.0;
  NoiseSimulator sc(c, 100.0, 9);
  for (int i = 0; i < 2000; ++i) {
    const double arw = sa.next().rate_dps[0];
    const double both = sb.next().rate_dps[0];
    const double flicker = sc.next().rate_dps[0];
    ASSERT_NEAR(both, arw + flicker, 1e-12 * (1.0 + std::fabs(both)));
  }
}

// ---- the composition the mock device uses ----------------------------------------------

TEST(NoiseSimulatorStream, NextIsAnalogThroughDlpfDecimationAndQuantisation) {
  const SimulationModel m = paperSensorModel();
  NoiseSimulator whole(m, 600.0, 77), parts(m, 600.0, 77);
  ASSERT_EQ(parts.decimation(), 20u);  // 1 kHz / 50 Hz
  ASSERT_EQ(parts.internalRateHz(), 1000.0);
  std::vector<DigitalLowPassFilter> dlpf(3, DigitalLowPassFilter(4));
  const double lsb = 131.0;
  for (int n = 0; n < 500; ++n) {
    SimulatedSample analog;
    std::array<double, 3> filtered{};
    for (std::size_t i = 0; i < (n == 0 ? 1u : 20u); ++i) {
      analog = parts.nextAnalog();
      for (std::size_t k = 0; k < 3; ++k) {
        if (n == 0) dlpf[k].reset(analog.rate_dps[k]);
        filtered[k] = dlpf[k].update(analog.rate_dps[k]);
      }
    }
    ASSERT_DOUBLE_EQ(analog.t_s, n / 50.0);
    const std::array<double, 3> extra = parts.nextOutputRateNoise();
    const SimulatedSample s = whole.next();
    ASSERT_EQ(s.t_s, n / 50.0);
    for (std::size_t k = 0; k < 3; ++k)
      ASSERT_EQ(s.rate_dps[k], quantizeToInt16(filtered[k] + extra[k], lsb) / lsb) << "n " << n << " axis " << k;
    ASSERT_EQ(s.temperature_c, quantizeToInt16(analog.temperature_c - 36.53, 340.0) / 340.0 + 36.53);
  }
}

// ---- deterministic parts ----------------------------------------------------------------

TEST(NoiseSimulatorTerms, BiasAloneIsConstantWithAndWithoutDlpf) {
  SimulationModel m = pureModel(100.0);
  m.axes[0].bias_dps = 1.367;
  m.axes[2].bias_dps = -0.5;
  NoiseSimulator pure(m, 10.0, 1);
  m.dlpf_cfg = 6;
  NoiseSimulator filtered(m, 10.0, 1);
  for (int i = 0; i < 1000; ++i) {
    const SimulatedSample a = pure.next(), b = filtered.next();
    ASSERT_EQ(a.rate_dps[0], 1.367);
    ASSERT_EQ(a.rate_dps[1], 0.0);
    ASSERT_EQ(a.rate_dps[2], -0.5);
    ASSERT_NEAR(b.rate_dps[0], 1.367, 1e-12);  // DC gain 1, started in steady state
    ASSERT_NEAR(b.rate_dps[2], -0.5, 1e-12);
  }
}

TEST(NoiseSimulatorTerms, RateRampIsRTimesTWithSeededSign) {
  // R [°/h²] → °/s² by /3600²; rate = ±R·t exactly, sign drawn per axis from the seed.
  const double r_paper = 1000.0;
  const double r_si = r_paper / (3600.0 * 3600.0);
  int positive = 0, negative = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    SimulationModel m = pureModel(10.0);
    for (auto& axis : m.axes) axis.terms.rate_ramp_deg_per_h2 = r_paper;
    NoiseSimulator sim(m, 100.0, seed);
    std::array<double, 3> sign{};
    for (int i = 0; i < 1000; ++i) {
      const SimulatedSample s = sim.next();
      const double t = i / 10.0;
      for (std::size_t k = 0; k < 3; ++k) {
        if (i == 1) sign[k] = s.rate_dps[k] > 0 ? 1.0 : -1.0;
        if (i >= 1) {
          ASSERT_NEAR(s.rate_dps[k], sign[k] * r_si * t, 1e-15 * (1.0 + t));
        }
      }
    }
    for (double sg : sign) (sg > 0 ? positive : negative)++;
  }
  EXPECT_GT(positive, 3);  // 30 fair signs: P(≤ 3 of either) ≈ 1e-5
  EXPECT_GT(negative, 3);
}

TEST(NoiseSimulatorTerms, TemperatureFollowsWarmUpCurve) {
  SimulationModel m = pureModel(10.0);
  m.temperature = {22.0, 41.0, 300.0, 0.0};
  NoiseSimulator sim(m, 1000.0, 3);
  for (int i = 0; i < 10000; ++i) {
    const SimulatedSample s = sim.next();
    ASSERT_NEAR(s.temperature_c, 41.0 - 19.0 * std::exp(-s.t_s / 300.0), 1e-12);
  }
  // With noise: residuals have the stated standard deviation (SE of a std ≈ σ/√(2n)).
  m.temperature.noise_std_c = 0.05;
  NoiseSimulator noisy(m, 1000.0, 3);
  double sum2 = 0.0;
  const int n = 10000;
  for (int i = 0; i < n; ++i) {
    const SimulatedSample s = noisy.next();
    const double r = s.temperature_c - (41.0 - 19.0 * std::exp(-s.t_s / 300.0));
    sum2 += r * r;
  }
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.05, 5.0 * 0.05 / std::sqrt(2.0 * n));
}

TEST(NoiseSimulatorTerms, QuantisationPutsEverySampleOnTheLsbGrid) {
  for (int fs_sel : {0, 1, 2, 3}) {
    SimulationModel m = pureModel(100.0);
    m.fs_sel = fs_sel;
    m.axes[0].terms.arw_deg_per_sqrt_h = 30.0;
    m.temperature = {20.0, 45.0, 60.0, 0.3};
    const double lsb = gyroSensitivityLsbPerDps(fs_sel);
    NoiseSimulator sim(m, 100.0, 5);
    int distinct_nonzero = 0;
    for (int i = 0; i < 5000; ++i) {
      const SimulatedSample s = sim.next();
      const double counts = s.rate_dps[0] * lsb;
      ASSERT_NEAR(counts, std::round(counts), 1e-9) << "fs_sel " << fs_sel;
      distinct_nonzero += counts != 0.0;
      const double temp_counts = (s.temperature_c - 36.53) * 340.0;
      ASSERT_NEAR(temp_counts, std::round(temp_counts), 1e-6);
    }
    EXPECT_GT(distinct_nonzero, 100);
  }
}

TEST(NoiseSimulatorTerms, SaturatesAtFullScale) {
  SimulationModel m = pureModel(100.0);
  m.fs_sel = 0;  // ±250 °/s
  m.axes[0].bias_dps = 300.0;
  m.axes[1].bias_dps = -300.0;
  m.axes[2].bias_dps = 249.9;
  NoiseSimulator sim(m, 1.0, 5);
  const SimulatedSample s = sim.next();
  EXPECT_EQ(s.rate_dps[0], 32767.0 / 131.0);
  EXPECT_EQ(s.rate_dps[1], -32768.0 / 131.0);
  EXPECT_EQ(s.rate_dps[2], std::round(249.9 * 131.0) / 131.0);
  m.fs_sel = 1;  // ±500 °/s: 300 fits
  NoiseSimulator wide(m, 1.0, 5);
  EXPECT_NEAR(wide.next().rate_dps[0], 300.0, 0.5 / 65.5);
}

// ---- AR component ----------------------------------------------------------------------

namespace {
// Autocovariance γ(0..max_lag) of x_k = φ1 x_{k−1} + φ2 x_{k−2} + a_k from the
// Yule–Walker equations solved by hand: ρ1 = φ1/(1 − φ2), ρ_l = φ1 ρ_{l−1} + φ2 ρ_{l−2},
// γ0 = σa²/(1 − φ1 ρ1 − φ2 ρ2).
std::vector<double> ar2Autocovariance(double phi1, double phi2, double var, int max_lag) {
  std::vector<double> rho(static_cast<std::size_t>(max_lag) + 1);
  rho[0] = 1.0;
  rho[1] = phi1 / (1.0 - phi2);
  for (int l = 2; l <= max_lag; ++l) rho[l] = phi1 * rho[l - 1] + phi2 * rho[l - 2];
  const double gamma0 = var / (1.0 - phi1 * rho[1] - phi2 * rho[2]);
  for (double& r : rho) r *= gamma0;
  return rho;
}
}  // namespace

TEST(NoiseSimulatorTerms, ArStartsStationaryAndHasItsAutocovariance) {
  const double phi1 = 0.6, phi2 = -0.3, var = 0.0577;
  const std::vector<double> gamma = ar2Autocovariance(phi1, phi2, var, 400);
  SimulationModel m = pureModel(50.0);
  m.axes[0].ar = {{phi1, phi2}, var};
  // (1) The first sample of many seeds has variance γ0, and the first two the covariance
  //     γ1: a zero start would give σa² and 0.6·σa² instead. SE of a variance ≈ γ0·√(2/n).
  const int seeds = 4000;
  double s00 = 0.0, s01 = 0.0;
  for (int seed = 0; seed < seeds; ++seed) {
    NoiseSimulator sim(m, 1.0, static_cast<std::uint64_t>(seed));
    const double x0 = sim.next().rate_dps[0], x1 = sim.next().rate_dps[0];
    s00 += x0 * x0;
    s01 += x0 * x1;
  }
  EXPECT_NEAR(s00 / seeds, gamma[0], 5.0 * gamma[0] * std::sqrt(2.0 / seeds));
  EXPECT_NEAR(s01 / seeds, gamma[1], 5.0 * gamma[0] * std::sqrt(2.0 / seeds));
  // (2) A long series has the theoretical autocorrelation at lags 1..3, within 5 of
  //     Bartlett's standard errors.
  const int n = 200000;
  NoiseSimulator sim(m, n / 50.0, 11);
  std::vector<double> x(n);
  for (double& v : x) v = sim.next().rate_dps[0];
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= n;
  auto acov = [&](int lag) {
    double s = 0.0;
    for (int i = 0; i + lag < n; ++i) s += (x[i] - mean) * (x[i + lag] - mean);
    return s / n;
  };
  const double c0 = acov(0);
  EXPECT_NEAR(c0, gamma[0], 5.0 * gamma[0] * std::sqrt(4.0 / n));  // generous: correlated samples
  for (int lag = 1; lag <= 3; ++lag) {
    auto rho = [&](int l) { return gamma[static_cast<std::size_t>(std::abs(l))] / gamma[0]; };
    double bartlett = 0.0;
    for (int j = -190; j <= 190; ++j)
      bartlett += rho(j) * rho(j) + rho(j + lag) * rho(j - lag) - 4.0 * rho(lag) * rho(j) * rho(j - lag) +
                  2.0 * rho(lag) * rho(lag) * rho(j) * rho(j);
    EXPECT_NEAR(acov(lag) / c0, rho(lag), 5.0 * std::sqrt(bartlett / n)) << "lag " << lag;
  }
}

TEST(NoiseSimulatorTerms, ArOfOrderZeroIsWhiteNoise) {
  SimulationModel m = pureModel(50.0);
  m.axes[2].ar = {{}, 0.25};
  const int n = 100000;
  NoiseSimulator sim(m, n / 50.0, 4);
  double s2 = 0.0, s11 = 0.0, prev = 0.0;
  for (int i = 0; i < n; ++i) {
    const double v = sim.next().rate_dps[2];
    s2 += v * v;
    s11 += v * prev;
    prev = v;
  }
  EXPECT_NEAR(s2 / n, 0.25, 5.0 * 0.25 * std::sqrt(2.0 / n));
  EXPECT_NEAR(s11 / n, 0.0, 5.0 * 0.25 / std::sqrt(n));
}
