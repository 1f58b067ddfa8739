// Motion profiles (true rates) and the simulator turned by them: each built-in against its
// definition, the table's interpolation, the angle of the turns, the errors naming the bad
// parameter, and the simulator's motion path (DLPF, saturation, truth, no change at rest).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <numbers>
#include <stdexcept>
#include <string>

#include "processing/simulation/motion_profile.hpp"
#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod::processing;

namespace {

std::string profileMessageOf(auto&& make) {
  try {
    make();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// ∫ ω dt on `axis` from 0 to t_end by the midpoint rule on a fine grid.
double integrateAngle(const MotionProfile& p, std::size_t axis, double t_end, double dt = 1e-4) {
  double angle = 0.0;
  for (double t = 0.5 * dt; t < t_end; t += dt) angle += p.rateAt(t)[axis] * dt;
  return angle;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST(MotionProfile, RestIsZeroEverywhere) {
  const MotionProfile rest;
  EXPECT_TRUE(rest.atRest());
  for (double t : {-1.0, 0.0, 3.5, 1e6}) EXPECT_EQ(rest.rateAt(t), (AngularRate{0.0, 0.0, 0.0}));
}

TEST(MotionProfile, StepConstantSineFollowTheirDefinitions) {
  const MotionProfile step = MotionProfile::step(1, 2.0, 10.0);
  EXPECT_EQ(step.rateAt(1.999)[1], 0.0);
  EXPECT_EQ(step.rateAt(2.0)[1], 10.0);
  EXPECT_EQ(step.rateAt(2.0)[0], 0.0);
  const MotionProfile constant = MotionProfile::constant(2, -3.0, 1.0, 2.0);
  EXPECT_EQ(constant.rateAt(0.5)[2], 0.0);
  EXPECT_EQ(constant.rateAt(1.0)[2], -3.0);
  EXPECT_EQ(constant.rateAt(2.999)[2], -3.0);
  EXPECT_EQ(constant.rateAt(3.0)[2], 0.0);
  const MotionProfile sine = MotionProfile::sine(0, 1.5, 20.0, 0.25);
  for (double t = 0.25; t < 5.0; t += 0.0137)
    EXPECT_NEAR(sine.rateAt(t)[0], 20.0 * std::sin(2.0 * std::numbers::pi * 1.5 * (t - 0.25)), 1e-12) << t;
  EXPECT_EQ(sine.rateAt(0.2)[0], 0.0);
}

TEST(MotionProfile, TableInterpolatesLinearlyAndHoldsItsEnds) {
  const MotionProfile table =
      MotionProfile::table({{0.0, {0.0, 1.0, 2.0}}, {1.0, {10.0, 1.0, -2.0}}, {3.0, {10.0, 5.0, 0.0}}});
  EXPECT_EQ(table.rateAt(-1.0), (AngularRate{0.0, 1.0, 2.0}));
  const AngularRate mid = table.rateAt(0.25);
  EXPECT_DOUBLE_EQ(mid[0], 2.5);
  EXPECT_DOUBLE_EQ(mid[1], 1.0);
  EXPECT_DOUBLE_EQ(mid[2], 1.0);
  EXPECT_DOUBLE_EQ(table.rateAt(2.0)[1], 3.0);
  EXPECT_EQ(table.rateAt(100.0), (AngularRate{10.0, 5.0, 0.0}));
  EXPECT_EQ(table.settledFrom(), 3.0);
}

TEST(MotionProfile, TurnsTurnTheStatedAngleWithStillPeriods) {
  const MotionProfile turns = MotionProfile::turns(2, 2.5, -90.0, 1.0, 0.5);
  EXPECT_EQ(turns.rateAt(1.2)[2], 0.0);    // first still period: 0.5 .. 1.5
  EXPECT_EQ(turns.rateAt(1.6)[2], -90.0);  // first turn: 1.5 .. 5.5
  EXPECT_EQ(turns.rateAt(5.9)[2], 0.0);    // still: 5.5 .. 6.5
  const double end = turns.settledFrom();
  EXPECT_DOUBLE_EQ(end, 0.5 + 2 * (1.0 + 4.0) + 1.0 + 0.5 * 4.0);  // the half turn ends it
  EXPECT_EQ(turns.rateAt(end - 0.01)[2], -90.0);
  EXPECT_NEAR(integrateAngle(turns, 2, end + 2.0), -900.0, 0.02);
  EXPECT_EQ(turns.rateAt(end + 1.0)[2], 0.0);
}

TEST(MotionProfile, SumAddsAndSequenceRunsEachOnItsOwnClock) {
  const MotionProfile sum = MotionProfile::sum(
      {MotionProfile::constant(0, 1.0), MotionProfile::step(0, 1.0, 2.0), MotionProfile::step(1, 0.0, 4.0)});
  EXPECT_EQ(sum.rateAt(0.5), (AngularRate{1.0, 4.0, 0.0}));
  EXPECT_EQ(sum.rateAt(1.5), (AngularRate{3.0, 4.0, 0.0}));
  const MotionProfile seq = MotionProfile::sequence(
      {{MotionProfile{}, 2.0}, {MotionProfile::step(1, 0.5, 7.0), 1.0}, {MotionProfile::constant(2, 3.0), 1.0}});
  EXPECT_EQ(seq.rateAt(1.0), (AngularRate{0.0, 0.0, 0.0}));
  EXPECT_EQ(seq.rateAt(2.4)[1], 0.0);  // the step's own t = 0.4
  EXPECT_EQ(seq.rateAt(2.6)[1], 7.0);
  EXPECT_EQ(seq.rateAt(3.5), (AngularRate{0.0, 0.0, 3.0}));
  EXPECT_EQ(seq.rateAt(4.0), (AngularRate{0.0, 0.0, 0.0}));
  EXPECT_EQ(seq.settledFrom(), 4.0);
}

TEST(MotionProfile, BadParametersNameTheParameterAndValue) {
  std::string msg = profileMessageOf([] { MotionProfile::sine(0, -1.0, 20.0); });
  EXPECT_NE(msg.find("sine.frequency_hz"), std::string::npos) << msg;
  EXPECT_NE(msg.find("-1"), std::string::npos) << msg;
  msg = profileMessageOf([] { MotionProfile::sine(0, 1.0, -2.0); });
  EXPECT_NE(msg.find("sine.amplitude_dps"), std::string::npos) << msg;
  msg = profileMessageOf([] { MotionProfile::turns(0, 0.0, 90.0, 1.0); });
  EXPECT_NE(msg.find("turns.count"), std::string::npos) << msg;
  msg = profileMessageOf([] { MotionProfile::turns(0, 3.0, 0.0, 1.0); });
  EXPECT_NE(msg.find("turns.rate_dps"), std::string::npos) << msg;
  msg = profileMessageOf([] { MotionProfile::step(3, 0.0, 1.0); });
  EXPECT_NE(msg.find("step.axis"), std::string::npos) << msg;
  msg = profileMessageOf([] { MotionProfile::constant(0, std::nan(""), 0.0); });
  EXPECT_NE(msg.find("constant.rate_dps"), std::string::npos) << msg;
  msg = profileMessageOf([] { MotionProfile::table({{0.0, {}}, {0.0, {}}}); });
  EXPECT_NE(msg.find("table point 1: t"), std::string::npos) << msg;
  msg = profileMessageOf([] { MotionProfile::table({}); });
  EXPECT_NE(msg.find("table"), std::string::npos) << msg;
  msg = profileMessageOf([] {
    MotionProfile::sequence({{MotionProfile{}, MotionProfile::kForever}, {MotionProfile{}, 1.0}});
  });
  EXPECT_NE(msg.find("sequence segment 0"), std::string::npos) << msg;
  msg = profileMessageOf([] { MotionProfile::sequence({{MotionProfile{}, -1.0}}); });
  EXPECT_NE(msg.find("sequence segment 0: duration_s"), std::string::npos) << msg;
}

// ---- the simulator with motion ------------------------------------------------------

namespace {

SimulationModel chipModel() {
  SimulationModel m;
  m.rate_hz = 50.0;
  m.dlpf_cfg = 4;
  m.fs_sel = 0;
  for (auto& axis : m.axes) {
    axis.terms.arw_deg_per_sqrt_h = 0.95;
    axis.terms.bias_instability_deg_per_h = 0.6;
  }
  m.axes[0].bias_dps = 1.367;
  m.temperature = {24.0, 38.0, 900.0, 0.02};
  return m;
}

}  // namespace

TEST(NoiseSimulatorMotion, AtRestTheStreamIsBitForBitTheOneWithoutMotion) {
  NoiseSimulator plain(chipModel(), 20.0, 42);
  NoiseSimulator rest(chipModel(), 20.0, 42, MotionProfile{});
  for (int i = 0; i < 1000; ++i) {
    const SimulatedSample a = plain.next(), b = rest.next();
    for (std::size_t k = 0; k < kSimulatedAxes; ++k) ASSERT_TRUE(sameBits(a.rate_dps[k], b.rate_dps[k])) << i;
    ASSERT_TRUE(sameBits(a.temperature_c, b.temperature_c));
    ASSERT_EQ(b.true_rate_dps, (std::array<double, 3>{0.0, 0.0, 0.0}));
  }
}

TEST(NoiseSimulatorMotion, MotionGoesThroughTheDlpfOntoTheSameNoise) {
  SimulationModel m = chipModel();
  m.fs_sel.reset();  // no rounding, so the difference is the filtered motion alone
  const MotionProfile motion =
      MotionProfile::sum({MotionProfile::step(1, 1.01, 10.0), MotionProfile::sine(2, 1.0, 20.0)});
  NoiseSimulator plain(m, 20.0, 7);
  NoiseSimulator moving(m, 20.0, 7, motion);
  const DigitalLowPassFilter dlpf(4);
  double max_sine_error = 0.0;
  for (int i = 0; i < 1000; ++i) {
    const SimulatedSample a = plain.next(), b = moving.next();
    ASSERT_EQ(b.true_rate_dps[1], motion.rateAt(b.t_s)[1]);
    ASSERT_EQ(b.true_rate_dps[2], motion.rateAt(b.t_s)[2]);
    EXPECT_TRUE(sameBits(a.rate_dps[0], b.rate_dps[0]));  // the still axis is untouched
    const double step_seen = b.rate_dps[1] - a.rate_dps[1];
    if (b.t_s < 1.0) {
      EXPECT_NEAR(step_seen, 0.0, 1e-12);
    }
    if (b.t_s > 1.2) {
      EXPECT_NEAR(step_seen, 10.0, 1e-9);  // settled: the DLPF's DC gain is 1
    }
    if (b.t_s > 1.0) {
      // The 1 Hz sine comes out as |H(1 Hz)|·sin(2πt + arg H) at the output instants.
      const std::complex<double> h = dlpf.frequencyResponse(1.0);
      const double expected = 20.0 * std::abs(h) * std::sin(2.0 * std::numbers::pi * b.t_s + std::arg(h));
      max_sine_error = std::max(max_sine_error, std::fabs(b.rate_dps[2] - a.rate_dps[2] - expected));
    }
  }
  EXPECT_LT(max_sine_error, 1e-6);
}

TEST(NoiseSimulatorMotion, FullScaleSaturatesAndQuantisesTheMotion) {
  SimulationModel m = chipModel();  // FS_SEL 0: ±250 °/s, 131 LSB per °/s
  NoiseSimulator sim(m, 10.0, 3, MotionProfile::constant(2, 400.0));
  for (int i = 0; i < 100; ++i) {
    const SimulatedSample s = sim.next();
    EXPECT_EQ(s.rate_dps[2], 32767.0 / 131.0);
    EXPECT_EQ(s.true_rate_dps[2], 400.0);
    EXPECT_EQ(std::round(s.rate_dps[1] * 131.0), s.rate_dps[1] * 131.0);
  }
}
