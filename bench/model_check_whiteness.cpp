// Calibration of the misfit's whiteness test on clean records: the held-out Ljung–Box p of
// the base Kalman model in several variants, on clean gyrod-like records through every DLPF
// setting (processing/model_check/hidden_effect_generator.hpp, as bench/model_check_dlpf_fdr.cpp
// makes them). Per setting: the share of axes with p < 0.01 and p < 1e-3, and the AR orders
// AIC chose. Not a unit test and not run by ctest; docs/model-check.md ("Misfit") gives the
// table and the command.
//
//   model_check_whiteness [--seeds N] [--first S] [--duration SEC] [--cfg C|none]
//
// Variants (all: AR fitted on the first half, innovations on the second):
//   paper:  AR(p ≤ 8) by AIC, the Kalman innovations of the record's detrended series, χ²(30 − p)
//   dof30:  the same innovations, χ²(30) (held out, nothing was fitted to them)
//   halves: each half detrended on its own, AR(p ≤ 8), χ²(30)
//   ar32:   each half detrended, AR(p ≤ 32) by AIC (prediction errors), χ²(30)
//   used:   the test the misfit uses (heldOutWhiteness, processing/model_check/misfit.cpp)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "processing/base/detrend.hpp"
#include "processing/model_check/detail.hpp"
#include "processing/model_check/hidden_effect_generator.hpp"
#include "processing/model_check/model_check.hpp"
#include "processing/paper/ar_model.hpp"

using namespace gyrod::processing;
using namespace gyrod::processing::model_check_detail;

namespace {

std::vector<double> predictionErrors(std::span<const double> x, const ArModel& m) {
  const std::size_t p = m.order();
  std::vector<double> e;
  if (x.size() <= p + 100) return e;
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  e.reserve(x.size() - p);
  for (std::size_t i = std::max<std::size_t>(p, 100); i < x.size(); ++i) {
    double pred = 0.0;
    for (std::size_t j = 0; j < p; ++j) pred += m.phi[j] * (x[i - 1 - j] - mean);
    e.push_back(x[i] - mean - pred);
  }
  return e;
}

struct Tally {
  std::size_t n = 0, below_01 = 0, below_001 = 0;
  std::vector<double> ps;
  void add(double p) {
    ++n;
    below_01 += p < 0.01 ? 1 : 0;
    below_001 += p < 1e-3 ? 1 : 0;
    ps.push_back(p);
  }
  std::string row() const {
    std::vector<double> s = ps;
    std::sort(s.begin(), s.end());
    char buf[160];
    std::snprintf(buf, sizeof buf, "%zu/%zu <0.01, %zu <1e-3, min %.2g, median %.2f", below_01, n, below_001,
                  s.empty() ? 0.0 : s.front(), s.empty() ? 0.0 : s[s.size() / 2]);
    return buf;
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::size_t seeds = 10, first = 1000;
  double duration = 600.0;
  constexpr int kNone = -1, kAll = -2;
  int only_cfg = kAll;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const char* v = argv[i + 1];
    if (key == "--seeds")
      seeds = std::strtoul(v, nullptr, 10);
    else if (key == "--first")
      first = std::strtoul(v, nullptr, 10);
    else if (key == "--duration")
      duration = std::strtod(v, nullptr);
    else if (key == "--cfg")
      only_cfg = std::string(v) == "none" ? kNone : std::atoi(v);
    else {
      std::fprintf(stderr, "model_check_whiteness: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  const std::vector<std::pair<int, double>> settings{{kNone, 50.0}, {0, 100.0}, {1, 200.0}, {2, 200.0},
                                                     {3, 100.0},    {4, 50.0},  {5, 50.0},  {6, 50.0}};
  Tally all_paper, all_dof, all_halves, all_ar32, all_used;
  for (const auto& [cfg, rate] : settings) {
    if (only_cfg != kAll && cfg != only_cfg) continue;
    const std::optional<int> dlpf = cfg == kNone ? std::nullopt : std::optional<int>(cfg);
    Tally paper, dof, halves, ar32, used;
    std::vector<std::size_t> orders8, orders32;
    for (std::size_t s = first; s < first + seeds; ++s) {
      HiddenEffectGenerator gen(s);
      gen.dlpf_cfg = dlpf;
      const GeneratedRecording g = gen.generate(duration * 50.0 / rate, rate, {});
      for (std::size_t a = 0; a < 3; ++a) {
        std::vector<double> xd = g.axes[a];
        removeLinearTrend(xd, 1.0 / rate);
        const std::size_t half = xd.size() / 2;
        const std::span<const double> all(xd);
        {
          const std::vector<ArModel> ar = yuleWalker(all.first(half), 8);
          const ArModel& m = ar[orderByAic(ar) - 1];
          orders8.push_back(m.order());
          const InnovationStats inn = kalmanInnovations(all.subspan(half), m.phi, m.noise_var, 0.0, 0.0, false);
          paper.add(ljungBoxTest(inn.innovations, 30, m.order()).p_value);
          dof.add(ljungBoxTest(inn.innovations, 30, 0).p_value);
        }
        std::vector<double> h1(xd.begin(), xd.begin() + static_cast<std::ptrdiff_t>(half));
        std::vector<double> h2(xd.begin() + static_cast<std::ptrdiff_t>(half), xd.end());
        removeLinearTrend(h1, 1.0 / rate);
        removeLinearTrend(h2, 1.0 / rate);
        {
          const std::vector<ArModel> ar = yuleWalker(h1, 8);
          const ArModel& m = ar[orderByAic(ar) - 1];
          halves.add(ljungBoxTest(predictionErrors(h2, m), 30, 0).p_value);
        }
        {
          const std::vector<ArModel> ar = yuleWalker(h1, 32);
          const ArModel& m = ar[orderByAic(ar) - 1];
          orders32.push_back(m.order());
          ar32.add(ljungBoxTest(predictionErrors(h2, m), 30, 0).p_value);
        }
        const HeldOutWhiteness w = heldOutWhiteness(all.first(half), all.subspan(half));
        used.add(w.test.p_value);
        if (std::getenv("WHITENESS_VERBOSE") && w.test.p_value < 1e-3) {
          const NoiseTerms& t = g.terms[a];
          std::printf("  seed %zu axis %zu p %.2g AR(%zu) Q %.3g N %.3g B %.3g K %.3g R %.3g; rho x100:", s, a,
                      w.test.p_value, w.ar_order, t.quantization_urad, t.arw_deg_per_sqrt_h,
                      t.bias_instability_deg_per_h, t.rrw_deg_per_h_sqrt_h, t.rate_ramp_deg_per_h2);
          const std::vector<double> ac = autocovariance(w.errors, 30);
          for (std::size_t k = 1; k <= 30; ++k) std::printf(" %.2f", 100.0 * ac[k] / ac[0]);
          std::printf("\n");
        }
      }
    }
    std::sort(orders8.begin(), orders8.end());
    std::sort(orders32.begin(), orders32.end());
    std::printf("DLPF %s @ %g Hz, %zu axes; AIC order (<=8) median %zu, (<=32) median %zu max %zu\n",
                cfg == kNone ? "none" : std::to_string(cfg).c_str(), rate, paper.n, orders8[orders8.size() / 2],
                orders32[orders32.size() / 2], orders32.back());
    std::printf("  paper  %s\n  dof30  %s\n  halves %s\n  ar32   %s\n  used   %s\n", paper.row().c_str(),
                dof.row().c_str(), halves.row().c_str(), ar32.row().c_str(), used.row().c_str());
    std::fflush(stdout);
    for (double p : paper.ps) all_paper.add(p);
    for (double p : dof.ps) all_dof.add(p);
    for (double p : halves.ps) all_halves.add(p);
    for (double p : ar32.ps) all_ar32.add(p);
    for (double p : used.ps) all_used.add(p);
  }
  std::printf("all: paper %s\n     dof30 %s\n     halves %s\n     ar32 %s\n     used %s\n", all_paper.row().c_str(),
              all_dof.row().c_str(), all_halves.row().c_str(), all_ar32.row().c_str(), all_used.row().c_str());
  return 0;
}
