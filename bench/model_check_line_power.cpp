// Detection power of the model check for a line whose frequency wanders (a narrowband line,
// processing/simulation/narrowband_line.hpp) against the fixed-sinusoid detector's, over many
// seeds of the hidden-effect generator: per line rms, how often the single-bin peak statistic
// (`spectral_peak_log_ratio`, the sinusoid detector's) fires on the line's axis, and how often
// the check names a narrowband line there (centre within 1 %, width within a factor 1.5).
// Not a unit test and not run by ctest; the table is in docs/model-check.md.
//
//   model_check_line_power [--seeds N] [--first S] [--duration SEC] [--rate HZ] [--width HZ]
//                          [--rms F1,F2,...] [--replicas R] [--threads T] [--write-csv PREFIX]
// rms in multiples of the axis's white-noise sd; defaults: 100 seeds from 5000, 600 s at
// 50 Hz, width 0.3 Hz, rms 0.05,0.07,0.1,0.14,0.2. --write-csv writes each record as
// PREFIX<rms>-<seed>.csv (t,gx,gy,gz,temp, as `gyroctl model-check` reads it) and prints
// what was hidden where.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"

using namespace gyrod::processing;

int main(int argc, char** argv) {
  std::size_t seeds = 100, first = 5000, replicas = 40, threads = 0;
  std::string csv_prefix;
  double duration = 600.0, rate = 50.0, width = 0.3;
  std::vector<double> rms_factors{0.05, 0.07, 0.1, 0.14, 0.2};
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
    else if (!std::strcmp(argv[i], "--width"))
      width = std::atof(next());
    else if (!std::strcmp(argv[i], "--replicas"))
      replicas = std::strtoull(next(), nullptr, 10);
    else if (!std::strcmp(argv[i], "--threads"))
      threads = std::strtoull(next(), nullptr, 10);
    else if (!std::strcmp(argv[i], "--write-csv"))
      csv_prefix = next();
    else if (!std::strcmp(argv[i], "--rms")) {
      rms_factors.clear();
      std::stringstream list(next());
      for (std::string item; std::getline(list, item, ',');) rms_factors.push_back(std::atof(item.c_str()));
    } else {
      std::fprintf(stderr, "unknown option %s\n", argv[i]);
      return 2;
    }
  }
  std::printf("model_check_line_power: %zu seeds from %zu, %.0f s at %g Hz, width %g Hz, %zu replicas\n", seeds, first,
              duration, rate, width, replicas);
  std::printf("%-12s %22s %22s %22s\n", "rms/white sd", "peak statistic fired", "named narrowband",
              "named, centre+width ok");
  for (double f : rms_factors) {
    std::size_t fired = 0, named = 0, right = 0;
    for (std::size_t s = first; s < first + seeds; ++s) {
      HiddenEffectGenerator gen(s);
      gen.line_width_lo = gen.line_width_hi = width;
      gen.line_rms_lo = gen.line_rms_hi = f;
      const GeneratedRecording rec = gen.generate(duration, rate, {ModelEffect::NarrowbandLine});
      const HiddenEffect& h = rec.hidden.at(0);
      if (!csv_prefix.empty()) {
        const std::string name = csv_prefix + std::to_string(f) + "-" + std::to_string(s) + ".csv";
        if (FILE* out = std::fopen(name.c_str(), "w")) {
          std::fprintf(out, "t,gx,gy,gz,temp\n");
          for (std::size_t i = 0; i < rec.t.size(); ++i)
            std::fprintf(out, "%.9g,%.9g,%.9g,%.9g,%.6g\n", rec.t[i], rec.axes[0][i], rec.axes[1][i], rec.axes[2][i],
                         rec.temp[i]);
          std::fclose(out);
        }
        std::printf("%s: line on axis %zu, centre %.6g Hz, width %.4g Hz, rms %.4g deg/s\n", name.c_str(), h.axis,
                    h.centre_hz, h.width_hz, h.rms_dps);
      }
      ModelCheckOptions o;
      o.replicas = replicas;
      o.seed = s;
      o.threads = threads;
      const AxisModelCheck r = checkAxisModel({rec.axes[h.axis], rate, rec.temp, rec.t, {}}, o);
      for (const CheckStatistic& st : r.statistics)
        if (st.name == "spectral_peak_log_ratio" && st.fired) ++fired;
      bool any = false, ok = false;
      for (const DetectedEffect& e : r.effects) {
        if (e.effect != ModelEffect::NarrowbandLine) continue;
        any = true;
        ok = ok || (std::fabs(e.centre_hz - h.centre_hz) <= 0.01 * h.centre_hz && e.width_hz >= h.width_hz / 1.5 &&
                    e.width_hz <= h.width_hz * 1.5);
      }
      named += any ? 1 : 0;
      right += ok ? 1 : 0;
      if (any && !ok) {  // what was named instead, for the record
        std::printf("  seed %zu: hidden centre %.5g width %.4g rms %.4g; named", s, h.centre_hz, h.width_hz, h.rms_dps);
        for (const DetectedEffect& e : r.effects)
          if (e.effect == ModelEffect::NarrowbandLine)
            std::printf(" [centre %.5g width %.4g rms %.4g]", e.centre_hz, e.width_hz, e.rms_dps);
        std::printf("\n");
      }
    }
    const auto pct = [&](std::size_t k) { return 100.0 * static_cast<double>(k) / static_cast<double>(seeds); };
    std::printf("%-12.3g %21.1f%% %21.1f%% %21.1f%%\n", f, pct(fired), pct(named), pct(right));
    std::fflush(stdout);
  }
  return 0;
}
