// gyroctl model-check: where the paper's model fails on a recording, the named cause, and
// the gain of the extended model (processing/model_check/model_check.hpp, docs/model-check.md).
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "formats/calibration.hpp"
#include "formats/model_toml.hpp"
#include "formats/output_file.hpp"
#include "formats/recording_header.hpp"
#include "processing/base/noise_terms.hpp"
#include "processing/model_check/model_check.hpp"
#include "processing/motion/warm_up_fit.hpp"
#include "processing/simulation/sensor_model.hpp"
#include "tools/gyroctl/commands.hpp"
#include "tools/gyroctl/input.hpp"
#include "tools/gyroctl/model_check_edges.hpp"
#include "tools/gyroctl/model_check_support.hpp"
#include "tools/gyroctl/model_check_write_model.hpp"
#include "tools/gyroctl/series_checks.hpp"

namespace gyrod::gyroctl {
namespace {

using namespace gyrod::processing;
using nlohmann::json;

struct ModelCheckCliOptions {
  std::string file;
  std::optional<double> rate_hz;
  std::string axis = "all";
  bool json = false;
  bool strict_timing = false;
  bool keep_edges = false;
  std::string report_dir;
  std::uint64_t seed = 1;
  std::size_t replicas = 40;
  std::size_t threads = 0;
  std::string write_model;
  std::optional<int> dlpf_cfg, fs_sel;
};

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// A stated 95 % interval as [lo, hi] under `<parameter>_95` (docs/model-check.md, "Intervals").
void addInterval(json& params, const std::string& parameter, const ParameterInterval& i) {
  if (i.stated) params[parameter + "_95"] = {i.lo, i.hi};
}

json effectParams(const DetectedEffect& e) {
  json p = json::object();
  switch (e.effect) {
    case ModelEffect::TemperatureBias:
      p = {{"k_dps_per_c", e.k_dps_per_c}};
      addInterval(p, "k_dps_per_c", e.k_interval);
      return p;
    case ModelEffect::Sinusoid:
      p = {{"freq_hz", e.freq_hz}, {"amp_dps", e.amp_dps}};
      addInterval(p, "amp_dps", e.amp_interval);
      return p;
    case ModelEffect::GaussMarkov:
      p = {{"tau_s", e.tau_s}, {"sigma_dps", e.sigma_dps}};
      addInterval(p, "tau_s", e.tau_interval);
      addInterval(p, "sigma_dps", e.sigma_interval);
      return p;
    case ModelEffect::BiasSteps: {
      p = {{"count", e.count}, {"times_s", e.times_s}, {"sizes_dps", e.sizes_dps}};
      json sizes = json::array();
      for (const ParameterInterval& i : e.size_intervals) sizes.push_back(i.stated ? json{i.lo, i.hi} : json(nullptr));
      if (!e.size_intervals.empty()) p["sizes_dps_95"] = sizes;
      return p;
    }
    case ModelEffect::Outliers:
      p = {{"count", e.count}, {"median_amplitude_dps", e.outlier_median_amplitude_dps}};
      addInterval(p, "count", e.count_interval);
      addInterval(p, "median_amplitude_dps", e.outlier_amplitude_interval);
      return p;
    case ModelEffect::SampleGaps: return {{"count", e.count}, {"lost", e.lost}};
    case ModelEffect::NarrowbandLine:
      p = {{"centre_hz", e.centre_hz}, {"width_hz", e.width_hz}, {"rms_dps", e.rms_dps}};
      addInterval(p, "centre_hz", e.centre_interval);
      addInterval(p, "width_hz", e.width_interval);
      addInterval(p, "rms_dps", e.rms_interval);
      return p;
    case ModelEffect::Unexplained:
      return {{"where", "tau " + fmt("%.4g", e.where_lo) + " to " + fmt("%.4g", e.where_hi) + " s"},
              {"tau_lo_s", e.where_lo},
              {"tau_hi_s", e.where_hi}};
  }
  return json::object();
}

// ---- the words of the evidence ----------------------------------------------------------

std::string nullText(const EffectEvidence& v) {
  return "threshold " + fmt("%.4g", v.threshold) + " from " + std::to_string(v.replicas) +
         " base-model replicas (median " + fmt("%.4g", v.null_median) + ")";
}

std::string decisionText(const EffectEvidence& v) {
  switch (v.decision) {
    case LowFrequencyDecision::None: return "";
    case LowFrequencyDecision::TemperatureOnly: return "the residual follows temperature; no step once it is removed";
    case LowFrequencyDecision::TemperatureThenSteps:
      return "the residual follows temperature, and steps remain once it is removed";
    case LowFrequencyDecision::StepsThenTemperature:
      return "abrupt steps, and a temperature response remains once they are removed";
    case LowFrequencyDecision::StepsOnly: return "abrupt steps in the bias; no temperature response";
    case LowFrequencyDecision::EachRemains:
      return "steps and a temperature response: each remains when the other is removed";
    case LowFrequencyDecision::TemperatureVanishes:
      return "the temperature correlation vanishes once the steps are removed, the steps do not once the "
             "temperature fit is";
    case LowFrequencyDecision::StepsVanish:
      return "the steps vanish once the temperature response is removed, not the other way round";
    case LowFrequencyDecision::ByBic:
      return "either explains the other away; BIC of the low-passed residual: temperature " +
             fmt("%.1f", v.bic_temperature) + ", steps " + fmt("%.1f", v.bic_steps);
  }
  return "";
}

std::string sinusoidEvidenceText(const EffectEvidence& v) {
  std::string s = "narrow spectral peak " + fmt("%.3g", v.peak_ratio) + " x the local background at " +
                  fmt("%.5g", v.freq_hz) + " Hz (log ratio " + fmt("%.3g", v.statistic) + "; " + nullText(v) + ")";
  for (const LineComponent& c : v.further_components)
    s += "; a second component " + fmt("%.3g", c.amp_dps) + " deg/s at " + fmt("%.5g", c.freq_hz) +
         " Hz remains once it is removed (peak " + fmt("%.3g", c.peak_ratio) +
         " x the background): the line's amplitude or phase wanders over the record";
  return s;
}

// One sentence per effect: the statistic, its value and threshold, and how the cause was told.
std::string evidenceText(const DetectedEffect& e) {
  const EffectEvidence& v = e.evidence;
  switch (e.effect) {
    case ModelEffect::SampleGaps:
      return std::to_string(e.count) + " intervals in t longer than 1.5 x the median spacing " +
             fmt("%.6g", v.median_spacing_s) + " s, " + std::to_string(e.lost) + " samples missing; timing jitter " +
             fmt("%.3g", v.jitter) + " of a spacing";
    case ModelEffect::Outliers:
      return "largest robust z " + fmt("%.3g", v.statistic) + " against its neighbours; " + nullText(v) + "; " +
             std::to_string(e.count) + " samples beyond it, median excursion " +
             fmt("%.3g", e.outlier_median_amplitude_dps) + " deg/s";
    case ModelEffect::Sinusoid: return sinusoidEvidenceText(v);
    case ModelEffect::NarrowbandLine:
      return "a spectral peak " + fmt("%.4g", e.width_hz) + " Hz wide at " + fmt("%.4g", e.centre_hz) +
             " Hz, wider than one periodogram bin (scan statistic " + fmt("%.3g", v.statistic) + "; " + nullText(v) +
             "): the line's frequency wanders";
    case ModelEffect::TemperatureBias:
      return "low-passed residual against the detrended temperature: slope " + fmt("%.4g", v.statistic) + " deg/s/C, " +
             nullText(v) + " (two-sided on the distance); " + decisionText(v);
    case ModelEffect::BiasSteps:
      return "largest standardised Haar difference of the low-passed residual " + fmt("%.3g", v.statistic) + ", " +
             nullText(v) + "; " + decisionText(v);
    case ModelEffect::GaussMarkov:
      return "a Gauss-Markov term in the Allan fit lowers the weighted residual by " + fmt("%.4g", v.chi2_gain) +
             " (from " + fmt("%.4g", v.chi2_base) + "), " + nullText(v);
    case ModelEffect::Unexplained:
      return "the measured Allan deviation leaves the " + std::string(v.against_extended ? "extended" : "base") +
             " model's replicas at tau " + fmt("%.4g", e.where_lo) + " to " + fmt("%.4g", e.where_hi) +
             " s (largest |z| " + fmt("%.3g", v.statistic) + ", threshold " + fmt("%.3g", v.threshold) +
             "); no catalogued effect accounts for it";
  }
  return "";
}

// A value to 4 significant digits (the text; the JSON keeps full precision).
std::string sig4(double v) { return fmt("%.4g", v); }

// "31.41 Hz (31.38–31.44)": a value, its unit and its 95 % interval when stated.
std::string withInterval(double v, const std::string& unit, const ParameterInterval& i) {
  std::string s = sig4(v) + (unit.empty() ? "" : " " + unit);
  if (i.stated) s += " (" + sig4(i.lo) + "–" + sig4(i.hi) + ")";
  return s;
}

// The parameters in words, 4 significant digits with units and 95 % intervals
// (docs/model-check.md, "Verdicts and output").
std::string paramsText(const DetectedEffect& e) {
  switch (e.effect) {
    case ModelEffect::TemperatureBias: return "k = " + withInterval(e.k_dps_per_c, "deg/s per C", e.k_interval);
    case ModelEffect::Sinusoid:
      return sig4(e.freq_hz) + " Hz, amplitude " + withInterval(e.amp_dps, "deg/s", e.amp_interval);
    case ModelEffect::GaussMarkov:
      return "T = " + withInterval(e.tau_s, "s", e.tau_interval) +
             ", sigma = " + withInterval(e.sigma_dps, "deg/s", e.sigma_interval);
    case ModelEffect::BiasSteps: {
      std::string s = std::to_string(e.count) + (e.count == 1 ? " step" : " steps");
      for (std::size_t j = 0; j < e.times_s.size(); ++j) {
        s += j == 0 ? ": " : "; ";
        s += "at " + sig4(e.times_s[j]) + " s";
        if (j < e.sizes_dps.size())
          s += " by " + withInterval(e.sizes_dps[j], "deg/s",
                                     j < e.size_intervals.size() ? e.size_intervals[j] : ParameterInterval{});
      }
      return s;
    }
    case ModelEffect::Outliers:
      return withInterval(static_cast<double>(e.count), "samples", e.count_interval) + ", median excursion " +
             withInterval(e.outlier_median_amplitude_dps, "deg/s", e.outlier_amplitude_interval);
    case ModelEffect::SampleGaps: return std::to_string(e.count) + " gaps, " + std::to_string(e.lost) + " samples lost";
    case ModelEffect::NarrowbandLine:
      return "centre " + withInterval(e.centre_hz, "Hz", e.centre_interval) + ", width " +
             withInterval(e.width_hz, "Hz", e.width_interval) + ", " +
             withInterval(e.rms_dps, "deg/s rms", e.rms_interval);
    case ModelEffect::Unexplained: return "tau " + sig4(e.where_lo) + " to " + sig4(e.where_hi) + " s";
  }
  return "";
}

// ---- the misfit of the final model -------------------------------------------------------

// The model the check ends with: the extended one when its extension was accepted.
const char* finalModelName(const AxisModelCheck& r) {
  return r.verdict.judged && r.verdict.accepted ? "extended" : "base";
}

json numberOrNull(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json misfitJson(const ModelMisfit& m) {
  return {{"fails", m.fails()},
          {"chain_fails", m.chain_fails},
          {"chain_reduced_chi2", numberOrNull(m.chain_reduced_chi2)},
          {"whiteness_fails", m.whiteness_fails},
          {"band_fails", m.band_fails},
          {"marginal", m.marginal},
          {"ljung_box_p_held_out", m.ljung_box_p_held_out},
          {"whiteness_ar_order", m.whiteness_ar_order},
          {"whiteness_q", m.whiteness_q},
          {"whiteness_q_replica_median", numberOrNull(m.whiteness_q_replica_median)},
          {"in_band", m.in_band},
          {"in_band_of", m.joint_band ? "simultaneous_90_band" : "per_tau_90_band"},
          {"in_band_replica_median", numberOrNull(m.in_band_replica_median)},
          {"in_band_replica_lowest", numberOrNull(m.in_band_replica_lowest)},
          {"band_p", numberOrNull(m.band_p)},
          {"tau_lo_s", numberOrNull(m.tau_lo_s)},
          {"tau_hi_s", numberOrNull(m.tau_hi_s)},
          {"adev_ratio", numberOrNull(m.adev_ratio)},
          {"freq_lo_hz", numberOrNull(m.freq_lo_hz)},
          {"freq_hi_hz", numberOrNull(m.freq_hi_hz)},
          {"power_ratio", numberOrNull(m.power_ratio)},
          {"power_ratio_against", std::isfinite(m.power_ratio)
                                      ? json(m.power_against_replicas ? "replicas_median" : "white_level")
                                      : json(nullptr)},
          {"halves_differ", m.halves_differ},
          {"halves_colour_p", numberOrNull(m.halves_colour_p)},
          {"halves_lag1_first", numberOrNull(m.halves_lag1_first)},
          {"halves_lag1_second", numberOrNull(m.halves_lag1_second)},
          {"halves_spectrum_p", numberOrNull(m.halves_spectrum_p)},
          {"halves_spectrum_hz", numberOrNull(m.halves_spectrum_hz)},
          {"halves_spectrum_ratio", numberOrNull(m.halves_spectrum_ratio)}};
}

std::string percent(double share) { return fmt("%.3g", 100.0 * share) + " %"; }

std::string bandName(const ModelMisfit& m) { return m.joint_band ? "simultaneous 90 % band" : "90 % band"; }

// The two tests' figures: "held-out whiteness p 0.43 (AR(5)), 100 % of the Allan curve in the
// simultaneous 90 % band (its replicas: median 100 %, lowest 80 %)".
std::string fitFiguresText(const ModelMisfit& m) {
  std::string s = "held-out whiteness p " + fmt("%.2g", m.ljung_box_p_held_out) + " (AR(" +
                  std::to_string(m.whiteness_ar_order) + ")), " + percent(m.in_band) + " of the Allan curve in the " +
                  bandName(m);
  if (std::isfinite(m.in_band_replica_median))
    s += " (its replicas: median " + percent(m.in_band_replica_median) + ", lowest " +
         percent(m.in_band_replica_lowest) + ")";
  return s;
}

// Where a misfit is: "misfit at tau 0.02–0.16 s (...) and 31.2–31.6 Hz (...)".
std::string whereText(const ModelMisfit& m) {
  std::vector<std::string> where;
  if (std::isfinite(m.tau_lo_s))
    where.push_back("tau " + sig4(m.tau_lo_s) + "–" + sig4(m.tau_hi_s) + " s (Allan deviation " +
                    (m.adev_ratio >= 1.0 ? "up to " : "down to ") + fmt("%.3g", m.adev_ratio) +
                    " x the replicas' median)");
  if (std::isfinite(m.freq_lo_hz))
    where.push_back(sig4(m.freq_lo_hz) + "–" + sig4(m.freq_hi_hz) + " Hz (" + fmt("%.3g", m.power_ratio) +
                    (m.power_against_replicas ? " x the replicas' median power)" : " x the white level)"));
  if (where.empty()) return "no tau range or frequency band stands out";
  return "misfit at " + where.front() + (where.size() > 1 ? " and " + where.back() : "");
}

// When the record itself changed between its halves: "; the record changes between its halves
// (lag-1 autocorrelation +0.034 -> -0.036, p 0.0021): no stationary model fitted to one half
// whitens the other". Empty when it did not.
std::string halvesText(const ModelMisfit& m) {
  if (!m.halves_differ) return "";
  std::vector<std::string> what;
  if (m.halves_colour_p < kHalvesAlpha / 2)
    what.push_back("lag-1 autocorrelation " + fmt("%+.3f", m.halves_lag1_first) + " -> " +
                   fmt("%+.3f", m.halves_lag1_second) + ", lags 1-" + std::to_string(kHalvesLags) + " p " +
                   fmt("%.2g", m.halves_colour_p));
  if (m.halves_spectrum_p < kHalvesAlpha / 2)
    what.push_back("power at " + sig4(m.halves_spectrum_hz) + " Hz " + fmt("%.3g", m.halves_spectrum_ratio) +
                   " x the first half's, p " + fmt("%.2g", m.halves_spectrum_p));
  std::string s = "; the record changes between its halves (";
  for (std::size_t i = 0; i < what.size(); ++i) s += (i ? "; " : "") + what[i];
  return s + "): no stationary model fitted to one half whitens the other";
}

// Why and where the model does not fit: "what it leaves is not white on the held-back half
// (Ljung-Box p 3.1e-05 < 0.001); ...; misfit at tau 0.02–0.16 s (up to 1.6 x the replicas'
// median) and 31.2–31.6 Hz (12 x white)".
std::string misfitText(const ModelMisfit& m) {
  std::vector<std::string> why;
  if (m.chain_fails)
    why.push_back("no DLPF setting fits its short-tau Allan curve (best reduced chi2 " +
                  fmt("%.3g", m.chain_reduced_chi2) + ")");
  if (m.whiteness_fails)
    why.push_back("what it leaves is not white on the held-back half (Ljung-Box p " +
                  fmt("%.2g", m.ljung_box_p_held_out) + " < " + fmt("%g", kMisfitWhitenessP) + ")");
  if (m.band_fails)
    why.push_back("the Allan curve leaves its replicas' " + bandName(m) + " more often than any replica does (" +
                  percent(m.in_band) + " in band against a lowest " + percent(m.in_band_replica_lowest) + ", median " +
                  percent(m.in_band_replica_median) + "; p " + fmt("%.2g", m.band_p) + ")");
  std::string s;
  for (const std::string& w : why) s += (s.empty() ? "" : "; ") + w;
  return s + "; " + whereText(m) + halvesText(m);
}

// A model that fits but only just: "marginal: held-out whiteness p 0.0069 (< 0.01); weakest at
// 12.1–12.9 Hz (1.9 x the white level)".
std::string marginalText(const ModelMisfit& m) {
  std::vector<std::string> why;
  if (m.ljung_box_p_held_out < kMarginalWhitenessP)
    why.push_back("held-out whiteness p " + fmt("%.2g", m.ljung_box_p_held_out) + " (< " +
                  fmt("%g", kMarginalWhitenessP) + ")");
  if (m.in_band < kMarginalInBand)
    why.push_back(percent(m.in_band) + " of the Allan curve in the " + bandName(m) + " (< " + percent(kMarginalInBand) +
                  ")");
  std::string s = "marginal: ";
  for (std::size_t i = 0; i < why.size(); ++i) s += (i ? " and " : "") + why[i];
  std::string where = whereText(m);
  where.replace(0, where.find(' '), "weakest");  // "misfit at ..." → "weakest at ..."
  return s + "; " + where + halvesText(m);
}

json termsJson(const NoiseTerms& t) {
  json j = json::object();
  for (NoiseTerm term : kAllNoiseTerms) j[std::string(noiseTermKey(term))] = t.get(term);
  return j;
}

json axisJson(const AxisModelCheck& r) {
  json effects = json::array();
  for (const DetectedEffect& e : r.effects) {
    json one = {{"effect", std::string(modelEffectName(e.effect))},
                {"params", effectParams(e)},
                {"evidence", evidenceText(e)},
                {"explained", e.explained}};
    if (!e.explained) one["not_explained_reason"] = notExplainedReason(r.verdict);
    effects.push_back(one);
  }
  json stats = json::array();
  for (const CheckStatistic& s : r.statistics)
    stats.push_back({{"name", s.name},
                     {"value", s.value},
                     {"null_median", s.null_median},
                     {"threshold", s.threshold},
                     {"fired", s.fired}});
  return {{"effects", effects},
          {"gain", gainJson(r.gain)},
          {"extension", verdictJson(r.verdict, r.gain)},
          {"misfit", misfitJson(r.misfit)},
          {"samples", r.samples},
          {"base_terms", termsJson(r.base_fit.value)},
          {"extended_terms", termsJson(r.extended_fit.value)},
          {"ar_order", r.ar_order},
          {"replicas_simulated", r.replicas_simulated},
          {"statistics", stats}};
}

void printAxisText(std::ostream& o, const std::string& name, const AxisModelCheck& r) {
  o << "\n== " << name << " ==\n";
  if (r.effects.empty() && !r.misfit.fails())
    o << "  the base model holds: no effect (" << fitFiguresText(r.misfit) << ")\n";
  if (r.effects.empty() && r.misfit.marginal) o << "      " << marginalText(r.misfit) << "\n";
  for (const DetectedEffect& e : r.effects) {
    o << "  " << modelEffectName(e.effect) << " (" << paramsText(e) << ")";
    if (!e.explained) o << ": seen, not explained (" << notExplainedReason(r.verdict) << ")";
    o << "\n      " << evidenceText(e) << '\n';
  }
  if (r.misfit.fails())
    o << "  the " << finalModelName(r) << " model does not fit: " << misfitText(r.misfit) << "\n      ("
      << fitFiguresText(r.misfit) << ")\n";
  else if (!r.effects.empty())
    o << "  the " << finalModelName(r) << " model fits (" << fitFiguresText(r.misfit) << ")\n";
  if (!r.effects.empty() && r.misfit.marginal) o << "      " << marginalText(r.misfit) << "\n";
  const ModelCheckGain& g = r.gain;
  char line[256];
  o << "  gain                    base        extended\n";
  std::snprintf(line, sizeof line, "  adev log error    %12.4g    %12.4g\n", g.adev_log_error_base,
                g.adev_log_error_extended);
  o << line;
  std::snprintf(line, sizeof line, "  innovation var    %12.4g    %12.4g\n", g.innovation_var_base,
                g.innovation_var_extended);
  o << line;
  std::snprintf(line, sizeof line, "  Ljung-Box p       %12.4g    %12.4g\n", g.ljung_box_p_base,
                g.ljung_box_p_extended);
  o << line;
  std::snprintf(line, sizeof line, "  in 90%% band/tau   %12.3f    %12.3f\n", g.in_band_base, g.in_band_extended);
  o << line;
  std::snprintf(line, sizeof line,
                "  held out (Kalman AR(p<=8)): innovation var %.4g -> %.4g, Ljung-Box p %.4g -> %.4g\n",
                g.innovation_var_base_held_out, g.innovation_var_extended_held_out, g.ljung_box_p_base_held_out,
                g.ljung_box_p_extended_held_out);
  o << line;
  if (g.tail_judged) {
    std::snprintf(line, sizeof line,
                  "  held out tail (innovations beyond 5 sigma): %zu, expected %.3g (base) / %.3g (extended), "
                  "log likelihood %.4g -> %.4g\n",
                  g.tail_count_held_out, g.tail_expected_base_held_out, g.tail_expected_extended_held_out,
                  g.tail_log_likelihood_base_held_out, g.tail_log_likelihood_extended_held_out);
    o << line;
  }
  if (r.verdict.judged)
    o << "  extension " << (r.verdict.accepted ? "accepted" : "not accepted") << " (judged by "
      << joined(judgedMeasures(r.verdict, r.gain))
      << "; better: " << (betterMeasures(r.verdict).empty() ? "none" : joined(betterMeasures(r.verdict)))
      << "; worse: " << (worseMeasures(r.verdict).empty() ? "none" : joined(worseMeasures(r.verdict))) << ")\n";
}

// ---- report ----------------------------------------------------------------------------

// `input`: the recording checked, which no report file may overwrite.
void writeText(const std::filesystem::path& p, const std::string& text, const std::string& input) {
  formats::writeFileAtomically(p.string(), text, {input});
}

bool gnuplotInstalled() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

std::string shellQuoted(const std::filesystem::path& p) {
  std::string s = "'";
  for (char ch : p.string()) s += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return s + "'";
}

// Data files and gnuplot scripts for one axis; returns the plots made (file names).
std::vector<std::string> writeAxisPlots(const std::filesystem::path& dir, const std::string& name,
                                        const AxisModelCheck& r, bool run_gnuplot, const std::string& input) {
  std::vector<std::string> made;
  {
    std::ostringstream d;
    d << "# tau_s measured base_median base_lo base_hi extended_median extended_lo extended_hi\n";
    for (std::size_t j = 0; j < r.allan_base.tau_s.size(); ++j)
      d << r.allan_base.tau_s[j] << ' ' << r.allan_base.measured[j] << ' ' << r.allan_base.median[j] << ' '
        << r.allan_base.lo[j] << ' ' << r.allan_base.hi[j] << ' ' << r.allan_extended.median[j] << ' '
        << r.allan_extended.lo[j] << ' ' << r.allan_extended.hi[j] << '\n';
    writeText(dir / ("allan_" + name + ".dat"), d.str(), input);
    std::ostringstream g;
    g << "set terminal pngcairo size 900,600\nset output 'allan_" << name << ".png'\n"
      << "set logscale xy\nset grid\nset xlabel 'tau [s]'\nset ylabel 'Allan deviation [deg/s]'\n"
      << "set title 'Allan deviation, " << name << ": measured against 90 % bands of the replicas'\n"
      << "plot 'allan_" << name
      << ".dat' u 1:4:5 w filledcurves lc rgb '#c0c0ff' fs transparent solid 0.5 t 'base 90 %', "
      << "'' u 1:7:8 w filledcurves lc rgb '#ffc080' fs transparent solid 0.5 t 'extended 90 %', "
      << "'' u 1:3 w l lc rgb 'blue' dt 2 t 'base median', '' u 1:6 w l lc rgb '#d06000' dt 2 t 'extended median', "
      << "'' u 1:2 w lp pt 7 ps 0.6 lc rgb 'black' t 'measured'\n";
    writeText(dir / ("allan_" + name + ".gp"), g.str(), input);
    made.push_back("allan_" + name + ".png");
  }
  {
    std::ostringstream d;
    d << "# freq_hz psd_measured psd_base_median psd_measured_band_peak  [(deg/s)^2/Hz]\n";
    for (std::size_t j = 0; j < r.spectrum_freq_hz.size(); ++j)
      if (std::isfinite(r.spectrum_measured[j]) && std::isfinite(r.spectrum_base_median[j]))
        d << r.spectrum_freq_hz[j] << ' ' << r.spectrum_measured[j] << ' ' << r.spectrum_base_median[j] << ' '
          << r.spectrum_measured_peak[j] << '\n';
    writeText(dir / ("spectrum_" + name + ".dat"), d.str(), input);
    std::ostringstream g;
    g << "set terminal pngcairo size 900,600\nset output 'spectrum_" << name << ".png'\n"
      << "set logscale xy\nset grid\nset xlabel 'frequency [Hz]'\nset ylabel 'PSD [(deg/s)^2/Hz]'\n"
      << "set title 'Power spectral density (band averages), " << name << "'\n"
      << "plot 'spectrum_" << name << ".dat' u 1:4 w l lc rgb '#a0a0a0' t 'measured, largest bin of each band', "
      << "'' u 1:2 w lp pt 7 ps 0.5 lc rgb 'black' t 'measured (band average)', "
      << "'' u 1:3 w l lc rgb 'blue' t 'base model (median of replicas)'\n";
    writeText(dir / ("spectrum_" + name + ".gp"), g.str(), input);
    made.push_back("spectrum_" + name + ".png");
  }
  if (!r.block_temperature_c.empty()) {
    std::ostringstream d;
    d << "# temperature_c low_passed_residual_dps (block means)\n";
    for (std::size_t j = 0; j < r.block_temperature_c.size(); ++j)
      d << r.block_temperature_c[j] << ' ' << r.block_residual_dps[j] << '\n';
    writeText(dir / ("temperature_" + name + ".dat"), d.str(), input);
    std::ostringstream g;
    g << "set terminal pngcairo size 900,600\nset output 'temperature_" << name << ".png'\n"
      << "set grid\nset xlabel 'temperature [C]'\nset ylabel 'low-passed residual [deg/s]'\n"
      << "set title 'Residual (detrended, block means) against temperature, " << name << "'\n"
      << "plot 'temperature_" << name << ".dat' u 1:2 w p pt 7 ps 0.3 lc rgb 'black' notitle\n";
    writeText(dir / ("temperature_" + name + ".gp"), g.str(), input);
    made.push_back("temperature_" + name + ".png");
  }
  if (run_gnuplot) {
    for (const std::string& png : made) {
      const std::string script = png.substr(0, png.size() - 4) + ".gp";
      const std::string cmd = "cd " + shellQuoted(dir) + " && gnuplot " + shellQuoted(script) + " >/dev/null 2>&1";
      if (std::system(cmd.c_str()) != 0) throw std::runtime_error("gnuplot failed on " + (dir / script).string());
    }
  }
  return made;
}

void writeReport(const std::string& dir_text, const ModelCheckCliOptions& opt, const LoadedInput& in,
                 const ChainChoice& chain, const std::vector<std::pair<std::string, AxisModelCheck>>& results,
                 double seconds) {
  const std::filesystem::path dir(dir_text);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir_text + ": cannot create the report folder: " + ec.message());
  const bool plots = gnuplotInstalled();
  std::ostringstream md;
  md << "# Model check: " << opt.file << "\n\n"
     << in.recording.size() << " samples at " << in.rate_hz << " Hz (" << in.rate_source << "), "
     << fmt("%.1f", static_cast<double>(in.recording.size()) / in.rate_hz) << " s; "
     << (in.recording.temp.empty() ? "no temperature channel" : "temperature channel present") << "; "
     << (in.recording.t.empty() ? "no t column" : "t column present") << ". Replicas per round: " << opt.replicas
     << ", seed " << opt.seed << "; checked in " << fmt("%.2f", seconds) << " s.\n\n"
     << "The base model is the paper's (five Allan terms fitted to the Allan deviation, AR(p) by AIC for the "
        "Kalman filter), seen through the acquisition chain. Every threshold comes from replicas simulated from the "
        "fitted model; see docs/model-check.md.\n\n"
     << "The " << chainText(chain) << ".\n";
  if (chain.no_setting_fits) md << "\n" << noDlpfFitsText(chain, in.recording.axis_names) << ".\n";
  if (!plots) md << "\n(gnuplot is not installed: the plot data and scripts are written, the pictures are not.)\n";
  for (const auto& [name, r] : results) {
    md << "\n## " << name << "\n\n";
    if (r.effects.empty() && !r.misfit.fails())
      md << "The base model holds: no effect found (" << fitFiguresText(r.misfit) << ").\n";
    if (r.effects.empty() && r.misfit.marginal)
      md << "It is " << marginalText(r.misfit) << ".\n";
    else if (!r.effects.empty()) {
      md << "| effect | parameters | evidence |\n|---|---|---|\n";
      for (const DetectedEffect& e : r.effects)
        md << "| `" << modelEffectName(e.effect) << "`" << (e.explained ? "" : " (seen, not explained)") << " | "
           << paramsText(e) << " | " << evidenceText(e)
           << (e.explained ? "" : "; not explained: " + notExplainedReason(r.verdict)) << " |\n";
    }
    if (r.misfit.fails())
      md << (r.effects.empty() ? "" : "\n") << "The " << finalModelName(r)
         << " model does not fit: " << misfitText(r.misfit) << ".\n";
    if (!r.effects.empty() && r.misfit.marginal)
      md << "\nThe " << finalModelName(r) << " model fits, " << marginalText(r.misfit) << ".\n";
    const ModelCheckGain& g = r.gain;
    md << "\n| figure | base | extended |\n|---|---|---|\n"
       << "| mean \\|log10(measured/median simulated ADEV)\\| | " << fmt("%.4g", g.adev_log_error_base) << " | "
       << fmt("%.4g", g.adev_log_error_extended) << " |\n"
       << "| Kalman innovation variance [(deg/s)^2] | " << fmt("%.4g", g.innovation_var_base) << " | "
       << fmt("%.4g", g.innovation_var_extended) << " |\n"
       << "| Ljung-Box p of the innovations | " << fmt("%.3g", g.ljung_box_p_base) << " | "
       << fmt("%.3g", g.ljung_box_p_extended) << " |\n"
       << "| fraction of tau inside the per-tau 90 % band | " << fmt("%.3f", g.in_band_base) << " | "
       << fmt("%.3f", g.in_band_extended) << " |\n"
       << "| held out: innovation variance (fit 1st half, score 2nd) | " << fmt("%.4g", g.innovation_var_base_held_out)
       << " | " << fmt("%.4g", g.innovation_var_extended_held_out) << " |\n"
       << "| held out: Ljung-Box p | " << fmt("%.3g", g.ljung_box_p_base_held_out) << " | "
       << fmt("%.3g", g.ljung_box_p_extended_held_out) << " |\n";
    if (g.tail_judged)
      md << "| held out: innovations beyond 5 sigma, " << g.tail_count_held_out
         << " seen: expected count / Poisson log likelihood | " << fmt("%.3g", g.tail_expected_base_held_out) << " / "
         << fmt("%.4g", g.tail_log_likelihood_base_held_out) << " | " << fmt("%.3g", g.tail_expected_extended_held_out)
         << " / " << fmt("%.4g", g.tail_log_likelihood_extended_held_out) << " |\n";
    if (r.verdict.judged)
      md << "\nExtension " << (r.verdict.accepted ? "**accepted**" : "**not accepted**") << " (judged by "
         << joined(judgedMeasures(r.verdict, r.gain))
         << "; better: " << (betterMeasures(r.verdict).empty() ? "none" : joined(betterMeasures(r.verdict)))
         << "; worse: " << (worseMeasures(r.verdict).empty() ? "none" : joined(worseMeasures(r.verdict))) << ").\n";
    md << "\nStatistics (value, median of the null, threshold):\n\n";
    for (const CheckStatistic& s : r.statistics)
      md << "- " << s.name << ": " << fmt("%.4g", s.value) << " (null median " << fmt("%.4g", s.null_median)
         << ", threshold " << fmt("%.4g", s.threshold) << ")" << (s.fired ? " **fired**" : "") << "\n";
    md << "\n";
    for (const std::string& png : writeAxisPlots(dir, name, r, plots, opt.file))
      md << "![" << png << "](" << png << ")\n";
  }
  writeText(dir / "report.md", md.str(), opt.file);
}

// ---- --write-model: the extended model as a simulation model file -----------------------

int runModelCheck(const ModelCheckCliOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  if (!opt.write_model.empty()) requireWritableTarget(opt.write_model, opt.file);
  LoadedInput in = loadInput(opt.file, opt.rate_hz, opt.axis);
  const EdgeTrim edges = trimEdgeMotion(in, opt.keep_edges);
  if (const std::string note = edgeTrimText(opt.file, edges); !note.empty()) std::fprintf(stderr, "%s\n", note.c_str());
  const auto& rec = in.recording;
  // The noise model is the gyro's: an accel column is read but not checked, which the user should not have to guess.
  if (std::any_of(rec.accel_g.begin(), rec.accel_g.end(), [](const auto& c) { return !c.empty(); }))
    std::fprintf(stderr,
                 "%s: the accelerometer columns (ax, ay, az) are not checked: the model check analyses the "
                 "gyro columns only\n",
                 opt.file.c_str());
  if (rec.size() < kModelCheckMinSamples) {
    std::ostringstream s;
    s << opt.file << ": " << rec.size() << " samples are too few for the model check (need at least "
      << kModelCheckMinSamples << ")";
    throw recording::RecordingError(s.str());
  }
  ModelCheckOptions options;
  options.seed = opt.seed;
  options.replicas = opt.replicas;
  options.threads = opt.threads;
  for (std::size_t idx : in.axis_indices) requireAnalysableValues(rec, idx);
  const ChainChoice chain = settleChain(opt.file, opt.dlpf_cfg, opt.fs_sel, in);
  const TimingSummary timing = checkTiming(rec, opt.rate_hz);
  reportTiming(opt.file, timing, opt.strict_timing);
  std::vector<std::pair<std::string, AxisModelCheck>> results;
  for (std::size_t idx : in.axis_indices) {
    AxisModelCheckInput axis{rec.axes[idx], chain.rate_hz, rec.temp, rec.t, chain.chain};
    try {
      results.emplace_back(rec.axis_names[idx], checkAxisModel(axis, options));
      AxisModelCheck& r = results.back().second;
      ModelMisfit& m = r.misfit;
      // The raw curve fits no DLPF setting: a misfit unless the named effects explain it (the
      // five terms refitted through the chain once they are removed fit; a strong line, say,
      // bends the short-τ curve of the raw series).
      const bool explained = r.extended_fit.reduced_chi2 <= kNoDlpfFitsChi2;
      m.chain_fails = chain.noSettingFits(idx) && !(r.verdict.judged && r.verdict.accepted && explained);
      if (m.chain_fails) m.chain_reduced_chi2 = chain.axis_best_chi2.at(idx);
      m.marginal = m.marginal && !m.chain_fails;
    } catch (const std::invalid_argument& e) {
      throw recording::RecordingError(opt.file + ": column '" + rec.axis_names[idx] + "': " + e.what());
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (opt.json) {
    json doc;
    doc["file"] = opt.file;
    doc["rate_hz"] = in.rate_hz;
    doc["samples"] = rec.size();
    doc["seed"] = opt.seed;
    doc["replicas"] = opt.replicas;
    doc["elapsed_s"] = seconds;
    doc["timing"] = timingJson(timing);
    doc["edges"] = edgeTrimJson(edges);
    doc["acquisition_chain"] = chainJson(chain);
    doc["axes"] = json::object();
    for (const auto& [name, r] : results) doc["axes"][name] = axisJson(r);
    std::cout << doc.dump(1) << '\n';
  } else {
    std::printf("gyroctl model-check %s: %zu samples at %g Hz (%s), %.1f s; %zu replicas per round, seed %llu\n",
                opt.file.c_str(), rec.size(), in.rate_hz, in.rate_source.c_str(),
                static_cast<double>(rec.size()) / in.rate_hz, opt.replicas, static_cast<unsigned long long>(opt.seed));
    std::printf("%s\n", chainText(chain).c_str());
    if (chain.no_setting_fits) std::printf("%s\n", noDlpfFitsText(chain, rec.axis_names).c_str());
    for (const auto& [name, r] : results) printAxisText(std::cout, name, r);
    std::printf("\nchecked in %.2f s\n", seconds);
  }
  if (!opt.report_dir.empty()) {
    writeReport(opt.report_dir, opt, in, chain, results, seconds);
    if (!opt.json) std::printf("report written to %s/report.md\n", opt.report_dir.c_str());
  }
  if (!opt.write_model.empty()) {
    formats::writeFileAtomically(opt.write_model, extendedModelToml(opt.file, opt.seed, opt.replicas, in, results),
                                 {opt.file});
    if (!opt.json) std::printf("extended model written to %s\n", opt.write_model.c_str());
  }
  return kExitOk;
}

}  // namespace

void addModelCheckCommand(CLI::App& app, CommandRunner& run) {
  auto opt = std::make_shared<ModelCheckCliOptions>();
  auto* sub = app.add_subcommand(
      "model-check",
      "Where the paper's noise model fails on a recording, the named cause "
      "(temperature_bias, sinusoid, narrowband_line, gauss_markov, bias_steps, outliers, sample_gaps, "
      "or unexplained), and the gain of the extended model");
  sub->add_option("FILE", opt->file, "CSV with header t,gx,gy,gz,temp (any subset), as analyze reads")->required();
  sub->add_option("--rate", opt->rate_hz, "sample rate [Hz] (default: from t, else 50)");
  sub->add_option("--axis", opt->axis, "gx, gy, gz or all")->default_val("all");
  sub->add_flag("--json", opt->json, "one JSON document on stdout");
  sub->add_flag("--keep-edges", opt->keep_edges,
                "keep motion found at the start or end of the recording (by default it is left out: the model is for a "
                "gyro at rest)");
  sub->add_flag("--strict-timing", opt->strict_timing,
                "gaps or irregular spacing in t, or GAP/DROPPED records, are an error instead of a warning");
  sub->add_option("--report", opt->report_dir, "write report.md with plots (gnuplot, when installed) into this folder");
  sub->add_option("--seed", opt->seed, "seed of the replicas")->default_val(1);
  sub->add_option("--replicas", opt->replicas, "replicas per round (the null distributions)")
      ->default_val(40)
      ->check(CLI::Range(std::size_t{8}, std::size_t{10000}));
  sub->add_option("--threads", opt->threads, "threads for the replicas (0: all cores)")->default_val(0);
  sub->add_option("--dlpf", opt->dlpf_cfg,
                  "DLPF_CFG 0..6 the recording was made with (default: the recording's '# device' header, else "
                  "estimated from the Allan curve)")
      ->check(CLI::Range(0, 6));
  sub->add_option("--fs-sel", opt->fs_sel,
                  "FS_SEL 0..3 the recording was made with: the LSB the replicas are rounded to (default: the header)")
      ->check(CLI::Range(0, 3));
  sub->add_option(
      "--write-model", opt->write_model,
      "write the extended model of every axis (terms and named effects) as TOML for gyroctl simulate --model");
  sub->callback([&run, opt] { run = [opt] { return runModelCheck(*opt); }; });
}

}  // namespace gyrod::gyroctl
