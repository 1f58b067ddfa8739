#include "tools/gyroctl/analyze_imu.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "formats/recording_csv.hpp"
#include "processing/base/noise_units.hpp"
#include "processing/base/units.hpp"

namespace gyrod::gyroctl {
namespace {

using processing::SensorKind;

std::string formatted(const char* fmt, double a, double b) {
  char buf[96];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

// One Kalibr entry: the mean over the axes of `sensor` whose fit kept the term (a term the
// fit set to 0 was not seen in the curve: not estimated), scaled by the inflation factor.
formats::KalibrValue kalibrValue(const std::vector<std::string>& columns,
                                 const std::vector<processing::AxisAnalysis>& analyses, SensorKind sensor,
                                 double (*si)(const processing::NoiseTerms&, SensorKind), double inflate) {
  formats::KalibrValue v;
  double sum = 0.0;
  std::size_t used = 0;
  std::string per_axis, without;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    if (processing::sensorOfColumn(columns[k]) != sensor) continue;
    const double value = si(analyses[k].noise.value, sensor);
    if (value > 0.0 && std::isfinite(value)) {
      sum += value;
      ++used;
      per_axis += (per_axis.empty() ? "" : ", ") + columns[k] +
                  formatted(" %.4g +- %.2g", value, si(analyses[k].noise.uncertainty, sensor));
    } else {
      without += (without.empty() ? "" : ", ") + columns[k];
    }
  }
  if (used == 0) {
    v.note = without.empty() ? std::string(sensor == SensorKind::Accel ? "no accelerometer column (ax,ay,az)"
                                                                       : "no gyro column analysed")
                             : "the fit found no such term in the Allan curve of " + without +
                                   "; record longer, or take a datasheet value";
    return v;
  }
  v.value = inflate * sum / static_cast<double>(used);
  v.note = "mean of " + per_axis;
  if (!without.empty()) v.note += "; not seen in " + without;
  if (inflate != 1.0) v.note += formatted("; x %.3g (--kalibr-inflate)", inflate, 0.0);
  return v;
}

// A random walk the fit did not see (a record too short for the +1/2 slope to rise above the
// other terms) still has a ceiling: σ(τ) ≥ K·√(τ/3) at every τ, so K ≤ min over τ of
// σ(τ)·√(3/τ), usually at the longest τ. Kalibr needs a number, and this bound is what
// imu_utils and allan_variance_ros users take there; the note says it is one. The largest
// bound over the axes, in SI. Returns whether it filled `v`.
bool boundUnseenRandomWalk(formats::KalibrValue& v, const std::vector<std::string>& columns,
                           const std::vector<processing::AxisAnalysis>& analyses, SensorKind sensor, double inflate) {
  if (v.value) return false;
  const double to_si = sensor == SensorKind::Accel ? units::kStandardGravity : units::kRadPerDeg;
  double bound = 0.0;
  double bound_tau = 0.0;
  std::string axes;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    if (processing::sensorOfColumn(columns[k]) != sensor) continue;
    double axis_bound = HUGE_VAL;
    double axis_tau = 0.0;
    for (const auto& p : analyses[k].allan) {
      const double b = p.oadev * std::sqrt(3.0 / p.tau_s);
      if (std::isfinite(b) && b > 0.0 && b < axis_bound) axis_bound = b, axis_tau = p.tau_s;
    }
    if (!std::isfinite(axis_bound)) continue;
    axes += (axes.empty() ? "" : ", ") + columns[k];
    if (axis_bound > bound) bound = axis_bound, bound_tau = axis_tau;
  }
  if (bound <= 0.0) return false;
  v.value = inflate * bound * to_si;
  v.note = "upper bound, not a fit: no random walk in the Allan curve of " + axes +
           formatted(", so min over tau of oadev * sqrt(3 / tau) (at tau = %.4g s), the largest of the axes", bound_tau,
                     0.0);
  if (inflate != 1.0) v.note += formatted("; x %.3g (--kalibr-inflate)", inflate, 0.0);
  return true;
}

}  // namespace

bool isAccelColumn(const std::string& name) {
  return std::find(recording::kAccelColumns.begin(), recording::kAccelColumns.end(), name) !=
         recording::kAccelColumns.end();
}

void selectAccelColumns(LoadedInput& in, const std::string& axis) {
  auto& rec = in.recording;
  const bool all = axis == "all";
  if (isAccelColumn(axis)) in.axis_indices.clear();
  for (std::size_t a = 0; a < recording::kAccelColumns.size(); ++a) {
    const std::string name(recording::kAccelColumns[a]);
    auto& column = rec.accel_g[a];
    if ((all || axis == name) && !column.empty()) {
      rec.axis_names.push_back(name);
      rec.axes.push_back(std::move(column));
      in.axis_indices.push_back(rec.axes.size() - 1);
    } else if (axis == name) {
      throwNoSuchAxis(rec, axis);
    }
    column = std::vector<double>();
  }
}

formats::KalibrImu kalibrImuFromAnalyses(const std::vector<std::string>& columns,
                                         const std::vector<processing::AxisAnalysis>& analyses, double rate_hz,
                                         const std::string& source, const KalibrOptions& options,
                                         std::vector<std::string>& missing) {
  formats::KalibrImu imu;
  imu.rostopic = options.rostopic;
  imu.update_rate_hz = rate_hz;
  imu.accelerometer_noise_density =
      kalibrValue(columns, analyses, SensorKind::Accel, processing::noiseDensitySi, options.inflate);
  imu.accelerometer_random_walk =
      kalibrValue(columns, analyses, SensorKind::Accel, processing::biasRandomWalkSi, options.inflate);
  imu.gyroscope_noise_density =
      kalibrValue(columns, analyses, SensorKind::Gyro, processing::noiseDensitySi, options.inflate);
  imu.gyroscope_random_walk =
      kalibrValue(columns, analyses, SensorKind::Gyro, processing::biasRandomWalkSi, options.inflate);
  if (boundUnseenRandomWalk(imu.accelerometer_random_walk, columns, analyses, SensorKind::Accel, options.inflate))
    missing.push_back("accelerometer_random_walk: " + imu.accelerometer_random_walk.note);
  if (boundUnseenRandomWalk(imu.gyroscope_random_walk, columns, analyses, SensorKind::Gyro, options.inflate))
    missing.push_back("gyroscope_random_walk: " + imu.gyroscope_random_walk.note);
  const std::pair<const char*, const formats::KalibrValue*> entries[] = {
      {"accelerometer_noise_density", &imu.accelerometer_noise_density},
      {"accelerometer_random_walk", &imu.accelerometer_random_walk},
      {"gyroscope_noise_density", &imu.gyroscope_noise_density},
      {"gyroscope_random_walk", &imu.gyroscope_random_walk}};
  for (const auto& [key, entry] : entries)
    if (!entry->value) missing.push_back(std::string(key) + ": not estimated (" + entry->note + ")");

  auto& head = imu.header_comments;
  head.push_back("Kalibr IMU noise model of " + source + " from gyroctl analyze --kalibr (docs/coming-from.md).");
  head.push_back("Continuous-time densities from an IEEE 952 fit of the Allan variance of a STATIC record:");
  head.push_back("noise density = angle/velocity random walk N, random walk = rate/acceleration random walk K.");
  head.push_back("Kalibr's wiki (\"IMU Noise Model\") advises inflating Allan values for a moving system");
  head.push_back("(often x10 for the noise density): vibration, temperature and unmodelled errors are not in");
  if (options.inflate == 1.0)
    head.push_back("a static record. These values are NOT inflated; use --kalibr-inflate F to scale them.");
  else
    head.push_back(
        formatted("a static record. These values ARE inflated: x %g (--kalibr-inflate).", options.inflate, 0.0));
  return imu;
}

}  // namespace gyrod::gyroctl
