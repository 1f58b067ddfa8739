// Coverage of the model check's stated 95 % parameter intervals (docs/model-check.md,
// "Intervals"): each effect hidden alone at a known, seeded parameter in a clean gyrod-like
// record (processing/model_check/hidden_effect_generator.hpp), the check run on that axis, and for each
// parameter: trials, detected, intervals stated, intervals containing the truth (count,
// fraction, two-sided 95 % Clopper–Pearson interval of the coverage). The goal of issue 13 is
// coverage ≥ 90 %. Not a unit test and not run by ctest: scripts/model-check-coverage.sh.
//
//   model_check_coverage [--trials N] [--first S] [--duration SEC] [--rate HZ] [--replicas R]
//                        [--effect NAME] [--threads T] [--dlpf CFG]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bench/binomial_bounds.hpp"
#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"

using namespace gyrod::processing;

namespace {

struct Tally {
  std::size_t trials = 0, detected = 0, stated = 0, contained = 0;
  void add(const ParameterInterval& i, double truth) {
    ++stated;
    contained += i.contains(truth) ? 1 : 0;
  }
};

const DetectedEffect* findEffect(const AxisModelCheck& r, ModelEffect e, double freq = 0.0) {
  const DetectedEffect* best = nullptr;
  for (const DetectedEffect& d : r.effects) {
    if (d.effect != e) continue;
    if (!best || std::fabs(d.freq_hz - freq) < std::fabs(best->freq_hz - freq)) best = &d;
  }
  return best;
}

// Every parameter's tally of one trial: the hidden effect h against what the check said.
void score(const HiddenEffect& h, const AxisModelCheck& r, double duration, std::map<std::string, Tally>& t) {
  const DetectedEffect* d = findEffect(r, h.effect, h.freq_hz);
  auto tally = [&](const std::string& name) -> Tally& {
    Tally& x = t[name];
    ++x.trials;
    if (d) ++x.detected;
    return x;
  };
  switch (h.effect) {
    case ModelEffect::TemperatureBias: {
      Tally& x = tally("temperature_bias k_dps_per_c");
      if (d && d->k_interval.stated) x.add(d->k_interval, h.k_dps_per_c);
      break;
    }
    case ModelEffect::Sinusoid: {
      Tally& x = tally("sinusoid amp_dps");
      // Only a line found at the hidden frequency speaks about its amplitude.
      if (d && std::fabs(d->freq_hz - h.freq_hz) < 2.0 / duration && d->amp_interval.stated)
        x.add(d->amp_interval, h.amp_dps);
      if (d && std::getenv("COVERAGE_VERBOSE"))
        std::printf("sinusoid: amp %g in [%g, %g] est %g; freq %g est %g; further components %zu\n", h.amp_dps,
                    d->amp_interval.lo, d->amp_interval.hi, d->amp_dps, h.freq_hz, d->freq_hz,
                    d->evidence.further_components.size());
      break;
    }
    case ModelEffect::GaussMarkov: {
      Tally& s = tally("gauss_markov sigma_dps");
      Tally& tau = tally("gauss_markov tau_s");
      if (d && d->sigma_interval.stated) s.add(d->sigma_interval, h.sigma_dps);
      if (d && std::getenv("COVERAGE_VERBOSE"))
        std::printf("gm: T %g in [%g, %g] est %g; sigma %g in [%g, %g] est %g\n", h.tau_s, d->tau_interval.lo,
                    d->tau_interval.hi, d->tau_s, h.sigma_dps, d->sigma_interval.lo, d->sigma_interval.hi,
                    d->sigma_dps);
      if (d && d->tau_interval.stated) tau.add(d->tau_interval, h.tau_s);
      break;
    }
    case ModelEffect::BiasSteps: {
      // Per hidden step: the detected step nearest in time (within 2 % of the record).
      for (std::size_t j = 0; j < h.times_s.size(); ++j) {
        Tally& x = t["bias_steps size_dps (per step)"];
        ++x.trials;
        if (!d) continue;
        std::optional<std::size_t> at;
        for (std::size_t k = 0; k < d->times_s.size(); ++k)
          if (std::fabs(d->times_s[k] - h.times_s[j]) < 0.02 * duration &&
              (!at || std::fabs(d->times_s[k] - h.times_s[j]) < std::fabs(d->times_s[*at] - h.times_s[j])))
            at = k;
        if (!at) continue;
        ++x.detected;
        if (*at < d->size_intervals.size() && d->size_intervals[*at].stated)
          x.add(d->size_intervals[*at], h.sizes_dps[j]);
      }
      break;
    }
    case ModelEffect::Outliers: {
      Tally& c = tally("outliers count");
      Tally& a = tally("outliers amplitude_dps");
      if (d && d->count_interval.stated) c.add(d->count_interval, static_cast<double>(h.count));
      if (d && d->outlier_amplitude_interval.stated) a.add(d->outlier_amplitude_interval, h.amp_dps);
      if (d && std::getenv("COVERAGE_VERBOSE"))
        std::printf("outliers: count %zu in [%g, %g] est %zu; amp %g in [%g, %g] est %g\n", h.count,
                    d->count_interval.lo, d->count_interval.hi, d->count, h.amp_dps, d->outlier_amplitude_interval.lo,
                    d->outlier_amplitude_interval.hi, d->outlier_median_amplitude_dps);
      break;
    }
    default: break;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t trials = 40, first = 5000, replicas = 40, threads = 0;
  double duration = 600.0, rate = 50.0;
  std::string only;
  std::optional<int> dlpf;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const char* v = argv[i + 1];
    if (key == "--trials")
      trials = std::strtoul(v, nullptr, 10);
    else if (key == "--first")
      first = std::strtoul(v, nullptr, 10);
    else if (key == "--duration")
      duration = std::strtod(v, nullptr);
    else if (key == "--rate")
      rate = std::strtod(v, nullptr);
    else if (key == "--replicas")
      replicas = std::strtoul(v, nullptr, 10);
    else if (key == "--threads")
      threads = std::strtoul(v, nullptr, 10);
    else if (key == "--effect")
      only = v;
    else if (key == "--dlpf")
      dlpf = std::atoi(v);
    else {
      std::fprintf(stderr, "model_check_coverage: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  const std::vector<ModelEffect> effects{ModelEffect::TemperatureBias, ModelEffect::Sinusoid, ModelEffect::GaussMarkov,
                                         ModelEffect::BiasSteps, ModelEffect::Outliers};
  std::map<std::string, Tally> tallies;
  for (ModelEffect e : effects) {
    if (!only.empty() && only != modelEffectName(e)) continue;
    for (std::size_t s = first; s < first + trials; ++s) {
      HiddenEffectGenerator gen(s);
      gen.dlpf_cfg = dlpf;
      const GeneratedRecording g = gen.generate(duration, rate, {e});
      const HiddenEffect& h = g.hidden.front();
      ModelCheckOptions o;
      o.seed = s;
      o.replicas = replicas;
      o.threads = threads;
      const AxisModelCheck r = checkAxisModel(
          {g.axes[h.axis], g.rate_hz, g.temp, g.t, {dlpf, dlpf ? std::optional<int>(0) : std::nullopt}}, o);
      score(h, r, duration, tallies);
    }
  }
  std::printf(
      "coverage of the stated 95 %% intervals: one effect hidden per %g s record at %g Hz%s, %zu trials from "
      "seed %zu, %zu replicas\n\n",
      duration, rate, dlpf ? (" through DLPF_CFG " + std::to_string(*dlpf)).c_str() : "", trials, first, replicas);
  std::printf(
      "| parameter | trials | detected | interval stated | contains truth | coverage | 95 %% CI of coverage |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const auto& [name, t] : tallies) {
    const auto ci = gyrod::bench::clopperPearson95(t.contained, t.stated);
    std::printf("| %s | %zu | %zu | %zu | %zu | %.1f %% | %.1f–%.1f %% |\n", name.c_str(), t.trials, t.detected,
                t.stated, t.contained,
                t.stated ? 100.0 * static_cast<double>(t.contained) / static_cast<double>(t.stated) : 0.0,
                100.0 * ci.lo, 100.0 * ci.hi);
  }
  return 0;
}
