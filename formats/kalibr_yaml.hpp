#pragma once
// Kalibr's IMU configuration file, imu.yaml (github.com/ethz-asl/kalibr wiki "YAML formats"
// and "IMU Noise Model"): the continuous-time white-noise densities and bias random walks of
// the accelerometer and the gyro, in SI units, the ROS topic and the update rate.
//
//   accelerometer_noise_density: 0.0019   # [m/s^2/sqrt(Hz)]
//   accelerometer_random_walk:   0.00043  # [m/s^3/sqrt(Hz)]
//   gyroscope_noise_density:     0.00019  # [rad/s/sqrt(Hz)]
//   gyroscope_random_walk:       2.7e-05  # [rad/s^2/sqrt(Hz)]
//   rostopic: /imu0
//   update_rate: 200                      # [Hz]
//
// A value that was not estimated is not written: its key appears only in a comment saying
// why, so Kalibr stops on the missing key instead of calibrating with an invented number.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gyrod::formats {

struct KalibrValue {
  std::optional<double> value;  // nullopt: not estimated
  std::string note;             // the comment after the value, or the reason it is missing
};

struct KalibrImu {
  KalibrValue accelerometer_noise_density;  // m/s²/√Hz
  KalibrValue accelerometer_random_walk;    // m/s³/√Hz
  KalibrValue gyroscope_noise_density;      // rad/s/√Hz
  KalibrValue gyroscope_random_walk;        // rad/s²/√Hz
  std::string rostopic = "/imu0";
  double update_rate_hz = 0.0;
  std::vector<std::string> header_comments;  // written as "# ..." lines at the top
};

// The file's text: header comments, then the keys in Kalibr's own order, each value to six
// significant digits.
std::string kalibrImuYaml(const KalibrImu& imu);

// Reads back the keys kalibrImuYaml writes (a key missing from the file stays nullopt; the
// notes and comments are not read). Throws std::runtime_error "NAME:LINE: cause" for a
// line that is not "key: value", an unknown key, or a value that is not a number.
KalibrImu parseKalibrImuYaml(std::string_view text, const std::string& name);

}  // namespace gyrod::formats
