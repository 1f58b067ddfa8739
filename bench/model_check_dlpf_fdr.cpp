// False discoveries of the model check on clean gyrod-like recordings made through every DLPF
// setting (processing/model_check/hidden_effect_generator.hpp with its dlpf_cfg set; the check told the
// chain, as gyrod's '# device' header tells it), and without a DLPF (`--cfg none`: 50 Hz,
// FS_SEL 0 told, no DLPF — where the Gauss–Markov null is the joint fit's). Any effect
// reported on an axis is a false discovery. Not a unit test and not run by ctest: scripts/model-check-dlpf-fdr.sh builds and
// runs it; the table is in docs/model-check.md.
//
//   model_check_dlpf_fdr [--seeds N] [--first S] [--duration SEC] [--replicas R] [--cfg C|none]
//                        [--threads T] [--rows-only 1] [--verbose 1|2]
// Without --cfg: the settings 0..6 (not `none`).
// The upper bound is Clopper–Pearson's, one-sided 95 % (0 of 300 axes: 1.0 %). --verbose
// prints the base fit against the truth and the measured/replica-median Allan ratio per τ
// of each flagged axis (2: of every axis).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench/binomial_bounds.hpp"
#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"

using namespace gyrod::processing;

using gyrod::bench::clopperPearsonUpper95;

int main(int argc, char** argv) {
  std::size_t seeds = 20, first = 1000, replicas = 40;
  double duration = 600.0;
  // The settings to run: 0..6 by default; kNone is "no DLPF".
  constexpr int kNone = -1, kAll = -2;
  int only_cfg = kAll;
  int verbose = 0;
  std::size_t threads = 0;
  bool rows_only = false;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const char* v = argv[i + 1];
    if (key == "--seeds")
      seeds = std::strtoul(v, nullptr, 10);
    else if (key == "--first")
      first = std::strtoul(v, nullptr, 10);
    else if (key == "--duration")
      duration = std::strtod(v, nullptr);
    else if (key == "--replicas")
      replicas = std::strtoul(v, nullptr, 10);
    else if (key == "--threads")
      threads = std::strtoul(v, nullptr, 10);
    else if (key == "--rows-only")
      rows_only = std::atoi(v) != 0;
    else if (key == "--verbose")
      verbose = std::atoi(v);
    else if (key == "--cfg")
      only_cfg = std::string(v) == "none" ? kNone : std::atoi(v);
    else {
      std::fprintf(stderr, "model_check_dlpf_fdr: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  // Each setting at a rate it allows (the narrow ones at gyrod's default 50 Hz).
  const std::vector<std::pair<int, double>> settings{{kNone, 50.0}, {0, 100.0}, {1, 200.0}, {2, 200.0},
                                                     {3, 100.0},    {4, 50.0},  {5, 50.0},  {6, 50.0}};
  if (!rows_only) {
    std::printf("clean %g s records through each DLPF setting, %zu seeds from %zu, %zu replicas, 3 axes each\n\n",
                duration, seeds, first, replicas);
    std::printf(
        "| DLPF_CFG | rate [Hz] | axes | false discoveries | per axis | 95 %% upper bound | effects named | "
        "does not fit (whiteness, band) | 95 %% upper bound | smallest whiteness p | smallest band p | band at 0.01 |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  }
  std::size_t all_axes = 0, all_false = 0, all_misfit = 0;
  // The pass rule on these clean axes (held-out whiteness p ≥ 0.01 and ≥ 90 % of the
  // Allan curve in band), with the simultaneous band and with the per-τ band: how often a
  // right model fails it.
  std::size_t rule_fails_joint = 0, rule_fails_per_tau = 0;
  const auto start = std::chrono::steady_clock::now();
  for (const auto& [cfg, rate] : settings) {
    if (only_cfg == kAll ? cfg == kNone : cfg != only_cfg) continue;
    const std::optional<int> dlpf = cfg == kNone ? std::nullopt : std::optional<int>(cfg);
    std::size_t axes = 0, false_axes = 0, misfit = 0, white_fails = 0, band_fails = 0;
    double min_p = 1.0, min_band_p = 1.0;
    std::size_t band_at_1e2 = 0;
    std::map<std::string, std::size_t> named;
    for (std::size_t s = first; s < first + seeds; ++s) {
      HiddenEffectGenerator gen(s);
      gen.dlpf_cfg = dlpf;
      // The same number of samples at every rate: the check's cost and power depend on it.
      const GeneratedRecording g = gen.generate(duration * 50.0 / rate, rate, {});
      for (std::size_t a = 0; a < 3; ++a) {
        ModelCheckOptions o;
        o.seed = s;
        o.replicas = replicas;
        o.threads = threads;
        const AxisModelCheck r = checkAxisModel({g.axes[a], g.rate_hz, g.temp, g.t, {dlpf, 0}}, o);
        ++axes;
        if (!r.effects.empty()) ++false_axes;
        misfit += r.misfit.fails() ? 1 : 0;
        const bool white = r.misfit.ljung_box_p_held_out >= 0.01;
        const double per_tau = r.verdict.judged && r.verdict.accepted ? r.gain.in_band_extended : r.gain.in_band_base;
        rule_fails_joint += (white && r.misfit.in_band >= 0.9) ? 0 : 1;
        rule_fails_per_tau += (white && per_tau >= 0.9) ? 0 : 1;
        white_fails += r.misfit.whiteness_fails ? 1 : 0;
        band_fails += r.misfit.band_fails ? 1 : 0;
        min_p = std::min(min_p, r.misfit.ljung_box_p_held_out);
        if (std::isfinite(r.misfit.band_p)) min_band_p = std::min(min_band_p, r.misfit.band_p);
        band_at_1e2 += (r.misfit.in_band < r.misfit.in_band_replica_lowest && r.misfit.band_p < 0.01) ? 1 : 0;
        if (verbose && r.misfit.fails())
          std::printf(
              "seed %zu axis %zu does not fit: whiteness p %.3g (Q %.4g, replicas' median %.4g, AR(%zu)), in band %.3f (replicas median %.3f, "
              "lowest %.3f, p %.3g)\n",
              s, a, r.misfit.ljung_box_p_held_out, r.misfit.whiteness_q, r.misfit.whiteness_q_replica_median,
              r.misfit.whiteness_ar_order, r.misfit.in_band, r.misfit.in_band_replica_median,
              r.misfit.in_band_replica_lowest, r.misfit.band_p);
        if (verbose > 1 || (verbose && !r.effects.empty())) {
          std::printf("seed %zu axis %zu:", s, a);
          for (const DetectedEffect& e : r.effects)
            std::printf(" %s(tau %g sigma %g where %g-%g freq %g centre %g width %g; statistic %g threshold %g)",
                        std::string(modelEffectName(e.effect)).c_str(), e.tau_s, e.sigma_dps, e.where_lo, e.where_hi,
                        e.freq_hz, e.centre_hz, e.width_hz, e.evidence.statistic, e.evidence.threshold);
          const NoiseTerms& tt = g.terms[a];
          const NoiseTerms& ft = r.base_fit.value;
          std::printf("\n  truth Q %.3g N %.3g B %.3g K %.3g R %.3g | fit Q %.3g N %.3g B %.3g K %.3g R %.3g chi2 %.3g",
                      tt.quantization_urad, tt.arw_deg_per_sqrt_h, tt.bias_instability_deg_per_h,
                      tt.rrw_deg_per_h_sqrt_h, tt.rate_ramp_deg_per_h2, ft.quantization_urad, ft.arw_deg_per_sqrt_h,
                      ft.bias_instability_deg_per_h, ft.rrw_deg_per_h_sqrt_h, ft.rate_ramp_deg_per_h2,
                      r.base_fit.reduced_chi2);
          std::printf("\n  tau measured/median:");
          for (std::size_t j = 0; j < r.allan_base.tau_s.size() && r.allan_base.tau_s[j] < 30.0; ++j)
            std::printf(" %g:%.3f", r.allan_base.tau_s[j], r.allan_base.measured[j] / r.allan_base.median[j]);
          std::printf("\n");
        }
        for (const DetectedEffect& e : r.effects) ++named[std::string(modelEffectName(e.effect))];
      }
    }
    std::string list;
    for (const auto& [name, count] : named) list += (list.empty() ? "" : ", ") + name + " " + std::to_string(count);
    std::printf("| %s | %g | %zu | %zu | %.2f %% | %.2f %% | %s | %zu (%zu, %zu) | %.2f %% | %.2g | %.2g | %zu |\n",
                cfg == kNone ? "none" : std::to_string(cfg).c_str(), rate, axes, false_axes,
                100.0 * static_cast<double>(false_axes) / static_cast<double>(axes),
                100.0 * clopperPearsonUpper95(false_axes, axes), list.empty() ? "none" : list.c_str(), misfit,
                white_fails, band_fails, 100.0 * clopperPearsonUpper95(misfit, axes), min_p, min_band_p, band_at_1e2);
    std::fflush(stdout);
    all_axes += axes;
    all_false += false_axes;
    all_misfit += misfit;
  }
  if (rows_only) return 0;
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("\nall settings: %zu of %zu axes (%.2f %%, 95 %% upper bound %.2f %%); %.0f s\n", all_false, all_axes,
              100.0 * static_cast<double>(all_false) / static_cast<double>(all_axes),
              100.0 * clopperPearsonUpper95(all_false, all_axes), secs);
  std::printf("does not fit: %zu of %zu axes (%.2f %%, 95 %% upper bound %.2f %%)\n", all_misfit, all_axes,
              100.0 * static_cast<double>(all_misfit) / static_cast<double>(all_axes),
              100.0 * clopperPearsonUpper95(all_misfit, all_axes));
  std::printf(
      "fail the pass rule (held-out whiteness p >= 0.01 and >= 90 %% in band): %zu of %zu axes (%.1f %%) with the "
      "simultaneous band, %zu (%.1f %%) with the per-tau band\n",
      rule_fails_joint, all_axes, 100.0 * static_cast<double>(rule_fails_joint) / static_cast<double>(all_axes),
      rule_fails_per_tau, 100.0 * static_cast<double>(rule_fails_per_tau) / static_cast<double>(all_axes));
  return 0;
}
