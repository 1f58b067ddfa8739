// The daemon's per-sample pipeline runs exactly the offline chain of `gyroctl filter`
// (identifyFilterChain + AxisFilterChain) on raw − bias, and its rolling Allan statistics
// equal the batch computation on the same samples.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <optional>
#include <random>
#include <vector>

#include "daemon/sample_pipeline.hpp"
#include "processing/allan/allan.hpp"

using namespace gyrod::daemon;
using namespace gyrod::processing;

namespace {

struct Stream {
  std::array<std::vector<double>, kAxes> x;
};

Stream noisyStream(std::size_t n, unsigned seed, const Vec3& bias) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Stream s;
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    double walk = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      walk += 0.001 * noise(rng);
      double v = bias[axis] + walk + noise(rng);
      if (u(rng) < 0.01) v += 1.5;  // gross errors for the mean filter to reject
      s.x[axis].push_back(v);
    }
  }
  return s;
}

PipelineSettings baseSettings() {
  PipelineSettings p;
  p.rate_hz = 50.0;
  p.allan_window_samples = 2048;
  return p;
}

}  // namespace

TEST(SamplePipeline, ConfiguredBiasAndKalmanRunTheOfflineChainFromTheFirstSample) {
  const Vec3 bias{1.5, -0.25, 0.125};
  const Stream s = noisyStream(3000, 1, bias);
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Config;
  p.bias_dps = bias;
  p.kalman = {-0.2855, 0.0577, 0.0667};
  SamplePipeline pipeline(p);
  EXPECT_EQ(pipeline.phase(), PipelinePhase::Running);
  EXPECT_FALSE(pipeline.kalmanIdentified());

  std::array<AxisFilterChain, kAxes> reference = {AxisFilterChain({20, 0.3, {-0.2855, 0.0577, 0.0667, 0.0, {}}}),
                                                  AxisFilterChain({20, 0.3, {-0.2855, 0.0577, 0.0667, 0.0, {}}}),
                                                  AxisFilterChain({20, 0.3, {-0.2855, 0.0577, 0.0667, 0.0, {}}})};
  for (std::size_t i = 0; i < 3000; ++i) {
    const Vec3 raw{s.x[0][i], s.x[1][i], s.x[2][i]};
    const ProcessedSample out = pipeline.process(i, i / 50.0, raw, 30.0);
    ASSERT_TRUE(out.filtered);
    EXPECT_EQ(out.raw, raw);
    for (std::size_t axis = 0; axis < kAxes; ++axis) {
      const FilteredRate f = reference[axis].update(raw[axis] - bias[axis]);
      ASSERT_EQ(out.mean[axis], f.mean_dps) << i;
      ASSERT_EQ(out.kalman[axis], f.kalman_dps) << i;
    }
  }
}

TEST(SamplePipeline, EstimatesBiasAndIdentifiesKalmanOverTheStillPeriod) {
  const Vec3 bias{0.75, -1.0, 2.0};
  const Stream s = noisyStream(2000, 2, bias);
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Estimate;
  p.still_seconds = 10.0;  // 500 samples
  p.kalman.r = 0.05;       // R given, A and Q identified
  SamplePipeline pipeline(p);
  EXPECT_EQ(pipeline.phase(), PipelinePhase::Estimating);
  for (std::size_t i = 0; i < 500; ++i) {
    const ProcessedSample out = pipeline.process(i, i / 50.0, {s.x[0][i], s.x[1][i], s.x[2][i]}, 25.0);
    EXPECT_EQ(out.filtered, false);
  }
  ASSERT_EQ(pipeline.phase(), PipelinePhase::Running);
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    std::vector<double> still(s.x[axis].begin(), s.x[axis].begin() + 500);
    double mean = 0.0;
    for (double v : still) mean += v;
    mean /= 500.0;
    EXPECT_NEAR(pipeline.bias()[axis], mean, 1e-12);
    for (double& v : still) v -= pipeline.bias()[axis];
    const FilterChainParameters expected = identifyFilterChain(still, 20, 0.3, {std::nullopt, std::nullopt, 0.05});
    EXPECT_EQ(pipeline.filterParameters()[axis].kalman.a, expected.kalman.a);
    EXPECT_EQ(pipeline.filterParameters()[axis].kalman.q, expected.kalman.q);
    EXPECT_EQ(pipeline.filterParameters()[axis].kalman.r, 0.05);
  }
}

TEST(SamplePipeline, FilteredOutputAfterEstimationEqualsTheOfflineChain) {
  const Vec3 bias{0.5, 0.5, 0.5};
  const Stream s = noisyStream(1500, 3, bias);
  PipelineSettings p = baseSettings();
  p.still_seconds = 4.0;  // 200 samples
  SamplePipeline pipeline(p);
  std::vector<ProcessedSample> outs;
  for (std::size_t i = 0; i < 1500; ++i)
    outs.push_back(pipeline.process(i, i / 50.0, {s.x[0][i], s.x[1][i], s.x[2][i]}, 25.0));
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    AxisFilterChain reference(pipeline.filterParameters()[axis]);
    for (std::size_t i = 200; i < 1500; ++i) {
      ASSERT_TRUE(outs[i].filtered);
      const FilteredRate f = reference.update(s.x[axis][i] - pipeline.bias()[axis]);
      ASSERT_EQ(outs[i].kalman[axis], f.kalman_dps) << "axis " << axis << " sample " << i;
    }
  }
}

TEST(SamplePipeline, RollingAllanEqualsBatchOnTheWindow) {
  const Stream s = noisyStream(5000, 4, {0.1, 0.2, 0.3});
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Config;
  p.kalman = {0.5, 0.01, 0.02};
  SamplePipeline pipeline(p);
  std::vector<double> kalman_x;
  for (std::size_t i = 0; i < 5000; ++i)
    kalman_x.push_back(pipeline.process(i, i / 50.0, {s.x[0][i], s.x[1][i], s.x[2][i]}, 25.0).kalman[0]);
  const AllanStreams a = pipeline.allanSnapshot();
  EXPECT_DOUBLE_EQ(a.window_s, 2048 / 50.0);
  const std::span<const double> last_raw(s.x[0].data() + 5000 - 2048, 2048);
  const std::span<const double> last_kalman(kalman_x.data() + 5000 - 2048, 2048);
  ASSERT_FALSE(a.raw[0].window.empty());
  for (const AllanPoint& pt : a.raw[0].window)
    EXPECT_NEAR(pt.oadev, std::sqrt(overlappingAllanVariance(last_raw, pt.m)), 1e-9 * pt.oadev) << pt.m;
  for (const AllanPoint& pt : a.kalman[0].window)
    EXPECT_NEAR(pt.oadev, std::sqrt(overlappingAllanVariance(last_kalman, pt.m)), 1e-9 * pt.oadev) << pt.m;
  for (const AllanPoint& pt : a.raw[1].since_start)
    EXPECT_NEAR(pt.oadev, std::sqrt(overlappingAllanVariance(s.x[1], pt.m)), 1e-9 * pt.oadev) << pt.m;
  pipeline.refitNoiseTerms();
  ASSERT_TRUE(pipeline.noiseTerms()[0].has_value());
  // The stream is white noise plus 1 % spikes plus a slow walk: its white level σ is
  // estimated from first differences (var(Δx) = 2σ² for white noise), N = 60·σ·√τ0 °/√h.
  const std::span<const double> w = last_raw;
  double sd = 0.0;
  for (std::size_t i = 1; i < w.size(); ++i) sd += (w[i] - w[i - 1]) * (w[i] - w[i - 1]);
  const double n_expected = 60.0 * std::sqrt(sd / (w.size() - 1) / 2.0) * std::sqrt(0.02);
  EXPECT_NEAR(pipeline.noiseTerms()[0]->value.arw_deg_per_sqrt_h, n_expected, 0.15 * n_expected);
}

TEST(SamplePipeline, DiscontinuityRestartsTheFiltersButNotTheStatistics) {
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Config;
  p.kalman = {0.9, 0.001, 0.1};
  SamplePipeline pipeline(p);
  for (int i = 0; i < 100; ++i) pipeline.process(i, i / 50.0, {1.0, 1.0, 1.0}, 25.0);
  pipeline.discontinuity();
  const ProcessedSample after = pipeline.process(105, 2.1, {-2.0, 0.0, 0.0}, 25.0);
  // A fresh chain returns its first input: x̂0 = the first mean-filter output = the sample.
  EXPECT_EQ(after.kalman[0], -2.0);
  EXPECT_EQ(after.mean[0], -2.0);
  EXPECT_EQ(pipeline.samplesProcessed(), 101u);
}

TEST(SamplePipeline, ReloadKeepsTheStreamAndAppliesNewParameters) {
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Config;
  p.kalman = {0.9, 0.001, 0.1};
  SamplePipeline pipeline(p);
  for (int i = 0; i < 50; ++i) pipeline.process(i, i / 50.0, {0.1, 0.2, 0.3}, 25.0);
  pipeline.reloadFilter(5, 0.5, {0.5, std::nullopt, std::nullopt});
  EXPECT_EQ(pipeline.filterParameters()[0].mean_window, 5u);
  EXPECT_EQ(pipeline.filterParameters()[0].kalman.a, 0.5);
  EXPECT_EQ(pipeline.filterParameters()[0].kalman.q, 0.001);
  EXPECT_EQ(pipeline.samplesProcessed(), 50u);
  EXPECT_THROW(pipeline.reloadFilter(0, 0.5, {}), std::invalid_argument);
  EXPECT_EQ(pipeline.filterParameters()[0].mean_window, 5u);  // a bad reload changes nothing
}

TEST(SamplePipeline, SettingsThatCannotWorkAreRefused) {
  PipelineSettings p = baseSettings();
  p.still_seconds = 1.0;  // 50 samples: too few to identify A and Q
  EXPECT_THROW(SamplePipeline{p}, std::invalid_argument);
  p.still_seconds = 1.0;
  p.kalman = {0.5, 0.01, 0.02};
  EXPECT_NO_THROW(SamplePipeline{p});  // bias only: 50 samples are enough
  p.rate_hz = 0.0;
  EXPECT_THROW(SamplePipeline{p}, std::invalid_argument);
  p = baseSettings();
  p.mean_window = 0;
  EXPECT_THROW(SamplePipeline{p}, std::invalid_argument);
}

TEST(SamplePipeline, ABadKalmanReloadChangesNothing) {
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Config;
  p.kalman = {0.9, 0.001, 0.1};
  SamplePipeline pipeline(p);
  for (int i = 0; i < 50; ++i) pipeline.process(i, i / 50.0, {0.1, 0.2, 0.3}, 25.0);
  EXPECT_THROW(pipeline.reloadFilter(5, 0.5, {0.5, std::nullopt, -1.0}), std::invalid_argument);
  EXPECT_EQ(pipeline.filterParameters()[0].mean_window, 20u);
  EXPECT_EQ(pipeline.filterParameters()[0].kalman.a, 0.9);
  EXPECT_EQ(pipeline.filterParameters()[0].kalman.r, 0.1);
}

namespace {

// A sensor model with a temperature term and a warm-up shape, so that b̂ moves.
RateEstimatorParameters rateModel() {
  RateEstimatorParameters p;
  p.rate_hz = 50.0;
  const Vec3 bias{1.5, -0.25, 0.125};
  for (std::size_t a = 0; a < kAxes; ++a) {
    AxisBiasModel& m = p.axes[a];
    m.bias_dps = bias[a];
    m.terms.arw_deg_per_sqrt_h = 3.0 * 60.0 * 0.05 / std::sqrt(50.0) * 60.0;  // white noise 0.05 °/s at 50 Hz
    m.terms.bias_instability_deg_per_h = 5.0;
    m.temperature_coefficient_dps_per_c = 0.02 * static_cast<double>(a + 1);
    m.temperature_coefficient_std_dps_per_c = 0.002;
    m.temperature_reference_c = 30.0;
    m.warm_up_amplitude_dps = 0.1;
    m.warm_up_time_constant_s = 20.0;
    m.bias_std_dps = 0.01;
  }
  return p;
}

}  // namespace

TEST(SamplePipeline, RateWithASensorModelIsTheRateEstimatorsOutputFromTheFirstSample) {
  const Stream s = noisyStream(3000, 4, {1.5, -0.25, 0.125});
  PipelineSettings p = baseSettings();  // bias estimated: the paper's chain waits, the rate does not
  p.rate_model = rateModel();
  SamplePipeline pipeline(p);
  EXPECT_EQ(pipeline.rateModel(), RateModel::SensorModel);
  EXPECT_EQ(toString(pipeline.rateModel()), "model");
  RateEstimator reference(rateModel());
  std::size_t still = 0;
  for (std::size_t i = 0; i < 3000; ++i) {
    const Vec3 raw{s.x[0][i], s.x[1][i], s.x[2][i]};
    const double t = 1234.5 + static_cast<double>(i) / 50.0;
    const double temp = 25.0 + 0.001 * static_cast<double>(i);
    const ProcessedSample out = pipeline.process(i, t, raw, temp);
    const RateSample r = reference.update(t, raw, temp);
    ASSERT_TRUE(out.has_rate) << i;
    ASSERT_EQ(out.rate, r.rate_dps) << i;
    ASSERT_EQ(out.rate_bias, r.bias_dps) << i;
    ASSERT_EQ(out.still, std::optional<bool>(r.still)) << i;
    still += r.still ? 1 : 0;
  }
  EXPECT_GT(still, 0u);  // the comparison covered residual updates
}

TEST(SamplePipeline, RateWithoutAModelIsRawMinusTheBiasOnceKnown) {
  PipelineSettings p = baseSettings();
  p.still_seconds = 1.0;
  p.kalman = {0.5, 0.01, 0.02};
  SamplePipeline pipeline(p);
  EXPECT_EQ(pipeline.rateModel(), RateModel::ConstantBias);
  for (int i = 0; i < 50; ++i) {
    const ProcessedSample out = pipeline.process(i, i / 50.0, {1.0, 2.0, 3.0 + (i % 2)}, 25.0);
    EXPECT_FALSE(out.has_rate) << i;  // as mean and kalman: from the sample after the still period
  }
  const ProcessedSample out = pipeline.process(50, 1.0, {1.5, 2.0, 4.0}, 25.0);
  ASSERT_TRUE(out.has_rate);
  EXPECT_EQ(out.rate_bias, pipeline.bias());
  EXPECT_EQ(out.rate, (Vec3{1.5 - pipeline.bias()[0], 2.0 - pipeline.bias()[1], 4.0 - pipeline.bias()[2]}));
  EXPECT_FALSE(out.still.has_value());
}

TEST(SamplePipeline, RateModelReloadValidatesFirstAndContinuesTheWarmUpShape) {
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Config;
  p.kalman = {0.9, 0.001, 0.1};
  SamplePipeline pipeline(p);
  for (int i = 0; i < 100; ++i) pipeline.process(i, 10.0 + i / 50.0, {0.1, 0.2, 0.3}, 30.0);
  RateEstimatorParameters bad = rateModel();
  bad.low_pass_hz = 40.0;  // past Nyquist
  EXPECT_THROW(pipeline.reloadRateModel(bad), std::invalid_argument);
  EXPECT_EQ(pipeline.rateModel(), RateModel::ConstantBias);  // a bad reload changes nothing

  pipeline.reloadRateModel(rateModel());
  ASSERT_EQ(pipeline.rateModel(), RateModel::SensorModel);
  // 100 samples (2 s) have passed since the first: the warm-up term is A·e^{−2/τ}.
  const ProcessedSample out = pipeline.process(100, 12.0, {0.1, 0.2, 0.3}, 30.0);
  const double expected_warm_up = 0.1 * std::exp(-2.0 / 20.0);
  EXPECT_NEAR(out.rate_bias[0], 1.5 + expected_warm_up, 1e-12);
  EXPECT_NEAR(pipeline.rateEstimator()->parameters().axes[0].warm_up_amplitude_dps, expected_warm_up, 1e-15);
  pipeline.reloadRateModel(std::nullopt);
  EXPECT_EQ(pipeline.rateModel(), RateModel::ConstantBias);
}

// A sensor whose output never changes (seen on Linux's i2c-stub, scripts/vm-kernel-test.sh):
// the still period cannot identify the filter. The pipeline says so once per still period
// and starts it again; it used to refuse every following sample.
TEST(SamplePipeline, AStillPeriodWithoutVarianceIsRefusedOnceAndStartsAgain) {
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Config;
  p.still_seconds = 4.0;  // 200 samples
  SamplePipeline pipeline(p);
  const Vec3 constant{1.0, -2.0, 5.0};
  std::size_t refused = 0;
  for (std::size_t i = 0; i < 1000; ++i) {
    try {
      const ProcessedSample out = pipeline.process(i, i / 50.0, constant, 30.0);
      EXPECT_EQ(out.raw, constant);
      EXPECT_FALSE(out.filtered);
    } catch (const std::invalid_argument& e) {
      ++refused;
      EXPECT_EQ(i % 200, 199u) << "refused at sample " << i;
      EXPECT_NE(std::string(e.what()).find("this one is constant"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(refused, 5u);
  EXPECT_EQ(pipeline.phase(), PipelinePhase::Estimating);

  // Noise arrives: the next still period identifies the filter as on a fresh start.
  const Stream s = noisyStream(200, 3, {0.0, 0.0, 0.0});
  for (std::size_t i = 0; i < 200; ++i)
    pipeline.process(1000 + i, (1000 + i) / 50.0, {s.x[0][i], s.x[1][i], s.x[2][i]}, 30.0);
  ASSERT_EQ(pipeline.phase(), PipelinePhase::Running);
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    const FilterChainParameters expected = identifyFilterChain(s.x[axis], 20, 0.3, {});
    EXPECT_EQ(pipeline.filterParameters()[axis].kalman.a, expected.kalman.a);
    EXPECT_EQ(pipeline.filterParameters()[axis].kalman.q, expected.kalman.q);
  }
}

// The start-up still window is checked for motion (processing/motion/still_period_check.hpp): a
// window in which the board turned is discarded and collected again; the bias comes from the
// first window at rest, and STATUS's state says what happened.
TEST(SamplePipeline, AStillWindowInWhichTheBoardTurnedIsCollectedAgain) {
  const Vec3 bias{0.75, -1.0, 2.0};
  const Stream s = noisyStream(1000, 5, bias);
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Estimate;
  p.still_seconds = 10.0;  // 500 samples
  p.kalman = {0.5, 0.01, 0.02};
  SamplePipeline pipeline(p);
  EXPECT_EQ(pipeline.stillPeriod().state, StillPeriodState::Collecting);
  for (std::size_t i = 0; i < 1000; ++i) {
    Vec3 raw{s.x[0][i], s.x[1][i], s.x[2][i]};
    if (i >= 200 && i < 300) raw[2] += 5.0;  // a 10° turn about z in the first window
    pipeline.process(i, i / 50.0, raw, 25.0);
    if (i == 499) {
      EXPECT_EQ(pipeline.stillPeriod().state, StillPeriodState::MovedRetrying);
      EXPECT_EQ(pipeline.stillPeriod().verdict.axis, 2u);
      EXPECT_EQ(pipeline.phase(), PipelinePhase::Estimating);
    }
  }
  const StillPeriodReport& r = pipeline.stillPeriod();
  EXPECT_EQ(r.state, StillPeriodState::Still);
  EXPECT_EQ(r.attempts, 2u);
  EXPECT_EQ(r.verdicts, 2u);
  ASSERT_EQ(pipeline.phase(), PipelinePhase::Running);
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    double mean = 0.0;
    for (std::size_t i = 500; i < 1000; ++i) mean += s.x[axis][i];
    EXPECT_NEAR(pipeline.bias()[axis], mean / 500.0, 1e-12) << axis;  // the second window's, not the first's
  }
}

TEST(SamplePipeline, ABoardThatNeverRestsKeepsTheLastWindowAndSaysItsBiasIsSuspect) {
  const Stream s = noisyStream(kMaxStillAttempts * 500, 6, {0.0, 0.0, 0.0});
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Estimate;
  p.still_seconds = 10.0;
  p.kalman = {0.5, 0.01, 0.02};
  SamplePipeline pipeline(p);
  for (std::size_t i = 0; i < kMaxStillAttempts * 500; ++i) {
    const double sway = 2.0 * std::sin(2.0 * M_PI * 0.3 * static_cast<double>(i) / 50.0);
    pipeline.process(i, i / 50.0, {s.x[0][i] + sway, s.x[1][i], s.x[2][i]}, 25.0);
  }
  EXPECT_EQ(pipeline.stillPeriod().state, StillPeriodState::MovedKept);
  EXPECT_EQ(pipeline.stillPeriod().attempts, kMaxStillAttempts);
  EXPECT_EQ(pipeline.stillPeriod().verdict.axis, 0u);
  EXPECT_EQ(pipeline.phase(), PipelinePhase::Running);  // gyrod does not wait for ever
}

TEST(SamplePipeline, NoStillPeriodNoStillCheck) {
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Config;
  p.kalman = {0.5, 0.01, 0.02};
  const SamplePipeline pipeline(p);
  EXPECT_EQ(pipeline.stillPeriod().state, StillPeriodState::None);
}

// The ALLAN reply's intervals: none before the first refit has identified the noise types;
// right after it, for every stream, the noise type, edf and χ² interval of the snapshot
// (the lag-1 identification on the whole window, as offline analyze does).
TEST(SamplePipeline, WindowIntervalsAfterARefitAreTheSnapshots) {
  const Stream s = noisyStream(3000, 7, {0.1, 0.2, 0.3});
  PipelineSettings p = baseSettings();
  p.bias_origin = BiasOrigin::Config;
  p.kalman = {0.5, 0.01, 0.02};
  SamplePipeline pipeline(p);
  for (std::size_t i = 0; i < 3000; ++i) pipeline.process(i, i / 50.0, {s.x[0][i], s.x[1][i], s.x[2][i]}, 25.0);
  const AllanWindowDeviations before = pipeline.allanWindowDeviations();
  EXPECT_EQ(before.samples, 2048u);  // the window's, not the 3000 processed
  for (const auto& point : before.points[0][0]) EXPECT_TRUE(std::isnan(point.edf));

  pipeline.refitNoiseTerms();
  const AllanWindowDeviations after = pipeline.allanWindowDeviations();
  const AllanStreams snap = pipeline.allanSnapshot();
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    const std::array<const std::vector<AllanPoint>*, kStreams> expected = {
        &snap.raw[axis].window, &snap.mean[axis].window, &snap.kalman[axis].window};
    for (std::size_t k = 0; k < kStreams; ++k) {
      ASSERT_EQ(after.points[axis][k].size(), expected[k]->size());
      for (std::size_t i = 0; i < expected[k]->size(); ++i) {
        const AllanPoint& got = after.points[axis][k][i];
        const AllanPoint& want = (*expected[k])[i];
        EXPECT_EQ(got.m, want.m);
        EXPECT_EQ(got.noise_alpha, want.noise_alpha) << axis << "/" << k << " m " << want.m;
        EXPECT_NEAR(got.oadev, want.oadev, 1e-12 * want.oadev);
        EXPECT_NEAR(got.edf, want.edf, 1e-12 * want.edf);
        EXPECT_NEAR(got.oadev_lo, want.oadev_lo, 1e-12 * want.oadev_lo);
        EXPECT_NEAR(got.oadev_hi, want.oadev_hi, 1e-12 * want.oadev_hi);
        EXPECT_LT(got.oadev_lo, got.oadev);
        EXPECT_GT(got.oadev_hi, got.oadev);
      }
    }
  }
}

namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expectSameSample(const ProcessedSample& a, const ProcessedSample& b) {
  ASSERT_EQ(a.seq, b.seq);
  EXPECT_EQ(a.filtered, b.filtered) << a.seq;
  EXPECT_EQ(a.has_rate, b.has_rate) << a.seq;
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    EXPECT_TRUE(sameBits(a.raw[axis], b.raw[axis])) << a.seq;
    if (a.filtered) {
      EXPECT_TRUE(sameBits(a.mean[axis], b.mean[axis])) << a.seq << " axis " << axis;
      EXPECT_TRUE(sameBits(a.kalman[axis], b.kalman[axis])) << a.seq << " axis " << axis;
    }
    if (a.has_rate) {
      EXPECT_TRUE(sameBits(a.rate[axis], b.rate[axis])) << a.seq << " axis " << axis;
    }
  }
}

}  // namespace

// The still window evaluated off the loop (gyrod): the samples that come meanwhile are held and
// released with exactly the values the pipeline gives when it evaluates the window in process(),
// a gap among them included; and a window that moved is collected again from the held samples.
TEST(SamplePipelineOffLoop, HeldSamplesAreReleasedExactlyAsTheInLoopPipelineGivesThem) {
  for (const bool turn_in_first_window : {false, true}) {
    SCOPED_TRACE(turn_in_first_window ? "a turn in the first window" : "at rest");
    PipelineSettings settings = baseSettings();
    settings.still_seconds = 4.0;  // 200 samples at 50 Hz
    PipelineSettings off = settings;
    off.still_window_off_loop = true;
    SamplePipeline in_loop(settings), off_loop(off);
    Stream s = noisyStream(900, 41, {0.5, -0.25, 1.0});
    if (turn_in_first_window)
      for (std::size_t i = 80; i < 130; ++i) s.x[0][i] += 5.0;  // 1 s at 5 deg/s
    std::vector<ProcessedSample> expected, got;
    std::optional<StillWindow> taken;
    std::size_t held_since_taken = 0;
    for (std::size_t i = 0; i < 900; ++i) {
      const Vec3 raw = {s.x[0][i], s.x[1][i], s.x[2][i]};
      if (i == 230) {  // a gap among the held samples
        in_loop.discontinuity();
        off_loop.discontinuity();
      }
      expected.push_back(in_loop.process(i, static_cast<double>(i) / 50.0, raw, 30.0));
      const ProcessedSample out = off_loop.process(i, static_cast<double>(i) / 50.0, raw, 30.0);
      if (!out.held) got.push_back(out);
      if (off_loop.stillWindowWaiting()) {
        taken = off_loop.takeStillWindow();
        held_since_taken = 0;
      } else if (taken && ++held_since_taken == 40) {  // the evaluation takes 40 samples' time
        for (const auto& r : off_loop.finishStillWindow(evaluateStillWindow(std::move(*taken)))) got.push_back(r);
        taken.reset();
        if (off_loop.stillWindowWaiting()) {
          taken = off_loop.takeStillWindow();
          held_since_taken = 0;
        }
      }
    }
    ASSERT_EQ(off_loop.phase(), PipelinePhase::Running);
    ASSERT_EQ(got.size(), expected.size());
    for (std::size_t i = 0; i < got.size(); ++i) expectSameSample(got[i], expected[i]);
    EXPECT_EQ(off_loop.stillPeriod().attempts, in_loop.stillPeriod().attempts);
    EXPECT_EQ(off_loop.stillPeriod().state, in_loop.stillPeriod().state);
    if (turn_in_first_window) {
      EXPECT_EQ(in_loop.stillPeriod().attempts, 2u);
    }
  }
}
