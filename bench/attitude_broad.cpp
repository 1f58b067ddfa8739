// The attitude estimator (processing/attitude/) on BROAD trials: per trial the inclination and
// heading RMSE over the movement phases (heading: mean offset removed), their means, and the
// cost per sample. docs/attitude.md lists the figures and the command.
// Usage: attitude_broad DIRECTORY [--errors] [--set NAME=VALUE]... [TRIAL...]
//   --errors: under each trial, the motion errors learned by its end (scale errors, cross-axis
//   terms, lever arm, accel delay).
//   TRIAL: default every NAME.truth.csv.gz in DIRECTORY; --set overrides an AttitudeParameters
//   field (tau, norm_scale, estimate_bias, rest_bias_tc, motion_bias_tc, rest_gyro, rest_accel,
//   rest_duration, bias_limit; the motion errors: estimate_sensitivity, estimate_cross_axis,
//   estimate_lever_arm, estimate_accel_delay, s_init, x_init, r_init, r_rw, b_init, b_rw, delay_init,
//   c_noise), for exploring the parameters.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "bench/broad_trial.hpp"

namespace {

std::vector<std::string> trialNames(const std::string& directory) {
  std::vector<std::string> names;
  const std::string truth_suffix = ".truth.csv.gz";
  for (const auto& entry : std::filesystem::directory_iterator(directory)) {
    const std::string file = entry.path().filename().string();
    if (file.size() > truth_suffix.size() &&
        file.compare(file.size() - truth_suffix.size(), truth_suffix.size(), truth_suffix) == 0)
      names.push_back(file.substr(0, file.size() - truth_suffix.size()));
  }
  std::sort(names.begin(), names.end());
  return names;
}

bool setParameter(gyrod::processing::attitude::AttitudeParameters& p, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos) return false;
  const std::string key = assignment.substr(0, eq);
  const double v = std::strtod(assignment.c_str() + eq + 1, nullptr);
  const std::map<std::string, double*> fields = {{"tau", &p.accel_time_constant_s},
                                                 {"norm_scale", &p.accel_norm_scale_g},
                                                 {"rest_bias_tc", &p.rest_bias_time_constant_s},
                                                 {"motion_bias_tc", &p.motion_bias_time_constant_s},
                                                 {"rest_gyro", &p.rest_gyro_deviation_dps},
                                                 {"rest_accel", &p.rest_accel_deviation_g},
                                                 {"rest_duration", &p.rest_duration_s},
                                                 {"bias_limit", &p.bias_limit_dps},
                                                 {"s_init", &p.motion_errors.sensitivity_initial_std},
                                                 {"x_init", &p.motion_errors.cross_axis_initial_std},
                                                 {"delay_init", &p.motion_errors.accel_delay_initial_std_s},
                                                 {"r_init", &p.motion_errors.lever_arm_initial_std_m},
                                                 {"r_rw", &p.motion_errors.lever_arm_random_walk_m_per_sqrt_s},
                                                 {"b_init", &p.motion_errors.bias_initial_std_rad_s},
                                                 {"b_rw", &p.motion_errors.bias_random_walk_rad_s_per_sqrt_s},
                                                 {"c_noise", &p.motion_errors.correction_noise_density}};
  const std::map<std::string, bool*> switches = {{"estimate_bias", &p.estimate_bias},
                                                 {"estimate_sensitivity", &p.estimate_sensitivity},
                                                 {"estimate_cross_axis", &p.estimate_cross_axis},
                                                 {"estimate_lever_arm", &p.estimate_lever_arm},
                                                 {"estimate_accel_delay", &p.estimate_accel_delay}};
  if (const auto on = switches.find(key); on != switches.end()) {
    *on->second = v != 0.0;
    return true;
  }
  const auto it = fields.find(key);
  if (it == fields.end()) return false;
  *it->second = v;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace gyrod;
  if (argc < 2) {
    std::fprintf(stderr, "usage: attitude_broad DIRECTORY [NAME...]\n");
    return 64;
  }
  const std::string directory = argv[1];
  processing::attitude::AttitudeParameters params;
  std::vector<std::string> names;
  bool print_errors = false;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--errors") {
      print_errors = true;
    } else if (arg == "--set" && i + 1 < argc) {
      if (!setParameter(params, argv[++i])) {
        std::fprintf(stderr, "attitude_broad: --set %s: unknown parameter or no '='\n", argv[i]);
        return 64;
      }
    } else {
      names.push_back(arg);
    }
  }
  try {
    if (names.empty()) names = trialNames(directory);
    if (names.empty()) {
      std::fprintf(stderr, "%s: no NAME.truth.csv.gz files\n", directory.c_str());
      return 66;
    }
    double sum_incl = 0.0, sum_heading = 0.0, total_ns = 0.0, total_samples = 0.0;
    std::printf("%-45s %10s %10s %9s\n", "trial", "incl[deg]", "head[deg]", "moving[s]");
    for (const auto& name : names) {
      const broad::Trial trial = broad::readTrial(directory, name);
      const auto start = std::chrono::steady_clock::now();
      processing::attitude::AttitudeSample last;
      const auto q = broad::estimateTrial(trial, params, &last);
      const auto stop = std::chrono::steady_clock::now();
      total_ns += std::chrono::duration<double, std::nano>(stop - start).count();
      total_samples += static_cast<double>(q.size());
      const broad::TrialErrors e = broad::broadErrors(q, trial);
      std::printf("%-45s %10.3f %10.3f %9.1f\n", name.c_str(), e.inclination_rmse_deg, e.heading_rmse_deg,
                  static_cast<double>(e.samples) / trial.rate_hz);
      if (print_errors) {
        const auto& sens = last.gyro_sensitivity_error;
        const auto& cross = last.gyro_cross_axis;
        const auto& r = last.lever_arm_m;
        std::printf(
            "  scale %+.2f %+.2f %+.2f %%, cross-axis xy %+.2f xz %+.2f yz %+.2f %%, lever arm %+.1f %+.1f %+.1f cm, "
            "accel delay %+.2f ms\n",
            100 * sens[0], 100 * sens[1], 100 * sens[2], 100 * cross[0], 100 * cross[1], 100 * cross[2], 100 * r[0],
            100 * r[1], 100 * r[2], 1e3 * last.accel_delay_s);
      }
      sum_incl += e.inclination_rmse_deg;
      sum_heading += e.heading_rmse_deg;
    }
    const double n = static_cast<double>(names.size());
    std::printf("%-45s %10.3f %10.3f\n", "mean", sum_incl / n, sum_heading / n);
    std::printf("cost: %.1f ns/sample (%.0f samples, one thread)\n", total_ns / total_samples, total_samples);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "attitude_broad: %s\n", e.what());
    return 65;
  }
  return 0;
}
