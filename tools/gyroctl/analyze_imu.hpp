#pragma once
// gyroctl analyze's accelerometer columns and its Kalibr output (imu.yaml).
#include <string>
#include <vector>

#include "formats/kalibr_yaml.hpp"
#include "processing/paper/axis_analysis.hpp"
#include "tools/gyroctl/input.hpp"

namespace gyrod::gyroctl {

// True for ax, ay, az.
bool isAccelColumn(const std::string& name);

// Moves the accelerometer columns `axis` asks for out of Recording::accel_g into the analysed
// columns (after the gyro's): all those present for "all", the one named for ax/ay/az (its
// absence is a RecordingError naming the file's columns), none for a gyro column (their
// memory is freed). `in.axis_indices` then lists what is analysed.
void selectAccelColumns(LoadedInput& in, const std::string& axis);

struct KalibrOptions {
  std::string output;
  double inflate = 1.0;
  std::string rostopic = "/imu0";
};

// imu.yaml from the analysed columns: per sensor, the mean over its analysed axes of the
// white-noise density (ARW / VRW) and of the bias random walk (RRW / acceleration random
// walk) in SI, each axis' value and 1-σ in a comment. A term no axis estimated is left out
// with a note; every such note is also returned in `missing` for stderr.
formats::KalibrImu kalibrImuFromAnalyses(const std::vector<std::string>& columns,
                                         const std::vector<processing::AxisAnalysis>& analyses, double rate_hz,
                                         const std::string& source, const KalibrOptions& options,
                                         std::vector<std::string>& missing);

}  // namespace gyrod::gyroctl
