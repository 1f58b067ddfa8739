#include "processing/motion/stream_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "processing/base/detrend.hpp"
#include "processing/paper/axis_analysis.hpp"

namespace gyrod::processing {
namespace {

constexpr std::size_t kAxisX = 0, kAxisZ = 2;
constexpr double kFinalStillS = 20.0;
constexpr double kStepHoldS = 3.0;
constexpr std::size_t kSteps = 40;

// Each figure's record has its own seed, so that changing one record leaves the others alone.
enum RecordSeed : std::uint64_t { Identification = 1, Step, Sine, Mixed = Sine + 3, Turns, WarmUp, Rest };

struct Record {
  std::vector<SimulatedSample> sim;
  std::array<std::vector<AngularRate>, kComparedStreams> stream;
  std::vector<AngularRate> rate_bias;
  AngularRate startup_bias{};
  double tau0 = 0.0;
  double stream_at(ComparedStream s, std::size_t i, std::size_t axis) const {
    return stream[static_cast<std::size_t>(s)][i][axis];
  }
};

TemperatureModel steadyTemperature(const StreamComparisonSetup& setup) {
  TemperatureModel t = setup.sensor.temperature;
  t.start_c = t.final_c = setup.steady_temperature_c;
  return t;
}

Record runRecord(const StreamComparisonSetup& setup, const std::array<FilterChainParameters, kSimulatedAxes>& paper,
                 const TemperatureModel& temperature, const MotionProfile& motion, double seconds, std::uint64_t seed) {
  SimulationModel model = setup.sensor;
  model.temperature = temperature;
  NoiseSimulator sim(model, seconds, seed, motion);
  Record r;
  r.tau0 = 1.0 / model.rate_hz;
  const std::size_t n = sim.sampleCount();
  r.sim.reserve(n);
  for (std::size_t i = 0; i < n; ++i) r.sim.push_back(sim.next());
  const auto startup = std::min<std::size_t>(n, static_cast<std::size_t>(setup.startup_still_s * model.rate_hz));
  for (std::size_t i = 0; i < startup; ++i)
    for (std::size_t a = 0; a < kMotionAxes; ++a)
      r.startup_bias[a] += r.sim[i].rate_dps[a] / static_cast<double>(startup);
  std::array<AxisFilterChain, kSimulatedAxes> chains = {AxisFilterChain(paper[0]), AxisFilterChain(paper[1]),
                                                        AxisFilterChain(paper[2])};
  RateEstimator estimator(setup.rate);
  for (auto& s : r.stream) s.resize(n);
  r.rate_bias.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const SimulatedSample& s = r.sim[i];
    for (std::size_t a = 0; a < kMotionAxes; ++a) {
      const double x = s.rate_dps[a] - r.startup_bias[a];
      const FilteredRate f = chains[a].update(x);
      r.stream[0][i][a] = x;
      r.stream[1][i][a] = f.mean_dps;
      r.stream[2][i][a] = f.kalman_dps;
    }
    const RateSample rate = estimator.update(s.t_s, s.rate_dps, s.temperature_c);
    r.stream[3][i] = rate.rate_dps;
    r.rate_bias[i] = rate.bias_dps;
  }
  return r;
}

std::array<FilterChainParameters, kSimulatedAxes> identifyPaperChain(const StreamComparisonSetup& setup) {
  SimulationModel model = setup.sensor;
  model.temperature = steadyTemperature(setup);
  NoiseSimulator sim(model, setup.identification_still_s, setup.seed * 16 + Identification);
  std::array<std::vector<double>, kSimulatedAxes> x;
  for (std::size_t i = 0; i < sim.sampleCount(); ++i) {
    const SimulatedSample s = sim.next();
    for (std::size_t a = 0; a < kSimulatedAxes; ++a) x[a].push_back(s.rate_dps[a]);
  }
  std::array<FilterChainParameters, kSimulatedAxes> out;
  for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
    removeLinearTrend(x[a], 1.0 / model.rate_hz);  // as `gyroctl filter` does by default
    out[a] = identifyFilterChain(x[a], FilterChainParameters{}.mean_window, FilterChainParameters{}.mean_threshold_dps);
  }
  return out;
}

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

std::size_t firstSampleAtOrAfter(double t_s, double tau0) {
  return static_cast<std::size_t>(std::ceil(t_s / tau0 - 1e-9));
}

void measureSteps(const StreamComparisonSetup& setup, const std::array<FilterChainParameters, kSimulatedAxes>& paper,
                  StreamComparison& out) {
  // Steps of +10 °/s on x after rests of 2–3 s drawn from the seed, so that the step falls
  // anywhere between two samples; each held 3 s.
  std::mt19937_64 rng(setup.seed);
  std::vector<MotionSegment> segments{{MotionProfile{}, setup.startup_still_s}};
  std::vector<double> step_times;
  double t = setup.startup_still_s;
  for (std::size_t i = 0; i < kSteps; ++i) {
    const double rest = uniform(rng, 2.0, 3.0);
    segments.push_back({MotionProfile{}, rest});
    segments.push_back({MotionProfile::constant(kAxisX, kCompareStepDps), kStepHoldS});
    step_times.push_back(t + rest);
    t += rest + kStepHoldS;
  }
  const Record r = runRecord(setup, paper, steadyTemperature(setup), MotionProfile::sequence(segments), t + 1.0,
                             setup.seed * 16 + Step);
  const auto settle_samples = static_cast<std::size_t>(0.5 / r.tau0);
  const auto hold_samples = static_cast<std::size_t>(kStepHoldS / r.tau0);
  out.steps = step_times.size();
  for (std::size_t s = 0; s < kComparedStreams; ++s) {
    StreamFigures& f = out.streams[s];
    const auto stream = static_cast<ComparedStream>(s);
    double t90_sum = 0.0;
    bool always_reached = true;
    for (double step_t : step_times) {
      const std::size_t first = firstSampleAtOrAfter(step_t, r.tau0);
      for (std::size_t k = 0; k < kCompareStepSamples.size(); ++k)
        f.step_value_dps[k] += r.stream_at(stream, first + kCompareStepSamples[k] - 1, kAxisX) / double(kSteps);
      for (std::size_t i = first + hold_samples - settle_samples; i < first + hold_samples; ++i)
        f.step_settled_dps += r.stream_at(stream, i, kAxisX) / double(kSteps * settle_samples);
      std::optional<std::size_t> reached;
      for (std::size_t i = first; i < first + hold_samples && !reached; ++i)
        if (r.stream_at(stream, i, kAxisX) >= 0.9 * kCompareStepDps) reached = i;
      if (reached)
        t90_sum += r.sim[*reached].t_s - step_t;
      else
        always_reached = false;
    }
    if (always_reached) f.step_t90_s = t90_sum / double(kSteps);
  }
}

struct SineFit {
  double amplitude = 0.0, phase_rad = 0.0;
};
// Least squares of y = a·sin(2πf(t − t0)) + b·cos(2πf(t − t0)) + c: amplitude √(a² + b²), phase atan2(b, a).
SineFit fitSine(const std::vector<double>& t, const std::vector<double>& y, double f, double t0) {
  std::array<std::array<double, 3>, 3> m{};
  std::array<double, 3> v{};
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double w = 2.0 * std::numbers::pi * f * (t[i] - t0);
    const std::array<double, 3> row = {std::sin(w), std::cos(w), 1.0};
    for (std::size_t j = 0; j < 3; ++j) {
      v[j] += row[j] * y[i];
      for (std::size_t k = 0; k < 3; ++k) m[j][k] += row[j] * row[k];
    }
  }
  // Gaussian elimination; the normal matrix is well conditioned over whole periods.
  for (std::size_t p = 0; p < 3; ++p)
    for (std::size_t j = p + 1; j < 3; ++j) {
      const double factor = m[j][p] / m[p][p];
      for (std::size_t k = p; k < 3; ++k) m[j][k] -= factor * m[p][k];
      v[j] -= factor * v[p];
    }
  std::array<double, 3> x{};
  for (std::size_t p = 3; p-- > 0;) {
    double s = v[p];
    for (std::size_t k = p + 1; k < 3; ++k) s -= m[p][k] * x[k];
    x[p] = s / m[p][p];
  }
  return {std::hypot(x[0], x[1]), std::atan2(x[1], x[0])};
}

double wrapDegrees(double deg) {
  while (deg > 180.0) deg -= 360.0;
  while (deg <= -180.0) deg += 360.0;
  return deg;
}

void measureSines(const StreamComparisonSetup& setup, const std::array<FilterChainParameters, kSimulatedAxes>& paper,
                  StreamComparison& out) {
  for (std::size_t k = 0; k < kCompareFrequenciesHz.size(); ++k) {
    const double f = kCompareFrequenciesHz[k];
    // 12 periods, at least 20 s; the first 2 periods let every filter settle, the fit takes the rest.
    const double periods = std::max(12.0, std::ceil(20.0 * f));
    const double start = setup.startup_still_s, length = periods / f;
    const MotionProfile motion = MotionProfile::sine(kAxisX, f, kCompareAmplitudesDps[k], start, length);
    const Record r =
        runRecord(setup, paper, steadyTemperature(setup), motion, start + length, setup.seed * 16 + Sine + k);
    std::vector<double> t, truth;
    std::array<std::vector<double>, kComparedStreams> y;
    for (std::size_t i = 0; i < r.sim.size(); ++i) {
      if (r.sim[i].t_s < start + 2.0 / f) continue;
      t.push_back(r.sim[i].t_s);
      truth.push_back(r.sim[i].true_rate_dps[kAxisX]);
      for (std::size_t s = 0; s < kComparedStreams; ++s) y[s].push_back(r.stream[s][i][kAxisX]);
    }
    const SineFit want = fitSine(t, truth, f, start);
    for (std::size_t s = 0; s < kComparedStreams; ++s) {
      const SineFit got = fitSine(t, y[s], f, start);
      out.streams[s].gain[k] = got.amplitude / want.amplitude;
      out.streams[s].phase_deg[k] = wrapDegrees((got.phase_rad - want.phase_rad) * 180.0 / std::numbers::pi);
    }
  }
}

// Steps, sines, a turn and a slow rotation on all three axes, with still periods between.
MotionProfile mixedProfile() {
  return MotionProfile::sequence({
      {MotionProfile::constant(0, 10.0), 5.0},
      {MotionProfile{}, 3.0},
      {MotionProfile::sine(1, 1.0, 20.0), 10.0},
      {MotionProfile{}, 3.0},
      {MotionProfile::turns(2, 2.0, 90.0, 2.0), 14.0},
      {MotionProfile::sum({MotionProfile::sine(0, 0.1, 5.0), MotionProfile::constant(1, 0.5)}), 20.0},
      {MotionProfile{}, 3.0},
      {MotionProfile::sum({MotionProfile::sine(2, 2.0, 30.0), MotionProfile::constant(0, -40.0)}), 10.0},
      {MotionProfile{}, 5.0},
  });
}

void measureMixed(const StreamComparisonSetup& setup, const std::array<FilterChainParameters, kSimulatedAxes>& paper,
                  StreamComparison& out) {
  const double start = setup.startup_still_s;
  const MotionProfile motion = MotionProfile::sequence({{MotionProfile{}, start}, {mixedProfile(), 73.0}});
  const Record r = runRecord(setup, paper, steadyTemperature(setup), motion, start + 73.0, setup.seed * 16 + Mixed);
  const std::size_t first = firstSampleAtOrAfter(start, r.tau0);
  for (std::size_t s = 0; s < kComparedStreams; ++s) {
    double sum = 0.0;
    for (std::size_t i = first; i < r.sim.size(); ++i)
      for (std::size_t a = 0; a < kMotionAxes; ++a) {
        const double e = r.stream[s][i][a] - r.sim[i].true_rate_dps[a];
        sum += e * e;
      }
    out.streams[s].mixed_rms_error_dps = std::sqrt(sum / static_cast<double>((r.sim.size() - first) * kMotionAxes));
  }
}

void measureTurns(const StreamComparisonSetup& setup, const std::array<FilterChainParameters, kSimulatedAxes>& paper,
                  StreamComparison& out) {
  // Ten full turns about z at 90 °/s, 2 s still before, between and after them.
  const MotionProfile motion = MotionProfile::turns(kAxisZ, 10.0, 90.0, 2.0, setup.startup_still_s);
  const Record r =
      runRecord(setup, paper, steadyTemperature(setup), motion, motion.settledFrom() + 2.0, setup.seed * 16 + Turns);
  for (std::size_t s = 0; s < kComparedStreams; ++s) {
    double angle = 0.0;
    for (const AngularRate& w : r.stream[s]) angle += w[kAxisZ] * r.tau0;
    out.streams[s].turns_angle_error_percent = 100.0 * (angle - 3600.0) / 3600.0;
  }
}

void measureWarmUp(const StreamComparisonSetup& setup, const std::array<FilterChainParameters, kSimulatedAxes>& paper,
                   StreamComparison& out) {
  // From a cold start, start → start + delta: each minute 58 s of motion drawn from the seed (a
  // sine of random frequency and amplitude on one axis, a constant rotation on another), then
  // 2 s still; at the end 20 s still, over which each stream's mean is its offset (truth 0).
  std::mt19937_64 rng(setup.seed * 16 + WarmUp);
  std::vector<MotionSegment> segments{{MotionProfile{}, setup.startup_still_s}};
  for (int i = 0; i < setup.warm_up_minutes; ++i) {
    const auto sine_axis = static_cast<std::size_t>(uniform(rng, 0.0, 3.0)) % 3, turn_axis = (sine_axis + 1) % 3;
    const double sign = uniform(rng, -1.0, 1.0) < 0.0 ? -1.0 : 1.0;
    segments.push_back(
        {MotionProfile::sum({MotionProfile::sine(sine_axis, uniform(rng, 0.2, 2.0), uniform(rng, 5.0, 30.0)),
                             MotionProfile::constant(turn_axis, sign * uniform(rng, 5.0, 40.0), uniform(rng, 5.0, 20.0),
                                                     uniform(rng, 10.0, 30.0))}),
         58.0});
    segments.push_back({MotionProfile{}, 2.0});
  }
  const double end_of_motion = setup.startup_still_s + 60.0 * setup.warm_up_minutes;
  TemperatureModel temperature = setup.sensor.temperature;
  temperature.start_c = setup.warm_up_start_c;
  temperature.final_c = setup.warm_up_start_c + setup.warm_up_delta_c;
  temperature.time_constant_s = setup.warm_up_time_constant_s;
  const Record r = runRecord(setup, paper, temperature, MotionProfile::sequence(segments), end_of_motion + kFinalStillS,
                             setup.seed * 16 + WarmUp);
  const std::size_t last_moving = firstSampleAtOrAfter(end_of_motion, r.tau0) - 1;
  const std::size_t n_end = r.sim.size() - last_moving - 1;
  std::array<double, kMotionAxes> true_bias{};
  for (std::size_t i = last_moving + 1; i < r.sim.size(); ++i)
    for (std::size_t a = 0; a < kMotionAxes; ++a)
      true_bias[a] += (r.sim[i].rate_dps[a] - r.sim[i].true_rate_dps[a]) / double(n_end);
  for (std::size_t s = 0; s < kComparedStreams; ++s) {
    double worst = 0.0;
    for (std::size_t a = 0; a < kMotionAxes; ++a) {
      double mean = 0.0;
      for (std::size_t i = last_moving + 1; i < r.sim.size(); ++i) mean += r.stream[s][i][a] / double(n_end);
      if (std::fabs(mean) > std::fabs(worst)) worst = mean;
    }
    out.streams[s].warm_up_offset_dps = worst;
  }
  for (std::size_t a = 0; a < kMotionAxes; ++a) {
    const double e = std::fabs(r.rate_bias[last_moving][a] - true_bias[a]);
    if (e >= out.rate_bias_error_dps) {
      out.rate_bias_error_dps = e;
      out.startup_bias_error_dps = std::fabs(r.startup_bias[a] - true_bias[a]);
    }
  }
}

void measureRest(const StreamComparisonSetup& setup, const std::array<FilterChainParameters, kSimulatedAxes>& paper,
                 StreamComparison& out) {
  const double start = setup.startup_still_s;
  const Record r =
      runRecord(setup, paper, steadyTemperature(setup), MotionProfile{}, start + setup.rest_s, setup.seed * 16 + Rest);
  const std::size_t first = firstSampleAtOrAfter(start, r.tau0);
  std::array<std::vector<double>, kComparedStreams> x;
  for (std::size_t s = 0; s < kComparedStreams; ++s)
    for (std::size_t i = first; i < r.sim.size(); ++i) x[s].push_back(r.stream[s][i][kAxisX]);
  out.raw_variance_dps2 = varianceAboutMean(x[0]);
  const double raw_peak = peakDeviationFromMean(x[0]);
  for (std::size_t s = 0; s < kComparedStreams; ++s) {
    out.streams[s].variance_ratio = varianceAboutMean(x[s]) / out.raw_variance_dps2;
    out.streams[s].peak_ratio = peakDeviationFromMean(x[s]) / raw_peak;
  }
}

}  // namespace

SimulationModel comparisonSensor() {
  SimulationModel m;
  m.rate_hz = 50.0;
  m.dlpf_cfg = 4;
  m.fs_sel = 0;
  constexpr std::array<double, 3> kBias = {1.367, -0.4, 0.25};
  constexpr std::array<double, 3> kCoefficient = {0.03, -0.02, 0.015};
  for (std::size_t a = 0; a < kSimulatedAxes; ++a) {
    AxisNoiseModel& axis = m.axes[a];
    axis.terms = {0.1663, 0.95164, 0.60565, 0.07759, 0.43223};
    axis.bias_dps = kBias[a];
    axis.extra.temperature_coefficient_dps_per_c = kCoefficient[a];
    axis.extra.temperature_reference_c = 25.0;
  }
  m.temperature = {25.0, 25.0, 300.0, 0.02};
  return m;
}

StreamComparison compareStreams(const StreamComparisonSetup& setup) {
  if (setup.rate.rate_hz != setup.sensor.rate_hz)
    throw std::invalid_argument(
        "the stream comparison cannot run: the rate model is for a different sample rate than the sensor");
  StreamComparison out;
  out.paper = identifyPaperChain(setup);
  measureSteps(setup, out.paper, out);
  measureSines(setup, out.paper, out);
  measureMixed(setup, out.paper, out);
  measureTurns(setup, out.paper, out);
  measureWarmUp(setup, out.paper, out);
  measureRest(setup, out.paper, out);
  return out;
}

}  // namespace gyrod::processing
