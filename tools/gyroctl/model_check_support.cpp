// gyroctl model-check's support: the acquisition chain and the verdict's words
// (tools/gyroctl/model_check_support.hpp).
#include "tools/gyroctl/model_check_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "formats/recording_csv.hpp"
#include "formats/recording_header.hpp"
#include "processing/simulation/sensor_model.hpp"

namespace gyrod::gyroctl {

using namespace gyrod::processing;
using nlohmann::json;

namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// The rate of a DLPF setting nearest to `rate` (the t column's median spacing is not exact),
// when one is within 1 %.
std::optional<double> reachableRate(int dlpf_cfg, double rate) {
  const double internal = dlpfSetting(dlpf_cfg).internal_rate_hz;
  const double divisor = std::clamp(std::round(internal / rate), 1.0, 256.0);
  const double made = internal / divisor;
  if (std::fabs(made - rate) > 0.01 * rate) return std::nullopt;
  return made;
}

std::string dlpfText(int cfg) {
  return "DLPF_CFG " + std::to_string(cfg) + " (" + fmt("%g", dlpfSetting(cfg).bandwidth_hz) + " Hz)";
}

}  // namespace

// --dlpf / --fs-sel first, then the recording's `# device` header, else the DLPF estimated
// from the Allan curve's short-τ roll-off (FS_SEL is not estimated: without it the replicas are
// not rounded, which matters only when the noise is a few LSB).
ChainChoice settleChain(const std::string& file, std::optional<int> dlpf_cfg, std::optional<int> fs_sel,
                        const LoadedInput& in) {
  ChainChoice c;
  c.rate_hz = in.rate_hz;
  const recording::AcquisitionHeader header = recording::readAcquisitionHeader(file);
  const std::string at_line = file + ":" + std::to_string(header.line);
  if (dlpf_cfg) {
    c.chain.dlpf_cfg = dlpf_cfg;
    c.dlpf_source = "--dlpf";
  } else if (header.dlpf_cfg) {
    c.chain.dlpf_cfg = header.dlpf_cfg;
    c.dlpf_source = "recording header (" + at_line + ")";
  }
  if (fs_sel) {
    c.chain.fs_sel = fs_sel;
    c.fs_sel_source = "--fs-sel";
  } else if (header.fs_sel) {
    c.chain.fs_sel = header.fs_sel;
    c.fs_sel_source = "recording header (" + at_line + ")";
  } else {
    c.fs_sel_source = "not given: replicas not rounded";
  }
  if (!c.chain.dlpf_cfg) {
    // Estimated on every checked axis at the nearest rate a DLPF can make (1 kHz / k).
    const double snapped = reachableRate(1, in.rate_hz).value_or(in.rate_hz);
    c.scores = dlpfCandidates(snapped);
    std::size_t scored = 0;
    for (std::size_t idx : in.axis_indices) {
      // An axis the base fit cannot take (e.g. constant) is left to the check, which names it.
      std::vector<DlpfCandidate> axis_scores = dlpfCandidates(snapped);
      try {
        scoreDlpfCandidates(in.recording.axes[idx], snapped, axis_scores);
      } catch (const std::invalid_argument&) {
        continue;
      }
      double axis_best = std::numeric_limits<double>::infinity();
      for (const DlpfCandidate& cand : axis_scores) axis_best = std::min(axis_best, cand.chi2);
      c.axis_best_chi2[idx] = axis_best;
      c.no_setting_fits = c.no_setting_fits || axis_best > kNoDlpfFitsChi2;
      for (std::size_t k = 0; k < axis_scores.size(); ++k) {
        c.scores[k].chi2 += axis_scores[k].chi2;
        c.scores[k].axes_preferring += axis_scores[k].axes_preferring;
      }
      ++scored;
    }
    c.chain.dlpf_cfg = scored > 0 ? chooseDlpf(c.scores, scored) : std::nullopt;
    if (scored > 0) {
      const DlpfCandidate* lowest = nullptr;
      for (const DlpfCandidate& cand : c.scores)
        if (!lowest || cand.chi2 < lowest->chi2) lowest = &cand;
      c.best_chi2_per_axis = lowest->chi2 / static_cast<double>(scored);
      c.best_candidate = lowest->dlpf_cfg;
    }
    double none = 0.0, best = 0.0;
    for (const DlpfCandidate& cand : c.scores) {
      if (!cand.dlpf_cfg) none = cand.chi2;
      if (cand.dlpf_cfg == c.chain.dlpf_cfg) best = cand.chi2;
    }
    c.dlpf_source = c.chain.dlpf_cfg ? "estimated from the short-tau roll-off of the Allan curve (reduced chi2 " +
                                           fmt("%.3g", best) + " with it, " + fmt("%.3g", none) + " without, " +
                                           std::to_string(scored) + " axes)"
                                     : "none: not in the header, none given, no roll-off seen (reduced chi2 " +
                                           fmt("%.3g", none) + " without one, no setting clearly better)";
  }
  if (c.chain.dlpf_cfg) {
    const std::optional<double> made = reachableRate(*c.chain.dlpf_cfg, in.rate_hz);
    if (!made)
      throw recording::RecordingError(file + ": rate " + fmt("%g", in.rate_hz) + " Hz cannot be made with " +
                                      dlpfText(*c.chain.dlpf_cfg) + " (" + c.dlpf_source +
                                      "): the rate is the internal rate / (1 + SMPLRT_DIV)");
    c.rate_hz = *made;
  }
  return c;
}

std::string noDlpfFitsText(const ChainChoice& c, const std::vector<std::string>& axis_names) {
  std::string axes, values;
  for (const auto& [idx, chi2] : c.axis_best_chi2) {
    if (!(chi2 > kNoDlpfFitsChi2)) continue;
    axes += (axes.empty() ? "" : ", ") + (idx < axis_names.size() ? axis_names[idx] : std::to_string(idx));
    values += (values.empty() ? "" : ", ") + fmt("%.3g", chi2);
  }
  return "no DLPF setting fits the short-tau Allan curve of " + axes + ": best reduced chi2 " + values + " (> " +
         fmt("%g", kNoDlpfFitsChi2) + ")";
}

std::string chainText(const ChainChoice& c) {
  return "acquisition chain: " + (c.chain.dlpf_cfg ? dlpfText(*c.chain.dlpf_cfg) : std::string("no DLPF")) + " [" +
         c.dlpf_source + "]; " +
         (c.chain.fs_sel ? "FS_SEL " + std::to_string(*c.chain.fs_sel) + " (LSB 1/" +
                               fmt("%g", gyroSensitivityLsbPerDps(*c.chain.fs_sel)) + " deg/s)"
                         : std::string("no quantisation")) +
         " [" + c.fs_sel_source + "]";
}

json chainJson(const ChainChoice& c) {
  json j = {{"dlpf_cfg", c.chain.dlpf_cfg ? json(*c.chain.dlpf_cfg) : json(nullptr)},
            {"dlpf_source", c.dlpf_source},
            {"fs_sel", c.chain.fs_sel ? json(*c.chain.fs_sel) : json(nullptr)},
            {"fs_sel_source", c.fs_sel_source},
            {"rate_hz", c.rate_hz}};
  if (!c.scores.empty()) {
    json scores = json::object();
    for (const DlpfCandidate& cand : c.scores)
      scores[cand.dlpf_cfg ? std::to_string(*cand.dlpf_cfg) : std::string("none")] = cand.chi2;
    j["dlpf_estimate_reduced_chi2"] = scores;
    j["no_dlpf_setting_fits"] = c.no_setting_fits;
    json per_axis = json::object();
    for (const auto& [idx, chi2] : c.axis_best_chi2) per_axis[std::to_string(idx)] = chi2;
    j["best_reduced_chi2_by_column"] = per_axis;
    j["best_reduced_chi2_per_axis"] = c.best_chi2_per_axis;
    j["best_dlpf_cfg"] = c.best_candidate ? json(*c.best_candidate) : json(nullptr);
  }
  return j;
}

// Why an extension was not accepted (ExtensionVerdict), in words.
std::vector<std::string> worseMeasures(const ExtensionVerdict& v) {
  std::vector<std::string> w;
  if (v.adev_worse) w.push_back("adev_log_error");
  if (v.band_worse) w.push_back("in_band");
  if (v.innovation_worse) w.push_back("innovation_var_held_out");
  if (v.ljung_box_worse) w.push_back("ljung_box_p_held_out");
  if (v.tail_worse) w.push_back("innovation_tail_held_out");
  return w;
}

std::vector<std::string> betterMeasures(const ExtensionVerdict& v) {
  std::vector<std::string> b;
  if (v.adev_better) b.push_back("adev_log_error");
  if (v.band_better) b.push_back("in_band");
  if (v.innovation_better) b.push_back("innovation_var_held_out");
  if (v.ljung_box_better) b.push_back("ljung_box_p_held_out");
  if (v.tail_better) b.push_back("innovation_tail_held_out");
  return b;
}

std::vector<std::string> judgedMeasures(const ExtensionVerdict& v, const ModelCheckGain& g) {
  std::vector<std::string> m;
  if (v.allan_judged) {
    m.emplace_back("adev_log_error");
    m.emplace_back("in_band");
  }
  m.emplace_back("innovation_var_held_out");
  m.emplace_back("ljung_box_p_held_out");
  if (g.tail_judged) m.emplace_back("innovation_tail_held_out");
  return m;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

std::string notExplainedReason(const ExtensionVerdict& v) {
  const std::vector<std::string> worse = worseMeasures(v), better = betterMeasures(v);
  if (!worse.empty())
    return "the extended model with it scored worse out of sample on " + joined(worse) + " and better on " +
           (better.empty() ? std::string("none") : joined(better));
  return "the extended model with it gained on no out-of-sample measure beyond its noise";
}

json verdictJson(const ExtensionVerdict& v, const ModelCheckGain& g) {
  return {{"judged", v.judged},
          {"accepted", v.accepted},
          {"judged_by", judgedMeasures(v, g)},
          {"worse", worseMeasures(v)},
          {"better", betterMeasures(v)}};
}

json gainJson(const ModelCheckGain& g) {
  json j = {{"adev_log_error_base", g.adev_log_error_base},
            {"adev_log_error_extended", g.adev_log_error_extended},
            {"innovation_var_base", g.innovation_var_base},
            {"innovation_var_extended", g.innovation_var_extended},
            {"ljung_box_p_base", g.ljung_box_p_base},
            {"ljung_box_p_extended", g.ljung_box_p_extended},
            {"in_band_base", g.in_band_base},
            {"in_band_extended", g.in_band_extended},
            {"innovation_var_base_held_out", g.innovation_var_base_held_out},
            {"innovation_var_extended_held_out", g.innovation_var_extended_held_out},
            {"ljung_box_p_base_held_out", g.ljung_box_p_base_held_out},
            {"ljung_box_p_extended_held_out", g.ljung_box_p_extended_held_out}};
  if (g.tail_judged)
    j["innovation_tail_held_out"] = {{"count", g.tail_count_held_out},
                                     {"expected_base", g.tail_expected_base_held_out},
                                     {"expected_extended", g.tail_expected_extended_held_out},
                                     {"log_likelihood_base", g.tail_log_likelihood_base_held_out},
                                     {"log_likelihood_extended", g.tail_log_likelihood_extended_held_out}};
  return j;
}

}  // namespace gyrod::gyroctl
