#pragma once
// Every stream side by side on simulated records from one seed (issue 11, item 4; the table
// of docs/motion.md, printed by bench/compare_streams and scripts/motion-table.sh):
//   raw     raw − b0, b0 the start-up estimate (the mean of the first startup_still_s, still),
//           as gyrod's bias.source = "estimate" subtracts it;
//   mean    the paper's mean filter on raw − b0 (processing/paper/filter_chain.hpp, as gyrod and
//           `gyroctl filter --bias b0 --ar-phi A --kalman-q Q --kalman-r R` run it);
//   kalman  the paper's Kalman filter after it, A, Q, R identified on a still record of the same
//           sensor at the steady temperature (as `gyroctl filter still.csv` identifies them);
//   rate    processing::RateEstimator with the caller's parameters (the sensor model file that
//           `gyroctl analyze --write-model` makes from a still cold-start record).
// Each figure comes from its own record (seed + a fixed offset), so each can be reproduced alone.
// Pure computation; allocates per record, not per sample in the estimators.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "processing/motion/rate_estimator.hpp"
#include "processing/paper/filter_chain.hpp"
#include "processing/simulation/noise_simulator.hpp"

namespace gyrod::processing {

enum class ComparedStream : std::size_t { Raw, Mean, Kalman, Rate };
inline constexpr std::size_t kComparedStreams = 4;
inline constexpr std::array<std::string_view, kComparedStreams> kComparedStreamNames = {"raw", "mean", "kalman",
                                                                                        "rate"};

struct StreamComparisonSetup {
  SimulationModel sensor;  // the truth; its temperature curve is replaced per record
  RateEstimatorParameters rate;
  std::uint64_t seed = 1;
  double steady_temperature_c = 40.0;  // the records other than the warm-up (a warmed-up board)
  double warm_up_start_c = 25.0;       // the warm-up record: start → start + delta, time constant tau
  double warm_up_delta_c = 15.0;
  double warm_up_time_constant_s = 300.0;
  int warm_up_minutes = 30;  // each minute: 58 s of motion, then 2 s still
  double startup_still_s = 10.0;
  double identification_still_s = 1200.0;  // the still record the paper's A, Q, R come from
  double rest_s = 600.0;                   // the record of the static figures
};

inline constexpr std::array<double, 3> kCompareFrequenciesHz = {0.1, 1.0, 5.0};
inline constexpr std::array<double, 3> kCompareAmplitudesDps = {5.0, 20.0, 20.0};
inline constexpr std::array<std::size_t, 4> kCompareStepSamples = {1, 2, 3, 5};  // k-th sample at/after the step
inline constexpr double kCompareStepDps = 10.0;

struct StreamFigures {
  std::array<double, kCompareStepSamples.size()> step_value_dps{};  // mean over the steps
  std::optional<double> step_t90_s;  // mean time from the step to 90 %; none: some step never got there
  double step_settled_dps = 0.0;     // mean over the last 0.5 s of each 3 s hold
  std::array<double, kCompareFrequenciesHz.size()> gain{}, phase_deg{};  // against the truth's fit
  double mixed_rms_error_dps = 0.0;                                      // all axes, after the start-up still period
  double turns_angle_error_percent = 0.0;
  double warm_up_offset_dps = 0.0;  // mean over the final 20 s still; the axis with the largest |.|
  double variance_ratio = 1.0;      // at rest, var(stream)/var(raw) about their means (axis x)
  double peak_ratio = 1.0;          // at rest, max|stream − mean| / max|raw − mean| (axis x)
};

struct StreamComparison {
  std::array<StreamFigures, kComparedStreams> streams;
  std::array<FilterChainParameters, kSimulatedAxes> paper;  // what the mean and Kalman ran with
  double raw_variance_dps2 = 0.0;                           // at rest, axis x
  double rate_bias_error_dps = 0.0;     // |b̂ − true bias| at the last moving sample of the warm-up, worst axis
  double startup_bias_error_dps = 0.0;  // |b0 − true bias| there, same axis
  std::size_t steps = 0;
};

// The sensor of the table: the paper's Table 2 terms on three axes, DLPF_CFG 4 at 50 Hz,
// FS_SEL 0, biases 1.367/−0.4/0.25 °/s, temperature coupling 0.03/−0.02/0.015 °/s per °C
// (reference 25 °C), temperature noise 0.02 °C, at 25 °C.
SimulationModel comparisonSensor();

StreamComparison compareStreams(const StreamComparisonSetup& setup);

}  // namespace gyrod::processing
