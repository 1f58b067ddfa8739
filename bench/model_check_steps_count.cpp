// Several bias steps per axis (issue 36): the hidden-effect generator hides 3–7 steps (random
// signs, sizes uniform over --lo..--hi × the axis's ADEV floor, times uniform over 0.1–0.9 of
// the record and at least --gap × the duration apart) on one axis of a 50 Hz record, and the
// model check runs on that axis with the t and temperature columns. Per seed: the steps hidden
// and found, and CPU seconds; at the end, the seeds whose count is exact, with the two-sided
// 95 % Wilson interval. Not a unit test (ModelCheckSteps.ThreeToSevenStepsOfDifferentSizesAre-
// CountedExactly is the seeded one); the figures are in docs/model-check.md.
//
//   model_check_steps_count [--first S] [--seeds N] [--lo X] [--hi X] [--duration SEC] [--gap F]
//                           [--threads T]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>

#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"

using namespace gyrod::processing;

int main(int argc, char** argv) {
  std::size_t first = 901, seeds = 20, threads = 1;
  double lo = 17.0, hi = 34.0, duration = 600.0, gap = 0.05;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const char* v = argv[i + 1];
    if (key == "--first")
      first = std::strtoul(v, nullptr, 10);
    else if (key == "--seeds")
      seeds = std::strtoul(v, nullptr, 10);
    else if (key == "--lo")
      lo = std::strtod(v, nullptr);
    else if (key == "--hi")
      hi = std::strtod(v, nullptr);
    else if (key == "--duration")
      duration = std::strtod(v, nullptr);
    else if (key == "--gap")
      gap = std::strtod(v, nullptr);
    else if (key == "--threads")
      threads = std::strtoul(v, nullptr, 10);
    else {
      std::fprintf(stderr, "model_check_steps_count: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  std::size_t exact = 0;
  for (std::size_t s = first; s < first + seeds; ++s) {
    HiddenEffectGenerator gen(s);
    gen.step_size_lo = lo;
    gen.step_size_hi = hi;
    gen.step_count_lo = 3;
    gen.step_count_hi = 7;
    gen.step_min_gap = gap;
    const GeneratedRecording g = gen.generate(duration, 50.0, {ModelEffect::BiasSteps});
    const HiddenEffect& h = g.hidden[0];
    ModelCheckOptions o;
    o.seed = s;
    o.threads = threads;
    const std::clock_t start = std::clock();
    const AxisModelCheck r = checkAxisModel({g.axes[h.axis], g.rate_hz, g.temp, g.t, {}}, o);
    const double cpu = static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
    std::size_t found = 0;
    for (const DetectedEffect& e : r.effects)
      if (e.effect == ModelEffect::BiasSteps) found = e.count;
    exact += found == h.count ? 1 : 0;
    std::printf("seed %zu: %zu hidden, %zu found%s, %.1f s CPU\n", s, h.count, found, found == h.count ? "" : " (off)",
                cpu);
  }
  // Wilson's interval of the exact share.
  const double n = static_cast<double>(seeds), p = static_cast<double>(exact) / n, z = 1.959964;
  const double centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
  const double half = z * std::sqrt(p * (1.0 - p) / n + z * z / (4.0 * n * n)) / (1.0 + z * z / n);
  std::printf("count exact in %zu of %zu seeds (%.0f %%, Wilson 95 %% %.0f-%.0f %%)\n", exact, seeds, 100.0 * p,
              100.0 * (centre - half), 100.0 * (centre + half));
  return 0;
}
