#pragma once
// gyroctl model-check's support: where the acquisition chain comes from (--dlpf/--fs-sel, the
// recording's '# device' header, or the DLPF estimated from the Allan curve), and the words
// of the acceptance verdict ("seen, not explained"). docs/model-check.md.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "processing/model_check/model_check.hpp"
#include "tools/gyroctl/input.hpp"

namespace gyrod::gyroctl {

// The acquisition chain the base model gets, and where each part came from.
struct ChainChoice {
  processing::AcquisitionChain chain;
  double rate_hz = 0.0;  // the rate the check uses: the DLPF's exact rate when one is set
  std::string dlpf_source, fs_sel_source;
  std::vector<processing::DlpfCandidate> scores;  // when the DLPF was estimated
};

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
nlohmann::json verdictJson(const processing::ExtensionVerdict& v);
// The gain figures, base against extended, by their JSON names.
nlohmann::json gainJson(const processing::ModelCheckGain& g);

}  // namespace gyrod::gyroctl
