#pragma once
// The sensor model the live check's integration tests give gyrod (filter.model) and its mock:
// the paper's noise terms on every axis, a 0.5 °/s bias, the temperature steady at 30 °C, no
// temperature coupling known (the coefficient 0 ± 0.05 °/s per °C). inline: each test file of a
// unity batch includes it.
#include <sstream>
#include <string>

namespace gyrod::test {

inline std::string liveCheckSensorModel() {
  std::ostringstream m;
  m << "rate_hz = 50\n[temperature]\nstart_c = 30\nfinal_c = 30\ntime_constant_s = 900.0\nnoise_std_c = 0.02\n";
  for (const char* axis : {"x", "y", "z"}) {
    m << "[" << axis << "]\nquantization_urad = 0.1663\narw_deg_per_sqrt_h = 0.95164\n"
      << "bias_instability_deg_per_h = 0.60565\nrrw_deg_per_h_sqrt_h = 0.07759\nbias_dps = 0.5\n"
      << "[" << axis << ".calibration]\nbias_std_dps = 0.02\ntemperature_coefficient_dps_per_c = 0.0\n"
      << "temperature_coefficient_std_dps_per_c = 0.05\ntemperature_reference_c = 25.0\n";
  }
  return m.str();
}

}  // namespace gyrod::test
