// The simulator's narrowband lines (AxisExtraEffects::narrowband_lines): a simulated line has
// the variance, centre and width it was given, its spectral density integrates to its
// variance, it is added to the noise without changing the noise's realisation, and a line on
// one axis leaves another axis's samples bit for bit alone when that axis draws no random
// numbers of the extras' generator (see docs/simulator.md "Random numbers").
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "processing/simulation/narrowband_line.hpp"
#include "processing/simulation/noise_simulator.hpp"
#include "welch_psd.hpp"

using namespace gyrod::processing;

namespace {

// The line of real MPU6050 records that the brief of the model check names: 31.4 Hz, 0.3 Hz
// wide, 0.02 °/s rms, on white noise two orders of magnitude below it in density.
constexpr double kNbSimRate = 100.0;
constexpr NarrowbandLine kNbSimLine{31.4, 0.3, 0.02};
constexpr double kNbSimArw = 0.05;  // °/√h: one-sided density 2·(0.05/60)² ≈ 1.4e-6 (°/s)²/Hz

SimulationModel nbSimWhiteNoiseModel() {
  SimulationModel m;
  m.rate_hz = kNbSimRate;
  for (AxisNoiseModel& axis : m.axes) axis.terms.arw_deg_per_sqrt_h = kNbSimArw;
  return m;
}

// n samples of one axis.
std::vector<double> nbSimAxis(const SimulationModel& m, double duration_s, std::uint64_t seed, std::size_t axis) {
  NoiseSimulator sim(m, duration_s, seed);
  std::vector<double> out(sim.sampleCount());
  for (double& v : out) v = sim.next().rate_dps[axis];
  return out;
}

// Σ_{k=−∞}^{∞} ρ_k² of the line's AR(2) (ρ_0 = 1, ρ_1 = a1/(1 − a2), ρ_k = a1·ρ_{k−1} + a2·ρ_{k−2}):
// the sample variance of n samples of a Gaussian process has variance 2σ⁴·Σρ_k²/n.
double nbSimSumOfSquaredAutocorrelations(const NarrowbandLineRecursion& r) {
  double before = 1.0, previous = r.a1 / (1.0 - r.a2);
  double sum = 1.0 + 2.0 * previous * previous;
  for (int k = 2; k < 1000000; ++k) {
    const double rho = r.a1 * previous + r.a2 * before;
    sum += 2.0 * rho * rho;
    before = previous;
    previous = rho;
    if (std::fabs(rho) < 1e-12 && std::fabs(before) < 1e-12) break;
  }
  return sum;
}

}  // namespace

TEST(NarrowbandLineSimulation, LineHasItsVarianceCentreAndWidth) {
  // One hour at 100 Hz; the line alone is the run with it minus the run without (pure mode:
  // the extras draw from a generator of their own, so the difference is the line to rounding).
  const double duration = 3600.0;
  SimulationModel with = nbSimWhiteNoiseModel();
  with.axes[1].extra.narrowband_lines = {kNbSimLine};
  const std::vector<double> total = nbSimAxis(with, duration, 77, 1);
  const std::vector<double> noise = nbSimAxis(nbSimWhiteNoiseModel(), duration, 77, 1);
  ASSERT_EQ(total.size(), noise.size());
  const double n = static_cast<double>(total.size());

  // Variance of the line component against rms², within 4 standard deviations of the
  // sample variance (≈ 1.7 % here: the line's correlation time is ~1 s, so 3600 s hold only
  // a few thousand independent values).
  double mean = 0.0;
  for (std::size_t i = 0; i < total.size(); ++i) mean += total[i] - noise[i];
  mean /= n;
  double variance = 0.0;
  for (std::size_t i = 0; i < total.size(); ++i)
    variance += (total[i] - noise[i] - mean) * (total[i] - noise[i] - mean);
  variance /= n - 1.0;
  const double rms2 = kNbSimLine.rms_dps * kNbSimLine.rms_dps;
  const NarrowbandLineRecursion recursion = narrowbandLineRecursion(kNbSimLine, kNbSimRate);
  const double sd_variance = rms2 * std::sqrt(2.0 * nbSimSumOfSquaredAutocorrelations(recursion) / n);
  EXPECT_NEAR(variance, rms2, 4.0 * sd_variance) << "sd of the sample variance " << sd_variance;
  EXPECT_LT(sd_variance / rms2, 0.03);  // "within a few %" is what 4 sd amounts to

  // The whole stream's Welch spectrum (4096-sample segments: 0.024 Hz bins, 174 segments, so
  // one bin scatters by ~8 % and the three-bin peak by ~5 %). The peak is the largest three-bin
  // mean (a single bin 0.05 Hz off the centre is still 88 % of the peak density, within the
  // scatter); the centre the midpoint of the half-power points, whose common error (the peak
  // level) cancels; the width their distance.
  const gyrod::test::WelchSpectrum spectrum = gyrod::test::welchPsd(total, kNbSimRate, 4096);
  const gyrod::test::SpectralPeak peak = gyrod::test::spectralPeakNear(spectrum, kNbSimLine.centre_hz, 2.0);
  EXPECT_NEAR(peak.centreHz(), kNbSimLine.centre_hz, 0.05);
  EXPECT_NEAR(peak.max_bin_hz, kNbSimLine.centre_hz, 0.05);
  EXPECT_GT(peak.widthHz(), kNbSimLine.width_hz / 1.3);
  EXPECT_LT(peak.widthHz(), kNbSimLine.width_hz * 1.3);
  // Its level against the theory: the one-sided density at the centre, 2·rms²/(π·width) for
  // a line narrow against the rate (Lorentzian), within 25 % (three-bin mean ± 3 sd).
  EXPECT_NEAR(peak.level / narrowbandLinePsd(recursion, kNbSimRate, kNbSimLine.centre_hz), 1.0, 0.25);
  RecordProperty("line_variance_over_rms2", std::to_string(variance / rms2));
  RecordProperty("line_centre_hz", std::to_string(peak.centreHz()));
  RecordProperty("line_width_hz", std::to_string(peak.widthHz()));
}

TEST(NarrowbandLineSimulation, PsdIntegratesToTheVariance) {
  // Simpson over [0, rate/2] on a grid fine against the width (0.3 Hz = 1200 steps).
  for (const NarrowbandLine line : {kNbSimLine, NarrowbandLine{2.0, 0.05, 0.3}, NarrowbandLine{45.0, 4.0, 1.0}}) {
    const NarrowbandLineRecursion r = narrowbandLineRecursion(line, kNbSimRate);
    const int steps = 200000;  // even
    const double h = (kNbSimRate / 2.0) / steps;
    double sum = narrowbandLinePsd(r, kNbSimRate, 0.0) + narrowbandLinePsd(r, kNbSimRate, kNbSimRate / 2.0);
    for (int i = 1; i < steps; ++i) sum += (i % 2 ? 4.0 : 2.0) * narrowbandLinePsd(r, kNbSimRate, i * h);
    EXPECT_NEAR(sum * h / 3.0, line.rms_dps * line.rms_dps, 1e-3 * line.rms_dps * line.rms_dps)
        << "centre " << line.centre_hz;
  }
}

TEST(NarrowbandLineSimulation, AddingALineLeavesTheNoiseRealisationAlone) {
  // (noise + line) − noise = the line alone, sample by sample, in pure mode.
  SimulationModel base = nbSimWhiteNoiseModel();
  for (AxisNoiseModel& axis : base.axes) axis.terms.bias_instability_deg_per_h = 8.0;
  SimulationModel with = base;
  with.axes[2].extra.narrowband_lines = {kNbSimLine, {12.0, 0.5, 0.1}};
  SimulationModel only;
  only.rate_hz = kNbSimRate;
  only.axes[2].extra = with.axes[2].extra;
  NoiseSimulator a(base, 100.0, 13), b(with, 100.0, 13), c(only, 100.0, 13);
  for (int i = 0; i < 5000; ++i) {
    const SimulatedSample sa = a.next(), sb = b.next(), sc = c.next();
    for (std::size_t k = 0; k < kSimulatedAxes; ++k)
      ASSERT_NEAR(sb.rate_dps[k], sa.rate_dps[k] + sc.rate_dps[k], 1e-12) << "sample " << i << " axis " << k;
    ASSERT_EQ(sb.temperature_c, sa.temperature_c);
  }
}

TEST(NarrowbandLineSimulation, LineOnYLeavesAxesWithoutRandomExtrasBitIdentical) {
  // The extras' generator is shared by the axes, so what holds is: a line on y changes no
  // sample of an axis whose own extras draw no random numbers (none, a sinusoid, steps,
  // temperature coupling; not a Gauss–Markov process or other lines). Sensor mode, so the
  // DLPF and the quantisation are in the comparison too.
  SimulationModel base = nbSimWhiteNoiseModel();
  base.dlpf_cfg = 3;  // 1 kHz internal, 100 Hz out
  base.fs_sel = 0;
  base.temperature = {24.0, 38.0, 300.0, 0.02};
  base.axes[0].extra.sinusoids = {{1.5, 0.2, 0.3}};
  SimulationModel with = base;
  with.axes[1].extra.narrowband_lines = {kNbSimLine};
  NoiseSimulator a(base, 120.0, 5), b(with, 120.0, 5);
  std::size_t y_differs = 0;
  for (std::uint64_t i = 0; i < a.sampleCount(); ++i) {
    const SimulatedSample sa = a.next(), sb = b.next();
    ASSERT_EQ(std::memcmp(&sa.rate_dps[0], &sb.rate_dps[0], sizeof(double)), 0) << "x at sample " << i;
    ASSERT_EQ(std::memcmp(&sa.rate_dps[2], &sb.rate_dps[2], sizeof(double)), 0) << "z at sample " << i;
    ASSERT_EQ(std::memcmp(&sa.temperature_c, &sb.temperature_c, sizeof(double)), 0) << "temperature at " << i;
    y_differs += sa.rate_dps[1] != sb.rate_dps[1];
  }
  EXPECT_GT(y_differs, a.sampleCount() / 2);  // 0.02 °/s rms against a 1/131 °/s LSB
}

TEST(NarrowbandLineSimulation, WithoutLinesTheStreamIsTheOneWithoutExtras) {
  // An empty list draws nothing: the stream is the one of a model without the field set.
  SimulationModel base = nbSimWhiteNoiseModel();
  base.axes[0].extra.gauss_markov_tau_s = 2.0;
  base.axes[0].extra.gauss_markov_sigma_dps = 0.01;
  SimulationModel with_empty = base;
  with_empty.axes[1].extra.narrowband_lines = {};
  NoiseSimulator a(base, 60.0, 3), b(with_empty, 60.0, 3);
  for (std::uint64_t i = 0; i < a.sampleCount(); ++i) {
    const SimulatedSample sa = a.next(), sb = b.next();
    ASSERT_EQ(std::memcmp(sa.rate_dps.data(), sb.rate_dps.data(), sizeof sa.rate_dps), 0) << "sample " << i;
  }
}

TEST(NarrowbandLineSimulation, BadLinesAreRejectedNamingTheKey) {
  const auto messageOf = [](const SimulationModel& m) -> std::string {
    try {
      NoiseSimulator sim(m, 10.0, 1);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  SimulationModel m = nbSimWhiteNoiseModel();
  m.axes[1].extra.narrowband_lines = {kNbSimLine, {60.0, 0.3, 0.02}};  // above rate/2 = 50
  EXPECT_EQ(messageOf(m), "axis y: extra.narrowband_line[1].centre_hz must be in (0, rate/2 = 50), got 60");
  EXPECT_THROW(validateSimulationModel(m), std::invalid_argument);
  m.axes[1].extra.narrowband_lines = {{31.4, 0.0, 0.02}};
  EXPECT_EQ(messageOf(m), "axis y: extra.narrowband_line[0].width_hz must be finite and > 0, got 0");
  m.axes[1].extra.narrowband_lines = {{31.4, 0.3, -0.02}};
  EXPECT_EQ(messageOf(m), "axis y: extra.narrowband_line[0].rms_dps must be finite and >= 0, got -0.02");
  m.axes[1].extra.narrowband_lines = {{-1.0, 0.3, 0.02}};
  EXPECT_EQ(messageOf(m), "axis y: extra.narrowband_line[0].centre_hz must be finite and > 0, got -1");
  // validateExtraEffects alone (no rate) checks what it can.
  AxisExtraEffects e;
  e.narrowband_lines = {{60.0, 0.3, 0.02}};
  EXPECT_NO_THROW(validateExtraEffects(e, "y."));
  e.narrowband_lines = {{60.0, std::nan(""), 0.02}};
  EXPECT_THROW(validateExtraEffects(e, "y."), std::invalid_argument);
}
