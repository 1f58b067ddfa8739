#pragma once
// gyroctl model-check's support: where the acquisition chain comes from (--dlpf/--fs-sel, the
// recording's '# device' header, or the DLPF estimated from the Allan curve), and the words
// of the acceptance verdict ("seen, not explained"). docs/model-check.md.
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "processing/model_check/model_check.hpp"
#include "tools/gyroctl/input.hpp"

namespace gyrod::gyroctl {

// A right model through a narrow DLPF keeps a reduced χ² of a few (docs/model-check.md, "The
// acquisition chain"); a real record with a shape no setting gives showed 41.
inline constexpr double kNoDlpfFitsChi2 = 10.0;

// The acquisition chain the base model gets, and where each part came from.
struct ChainChoice {
  processing::AcquisitionChain chain;
  double rate_hz = 0.0;  // the rate the check uses: the DLPF's exact rate when one is set
  std::string dlpf_source, fs_sel_source;
  std::vector<processing::DlpfCandidate> scores;  // when the DLPF was estimated
  // When estimated: the lowest reduced χ² of any candidate (none included) summed over the
  // axes, per axis, which candidate; and per axis (by column index) its own lowest, which is
  // far from fitting (> kNoDlpfFitsChi2) when its short-τ Allan curve has a shape no DLPF
  // setting gives: that axis does not "hold" (docs/model-check.md, "Misfit").
  double best_chi2_per_axis = 0.0;
  std::optional<int> best_candidate;
  std::map<std::size_t, double> axis_best_chi2;
  bool no_setting_fits = false;  // on some axis
  bool noSettingFits(std::size_t axis) const {
    const auto it = axis_best_chi2.find(axis);
    return it != axis_best_chi2.end() && it->second > kNoDlpfFitsChi2;
  }
};
// "no DLPF setting fits the short-tau Allan curve of gx, gz: best reduced chi2 41 and 52 (> 10)".
std::string noDlpfFitsText(const ChainChoice& c, const std::vector<std::string>& axis_names);

// --dlpf / --fs-sel first, then the recording's header, else the DLPF estimated. Throws
// RecordingError for a bad header value or a rate the DLPF cannot make.
ChainChoice settleChain(const std::string& file, std::optional<int> dlpf_cfg, std::optional<int> fs_sel,
                        const LoadedInput& in);
std::string chainText(const ChainChoice& c);
nlohmann::json chainJson(const ChainChoice& c);

// The measures an extension was worse or better on (JSON names), joined by ", ".
std::vector<std::string> worseMeasures(const processing::ExtensionVerdict& v);
std::vector<std::string> betterMeasures(const processing::ExtensionVerdict& v);
std::string joined(const std::vector<std::string>& v);
// Why the effects of an extension that was not accepted are "seen, not explained".
std::string notExplainedReason(const processing::ExtensionVerdict& v);
// The measures an extension was judged by: without the Allan ones when outliers are the only
// effect named (they cannot see spikes), with the held-out tail when outliers are named.
std::vector<std::string> judgedMeasures(const processing::ExtensionVerdict& v, const processing::ModelCheckGain& g);
nlohmann::json verdictJson(const processing::ExtensionVerdict& v, const processing::ModelCheckGain& g);
// The gain figures, base against extended, by their JSON names.
nlohmann::json gainJson(const processing::ModelCheckGain& g);

}  // namespace gyrod::gyroctl
