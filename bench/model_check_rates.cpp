// Detection rate, false-discovery rate and parameter errors of the model check over many
// seeds of the hidden-effect generator (processing/model_check/hidden_effect_generator.hpp).
// Not a unit test and not run by ctest: scripts/model-check-rates.sh builds and runs it.
//
//   model_check_rates [--seeds N] [--first S] [--duration SEC] [--rate HZ] [--replicas R]
//                     [--mode single|clean|two] [--effect NAME] [--verbose]
//
// Per seed: single = one random effect, clean = none, two = two random effects;
// --effect NAME hides that effect in every seed (single mode) instead of a random one.
// A hidden effect is detected when its axis reports an effect of the same name (for
// sample_gaps: every axis). Any other reported effect is a false discovery.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"

using namespace gyrod;
using processing::ModelEffect;

namespace {

struct Tally {
  std::size_t hidden = 0, detected = 0;
  std::map<std::string, std::vector<double>> errors;  // relative (or absolute, see name)
  // Detection against the size of the hidden effect (effectSizes), one entry per hidden effect.
  std::map<std::string, std::vector<std::pair<double, bool>>> by_size;
};

// How large a hidden effect is against the noise of its axis, in the generator's own terms
// (processing/model_check/hidden_effect_generator.hpp draws each of these uniformly in a range):
// what the detection rate depends on. Computed from the truth after the fact, for the table only.
std::vector<std::pair<std::string, double>> effectSizes(const processing::HiddenEffect& h,
                                                        const processing::GeneratedRecording& rec, double duration) {
  const processing::NoiseTerms& terms = rec.terms[h.axis];
  const double white_std = terms.arw_deg_per_sqrt_h / 60.0 * std::sqrt(rec.rate_hz);
  switch (h.effect) {
    case ModelEffect::GaussMarkov: {
      double peak = 0.0;
      for (double tau = h.tau_s / 10.0; tau < h.tau_s * 10.0; tau *= 1.05)
        peak = std::max(peak, processing::gaussMarkovAllanVariance(tau, h.tau_s, h.sigma_dps) /
                                  processing::allanVarianceOfTerms(terms, tau));
      return {{"peak ADEV ratio (GM / base)", std::sqrt(peak)}, {"T / duration", h.tau_s / duration}};
    }
    case ModelEffect::BiasSteps: {
      double floor_adev = 1e300;
      for (double tau = 2.0; tau <= 128.0; tau *= 2.0)
        floor_adev = std::min(floor_adev, std::sqrt(processing::allanVarianceOfTerms(terms, tau)));
      double smallest = 1e300;
      for (double d : h.sizes_dps) smallest = std::min(smallest, std::fabs(d));
      return {{"smallest |step| / ADEV floor", smallest / floor_adev}};
    }
    case ModelEffect::Sinusoid: return {{"amplitude / white sd", h.amp_dps / white_std}};
    default: return {};
  }
}

double quantile(std::vector<double> v, double q) {  // linear interpolation between order statistics
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(pos);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}
double median(std::vector<double> v) { return quantile(std::move(v), 0.5); }

std::string describeHidden(const processing::HiddenEffect& h) {
  char buf[160];
  switch (h.effect) {
    case ModelEffect::TemperatureBias: std::snprintf(buf, sizeof buf, " k=%.3g", h.k_dps_per_c); break;
    case ModelEffect::Sinusoid: std::snprintf(buf, sizeof buf, " f=%.4g amp=%.3g", h.freq_hz, h.amp_dps); break;
    case ModelEffect::GaussMarkov: std::snprintf(buf, sizeof buf, " tau=%.3g sigma=%.3g", h.tau_s, h.sigma_dps); break;
    case ModelEffect::BiasSteps: {
      std::string s = " steps";
      for (std::size_t j = 0; j < h.times_s.size(); ++j) {
        std::snprintf(buf, sizeof buf, " %.1f s:%.3g", h.times_s[j], h.sizes_dps[j]);
        s += buf;
      }
      return s;
    }
    default: return "";
  }
  return buf;
}

void recordErrors(Tally& t, const processing::HiddenEffect& h, const processing::DetectedEffect& d) {
  auto rel = [](double est, double truth) { return std::fabs(est - truth) / std::fabs(truth); };
  switch (h.effect) {
    case ModelEffect::TemperatureBias: t.errors["k rel"].push_back(rel(d.k_dps_per_c, h.k_dps_per_c)); break;
    case ModelEffect::Sinusoid:
      t.errors["freq rel"].push_back(rel(d.freq_hz, h.freq_hz));
      t.errors["amp rel"].push_back(rel(d.amp_dps, h.amp_dps));
      break;
    case ModelEffect::GaussMarkov:
      t.errors["tau rel"].push_back(rel(d.tau_s, h.tau_s));
      t.errors["sigma rel"].push_back(rel(d.sigma_dps, h.sigma_dps));
      break;
    case ModelEffect::BiasSteps: {
      t.errors["count abs"].push_back(std::fabs(static_cast<double>(d.count) - static_cast<double>(h.count)));
      for (double truth : h.times_s) {
        double best = 1e300;
        for (double est : d.times_s) best = std::min(best, std::fabs(est - truth));
        t.errors["time abs s"].push_back(best);
      }
      break;
    }
    case ModelEffect::Outliers:
      t.errors["count abs"].push_back(std::fabs(static_cast<double>(d.count) - static_cast<double>(h.count)));
      break;
    case ModelEffect::SampleGaps:
      t.errors["count abs"].push_back(std::fabs(static_cast<double>(d.count) - static_cast<double>(h.count)));
      t.errors["lost abs"].push_back(std::fabs(static_cast<double>(d.lost) - static_cast<double>(h.lost)));
      break;
    case ModelEffect::NarrowbandLine:
      t.errors["centre rel"].push_back(rel(d.centre_hz, h.centre_hz));
      t.errors["width rel"].push_back(rel(d.width_hz, h.width_hz));
      t.errors["rms rel"].push_back(rel(d.rms_dps, h.rms_dps));
      break;
    case ModelEffect::Unexplained: break;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t seeds = 200, first = 1, replicas = 40;
  double duration = 1200.0, rate = 50.0;
  std::string mode = "single", only;
  bool verbose = false;
  for (int i = 1; i < argc; ++i) {
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", argv[i]);
        std::exit(2);
      }
      return argv[++i];
    };
    if (!std::strcmp(argv[i], "--seeds"))
      seeds = std::strtoull(next(), nullptr, 10);
    else if (!std::strcmp(argv[i], "--first"))
      first = std::strtoull(next(), nullptr, 10);
    else if (!std::strcmp(argv[i], "--duration"))
      duration = std::atof(next());
    else if (!std::strcmp(argv[i], "--rate"))
      rate = std::atof(next());
    else if (!std::strcmp(argv[i], "--replicas"))
      replicas = std::strtoull(next(), nullptr, 10);
    else if (!std::strcmp(argv[i], "--mode"))
      mode = next();
    else if (!std::strcmp(argv[i], "--effect"))
      only = next();
    else if (!std::strcmp(argv[i], "--verbose"))
      verbose = true;
    else {
      std::fprintf(stderr, "unknown option %s\n", argv[i]);
      return 2;
    }
  }
  if (mode != "single" && mode != "clean" && mode != "two") {
    std::fprintf(stderr, "--mode must be single, clean or two\n");
    return 2;
  }

  std::map<std::string, Tally> tallies;
  std::map<std::string, std::size_t> false_by_name;
  std::size_t axes_checked = 0, axes_with_false = 0, false_total = 0;
  double seconds = 0.0;
  for (std::size_t s = first; s < first + seeds; ++s) {
    processing::HiddenEffectGenerator gen(s);
    std::vector<ModelEffect> effects;
    const std::size_t count = mode == "clean" ? 0 : (mode == "single" ? 1 : 2);
    while (effects.size() < count) {
      ModelEffect e = gen.randomEffect();
      for (ModelEffect c : processing::kHideableEffects)
        if (!only.empty() && processing::modelEffectName(c) == only) e = c;
      if (std::find(effects.begin(), effects.end(), e) == effects.end()) effects.push_back(e);
    }
    const processing::GeneratedRecording rec = gen.generate(duration, rate, effects);
    processing::ModelCheckOptions o;
    o.replicas = replicas;
    o.seed = s;
    for (std::size_t a = 0; a < 3; ++a) {
      processing::AxisModelCheckInput in{rec.axes[a], rate, rec.temp, rec.t, {}};
      const auto t0 = std::chrono::steady_clock::now();
      const processing::AxisModelCheck r = processing::checkAxisModel(in, o);
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      ++axes_checked;
      std::vector<bool> used(r.effects.size(), false);
      for (const processing::HiddenEffect& h : rec.hidden) {
        if (h.axis != a && h.effect != ModelEffect::SampleGaps) continue;
        Tally& t = tallies[std::string(processing::modelEffectName(h.effect))];
        if (a == h.axis) ++t.hidden;
        bool found = false;
        for (std::size_t j = 0; j < r.effects.size(); ++j) {
          if (r.effects[j].effect != h.effect || used[j]) continue;
          used[j] = true;
          if (a == h.axis) {
            ++t.detected;
            found = true;
            recordErrors(t, h, r.effects[j]);
          }
          break;
        }
        if (a == h.axis)
          for (const auto& [what, size] : effectSizes(h, rec, duration)) t.by_size[what].push_back({size, found});
      }
      std::size_t false_here = 0;
      for (std::size_t j = 0; j < r.effects.size(); ++j) {
        if (used[j]) continue;
        ++false_here;
        ++false_by_name[std::string(processing::modelEffectName(r.effects[j].effect))];
      }
      false_total += false_here;
      axes_with_false += false_here > 0 ? 1 : 0;
      if (verbose) {
        std::printf("seed %zu axis %zu:", s, a);
        for (const processing::HiddenEffect& h : rec.hidden)
          if (h.axis == a)
            std::printf(" [hidden %s%s]", std::string(processing::modelEffectName(h.effect)).c_str(),
                        describeHidden(h).c_str());
        for (const auto& e : r.effects) std::printf(" %s", std::string(processing::modelEffectName(e.effect)).c_str());
        std::printf("\n");
        bool hidden_here = false;
        for (const processing::HiddenEffect& h : rec.hidden) hidden_here = hidden_here || h.axis == a;
        if (hidden_here)
          for (const auto& st : r.statistics)
            std::printf("    %-40s %11.4g  median %11.4g  threshold %11.4g%s\n", st.name.c_str(), st.value,
                        st.null_median, st.threshold, st.fired ? "  FIRED" : "");
        if (false_here > 0)
          for (const auto& e : r.effects)  // the evidence as numbers (its sentences are gyroctl's)
            std::printf("    %s: statistic %.4g, threshold %.4g, null median %.4g\n",
                        std::string(processing::modelEffectName(e.effect)).c_str(), e.evidence.statistic,
                        e.evidence.threshold, e.evidence.null_median);
      }
    }
  }

  std::printf("model_check_rates: mode %s, %zu seeds from %zu, %.0f s at %g Hz, %zu replicas per round\n", mode.c_str(),
              seeds, first, duration, rate, replicas);
  std::printf("%-17s %7s %9s  %s\n", "effect", "hidden", "detected", "parameter errors: median / 90th percentile");
  for (const auto& [name, t] : tallies) {
    std::printf("%-17s %7zu %8.1f%%  ", name.c_str(), t.hidden, t.hidden ? 100.0 * t.detected / t.hidden : 0.0);
    for (const auto& [pname, v] : t.errors)
      std::printf("%s %.3g / %.3g;  ", pname.c_str(), median(v), quantile(v, 0.9));
    std::printf("\n");
  }
  // Detection by size: each effect's hidden cases in three equal-count groups of its size.
  for (const auto& [name, t] : tallies)
    for (auto [what, cases] : t.by_size) {
      if (cases.size() < 6) continue;
      std::sort(cases.begin(), cases.end());
      std::printf("%-17s by %s:", name.c_str(), what.c_str());
      for (std::size_t g = 0; g < 3; ++g) {
        const std::size_t lo = g * cases.size() / 3, hi = (g + 1) * cases.size() / 3;
        std::size_t found = 0;
        for (std::size_t i = lo; i < hi; ++i) found += cases[i].second ? 1 : 0;
        std::printf("  %.3g..%.3g: %zu/%zu", cases[lo].first, cases[hi - 1].first, found, hi - lo);
      }
      std::printf("\n");
    }
  std::printf("false discoveries: %zu on %zu of %zu axes (%.2f%% of axes)", false_total, axes_with_false, axes_checked,
              100.0 * static_cast<double>(axes_with_false) / static_cast<double>(axes_checked));
  for (const auto& [name, c] : false_by_name) std::printf("; %s %zu", name.c_str(), c);
  std::printf("\nmean time per axis: %.2f s\n", seconds / static_cast<double>(axes_checked));
  return 0;
}
