#include "processing/base/noise_units.hpp"

#include <stdexcept>

#include "processing/base/units.hpp"

namespace gyrod::processing {
namespace {

using namespace gyrod::units;

std::vector<NoiseFigure> gyroFigures(NoiseTerm term, double v) {
  const std::string_view paper_key = noiseTermKey(term), paper_label = noiseTermLabel(term);
  switch (term) {
    case NoiseTerm::Quantization:
      return {{paper_key, paper_label, v}, {"quantization_rad", "quantization Q [rad]", microradToRad(v)}};
    case NoiseTerm::AngleRandomWalk:
      return {
          {paper_key, paper_label, v},
          {"arw_rad_per_s_sqrt_hz", "angle random walk N [rad/s/sqrt(Hz)]", arwDegPerSqrtHourToRadPerSecondSqrtHz(v)}};
    case NoiseTerm::BiasInstability:
      return {{paper_key, paper_label, v},
              {"bias_instability_rad_per_s", "bias instability B [rad/s]", degPerHourToRadPerSecond(v)}};
    case NoiseTerm::RateRandomWalk:
      return {{paper_key, paper_label, v},
              {"rrw_rad_per_s2_sqrt_hz", "rate random walk K [rad/s^2/sqrt(Hz)]",
               rrwDegPerHourSqrtHourToRadPerSecond2SqrtHz(v)}};
    case NoiseTerm::RateRamp:
      return {{paper_key, paper_label, v},
              {"rate_ramp_rad_per_s2", "rate ramp R [rad/s^2]", degPerHour2ToRadPerSecond2(v)}};
  }
  throw std::invalid_argument("unknown noise term");
}

// `v` is the fit's number for a series in g read as if in °/s: the paper's time conversions
// (s → h) are already in it, so the unit g only becomes m/s² (× standard gravity).
std::vector<NoiseFigure> accelFigures(NoiseTerm term, double v) {
  switch (term) {
    case NoiseTerm::Quantization:  // Q: √3·Q/τ with Q in g·s = (µrad number → "°") g·s
      return {{"velocity_quantization_m_per_s", "velocity quantization [m/s]", gToMetresPerSecond2(microradToDeg(v))}};
    case NoiseTerm::AngleRandomWalk: {
      const double vrw = gToMetresPerSecond2(v);
      return {{"vrw_m_per_s_per_sqrt_h", "velocity random walk [m/s/sqrt(h)]", vrw},
              {"vrw_m_per_s2_sqrt_hz", "velocity random walk [m/s^2/sqrt(Hz)]",
               vrwMetresPerSecondSqrtHourToMetresPerSecond2SqrtHz(vrw)}};
    }
    case NoiseTerm::BiasInstability: {
      const double mg = 1e3 * degPerHourToDegPerSecond(v);
      return {{"bias_instability_mg", "bias instability [mg]", mg},
              {"bias_instability_m_per_s2", "bias instability [m/s^2]", milligToMetresPerSecond2(mg)}};
    }
    case NoiseTerm::RateRandomWalk: {
      const double arw = gToMetresPerSecond2(v);
      return {{"accel_random_walk_m_per_s_per_h_sqrt_h", "acceleration random walk [m/s/h^1.5]", arw},
              {"accel_random_walk_m_per_s3_sqrt_hz", "acceleration random walk [m/s^3/sqrt(Hz)]",
               accelRandomWalkMetresPerSecondHourSqrtHourToSi(arw)}};
    }
    case NoiseTerm::RateRamp: {
      const double ramp = gToMetresPerSecond2(v);
      return {{"accel_ramp_m_per_s_per_h2", "acceleration ramp [m/s/h^2]", ramp},
              {"accel_ramp_m_per_s3", "acceleration ramp [m/s^3]", metresPerSecondHour2ToMetresPerSecond3(ramp)}};
    }
  }
  throw std::invalid_argument("unknown noise term");
}

}  // namespace

SensorKind sensorOfColumn(std::string_view column) {
  return column == "ax" || column == "ay" || column == "az" ? SensorKind::Accel : SensorKind::Gyro;
}

std::vector<NoiseFigure> noiseFigures(NoiseTerm term, double value, SensorKind sensor) {
  return sensor == SensorKind::Gyro ? gyroFigures(term, value) : accelFigures(term, value);
}

double noiseDensitySi(const NoiseTerms& terms, SensorKind sensor) {
  return noiseFigures(NoiseTerm::AngleRandomWalk, terms.arw_deg_per_sqrt_h, sensor).back().value;
}

double biasRandomWalkSi(const NoiseTerms& terms, SensorKind sensor) {
  return noiseFigures(NoiseTerm::RateRandomWalk, terms.rrw_deg_per_h_sqrt_h, sensor).back().value;
}

}  // namespace gyrod::processing
