// Cost of the simulator's random numbers and of one model-check replica, as a table with
// ratios measured in the same run (interleaved, best of --repeats, so a busy machine
// hurts both sides alike). Not run by ctest.
//
//   simulator_speed [--repeats N] [--seconds S]
//
// Rows: ns per normal deviate, polar method (NormalGenerator) against the ziggurat
// (ZigguratNormalGenerator); ns per output sample of one pure-mode axis at 50 Hz with the
// paper's Table 2 terms (what `gyroctl model-check` simulates per replica), with and
// without bias instability (the flicker bank's share), and ARW alone.
//
// bench/compare_simulator_speed.sh builds this same file against an older commit's library
// (with -DGYROD_BENCH_BASELINE, which leaves out what that commit does not have) and prints
// old/new ratios.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "processing/base/portable_random.hpp"
#include "processing/simulation/noise_simulator.hpp"

using namespace gyrod::processing;

namespace {

volatile double g_sink = 0.0;  // keeps the compiler from dropping the loops

template <class Body>
double secondsOf(Body&& body) {
  const auto t0 = std::chrono::steady_clock::now();
  body();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template <class Generator>
double nsPerNormal(std::size_t n) {
  Generator g(12345);
  double sum = 0.0;
  const double s = secondsOf([&] {
    for (std::size_t i = 0; i < n; ++i) sum += g.next();
  });
  g_sink = sum;
  return 1e9 * s / static_cast<double>(n);
}

SimulationModel pureAxisModel(bool bias_instability, bool arw_only) {
  SimulationModel m;  // as model_check.cpp's pureModel(): axis 0 only, no DLPF, no quantisation
  m.rate_hz = 50.0;
  NoiseTerms& t = m.axes[0].terms;
  t.arw_deg_per_sqrt_h = 0.95164;
  if (!arw_only) {
    t.quantization_urad = 0.1663;
    t.rrw_deg_per_h_sqrt_h = 0.07759;
    t.rate_ramp_deg_per_h2 = 0.43223;
    if (bias_instability) t.bias_instability_deg_per_h = 0.60565;
  }
  return m;
}

double nsPerSample(const SimulationModel& m, double seconds) {
  NoiseSimulator sim(m, seconds, 7);
  const std::size_t n = sim.sampleCount();
  double sum = 0.0;
  const double s = secondsOf([&] {
    for (std::size_t i = 0; i < n; ++i) sum += sim.next().rate_dps[0];
  });
  g_sink = sum;
  return 1e9 * s / static_cast<double>(n);
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 5;
  double seconds = 3600.0;
  for (int i = 1; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    if (!std::strcmp(argv[i], "--repeats") && has_value)
      repeats = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--seconds") && has_value)
      seconds = std::atof(argv[++i]);
    else {
      std::fprintf(stderr, "usage: %s [--repeats N] [--seconds S]\n", argv[0]);
      return 2;
    }
  }
  if (repeats < 1 || !(seconds >= 1.0)) {
    std::fprintf(stderr, "--repeats must be >= 1 and --seconds >= 1\n");
    return 2;
  }
  constexpr std::size_t kNormals = 20'000'000;
  std::vector<double> polar, zig, full, no_flicker, arw;
  for (int r = 0; r < repeats; ++r) {
    polar.push_back(nsPerNormal<NormalGenerator>(kNormals));
#ifndef GYROD_BENCH_BASELINE
    zig.push_back(nsPerNormal<ZigguratNormalGenerator>(kNormals));
#endif
    full.push_back(nsPerSample(pureAxisModel(true, false), seconds));
    no_flicker.push_back(nsPerSample(pureAxisModel(false, false), seconds));
    arw.push_back(nsPerSample(pureAxisModel(false, true), seconds));
  }
  auto best = [](const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); };
  std::printf("%-44s %10s\n", "what (best of repeats)", "ns");
  std::printf("%-44s %10.2f\n", "normal deviate, polar (NormalGenerator)", best(polar));
#ifndef GYROD_BENCH_BASELINE
  std::printf("%-44s %10.2f   polar/ziggurat = %.2f\n", "normal deviate, ziggurat", best(zig), best(polar) / best(zig));
#endif
  std::printf("%-44s %10.2f   (%.3g samples/s)\n", "sample, pure axis, Table 2 terms", best(full), 1e9 / best(full));
  std::printf("%-44s %10.2f   flicker bank share = %.0f %%\n", "sample, same without bias instability",
              best(no_flicker), 100.0 * (1.0 - best(no_flicker) / best(full)));
  std::printf("%-44s %10.2f\n", "sample, ARW alone", best(arw));
  return 0;
}
