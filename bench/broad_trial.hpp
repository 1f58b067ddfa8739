#pragma once
// A trial of the BROAD benchmark as tests/data/broad/ stores it (tests/data/broad/README.md):
// NAME.csv.gz (t,gx,gy,gz [°/s],ax,ay,az [g]) and NAME.truth.csv.gz (t,qw,qx,qy,qz,moving), and
// the benchmark's error metrics (Laidig et al., "BROAD — A Benchmark for Robust Inertial
// Orientation Estimation", Data 6(7), 2021, section 4). Header-only, for bench/attitude_broad
// and the tests; the files are read with zlib.
#include <zlib.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "processing/attitude/attitude_estimator.hpp"
#include "processing/attitude/quaternion.hpp"

namespace gyrod::broad {

struct Trial {
  std::string name;
  double rate_hz = 2000.0 / 7.0;
  std::vector<processing::attitude::Vector3> rate_dps, accel_g;
  std::vector<processing::attitude::Quaternion> truth;  // NaN where the markers were lost
  std::vector<bool> moving;
};

// The rows of a gzip'd CSV with a header line, each as `columns` numbers ("nan" allowed).
inline std::vector<std::vector<double>> readGzipCsv(const std::string& path, std::size_t columns) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw std::runtime_error(path + ": cannot open");
  std::vector<std::vector<double>> rows;
  std::array<char, 1024> line{};
  std::size_t line_number = 0;
  while (gzgets(f, line.data(), static_cast<int>(line.size()))) {
    if (++line_number == 1) continue;  // the header
    std::vector<double> row;
    row.reserve(columns);
    const char* p = line.data();
    for (std::size_t c = 0; c < columns; ++c) {
      char* end = nullptr;
      row.push_back(std::strtod(p, &end));
      if (end == p) {
        gzclose(f);
        throw std::runtime_error(path + ":" + std::to_string(line_number) + ": expected " + std::to_string(columns) +
                                 " numbers");
      }
      p = *end == ',' ? end + 1 : end;
    }
    rows.push_back(std::move(row));
  }
  gzclose(f);
  return rows;
}

// directory/name.csv.gz and directory/name.truth.csv.gz, the same number of rows.
inline Trial readTrial(const std::string& directory, const std::string& name) {
  Trial trial;
  trial.name = name;
  const auto imu = readGzipCsv(directory + "/" + name + ".csv.gz", 7);
  const auto truth = readGzipCsv(directory + "/" + name + ".truth.csv.gz", 6);
  if (imu.size() != truth.size() || imu.size() < 2)
    throw std::runtime_error(directory + "/" + name + ": " + std::to_string(imu.size()) + " IMU rows but " +
                             std::to_string(truth.size()) + " truth rows");
  trial.rate_hz = static_cast<double>(imu.size() - 1) / (imu.back()[0] - imu.front()[0]);
  for (std::size_t i = 0; i < imu.size(); ++i) {
    trial.rate_dps.push_back({imu[i][1], imu[i][2], imu[i][3]});
    trial.accel_g.push_back({imu[i][4], imu[i][5], imu[i][6]});
    trial.truth.push_back({truth[i][1], truth[i][2], truth[i][3], truth[i][4]});
    trial.moving.push_back(truth[i][5] != 0.0);
  }
  return trial;
}

struct TrialErrors {
  double inclination_rmse_deg = 0.0;
  double heading_rmse_deg = 0.0;  // after removing the mean heading offset
  std::size_t samples = 0;        // movement samples with truth
};

// With e = q_est ⊗ q_truth⁻¹ per sample, over the movement phases where the truth exists:
// the RMS of the inclination angle of e, and the RMS of its heading angle less their circular mean
// (a 6-axis estimate has no heading reference).
inline TrialErrors broadErrors(const std::vector<processing::attitude::Quaternion>& estimate, const Trial& trial) {
  using namespace processing::attitude;
  constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
  double sum_incl2 = 0.0, sum_sin = 0.0, sum_cos = 0.0;
  std::vector<double> headings;
  for (std::size_t i = 0; i < estimate.size() && i < trial.truth.size(); ++i) {
    const Quaternion& t = trial.truth[i];
    if (!trial.moving[i] || !std::isfinite(t[0]) || !std::isfinite(t[1]) || !std::isfinite(t[2]) ||
        !std::isfinite(t[3]))
      continue;
    const Quaternion e = multiply(estimate[i], conjugate(normalized(t)));
    const double incl = inclinationAngle(e);
    sum_incl2 += incl * incl;
    const double h = signedHeadingAngle(e);
    headings.push_back(h);
    sum_sin += std::sin(h);
    sum_cos += std::cos(h);
  }
  TrialErrors out;
  out.samples = headings.size();
  if (headings.empty()) return out;
  const double offset = std::atan2(sum_sin, sum_cos);
  double sum_h2 = 0.0;
  for (double h : headings) {
    const double d = wrapAngle(h - offset);
    sum_h2 += d * d;
  }
  const double n = static_cast<double>(headings.size());
  out.inclination_rmse_deg = std::sqrt(sum_incl2 / n) * kRadToDeg;
  out.heading_rmse_deg = std::sqrt(sum_h2 / n) * kRadToDeg;
  return out;
}

// The estimator over the whole trial, one quaternion a sample; `last`, when given, gets the
// last sample's output (the motion errors learned by the end).
inline std::vector<processing::attitude::Quaternion> estimateTrial(
    const Trial& trial, processing::attitude::AttitudeParameters params,
    processing::attitude::AttitudeSample* last = nullptr) {
  params.rate_hz = trial.rate_hz;
  processing::attitude::AttitudeEstimator estimator(params);
  std::vector<processing::attitude::Quaternion> q(trial.rate_dps.size());
  processing::attitude::AttitudeSample sample;
  for (std::size_t i = 0; i < q.size(); ++i) {
    sample = estimator.update(trial.rate_dps[i], trial.accel_g[i]);
    q[i] = sample.q;
  }
  if (last) *last = sample;
  return q;
}

}  // namespace gyrod::broad
