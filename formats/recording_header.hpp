#pragma once
// The acquisition chain in a recording's header: gyrod writes one machine-readable comment
//
//   # device dlpf_cfg=4 fs_sel=0 rate_hz=50 smplrt_div=19
//
// before the column line (DLPF_CFG 0..6, FS_SEL 0..3, the output rate and SMPLRT_DIV, with
// rate = internal rate / (1 + SMPLRT_DIV), the internal rate 8 kHz for DLPF_CFG 0, else
// 1 kHz). The model check puts that chain into its base model (docs/model-check.md).
// Unknown keys are skipped (a later gyrod may add some); a known key with a bad value, a
// token that is not key=value or a rate that the DLPF and SMPLRT_DIV cannot make is an error
// naming FILE:LINE, the key and the value.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gyrod::recording {

struct AcquisitionHeader {
  std::optional<int> dlpf_cfg, fs_sel, smplrt_div;
  std::optional<double> rate_hz;
  std::size_t line = 0;  // the `# device` line; 0 when the header has none
  // The calibration state gyrod's rate stream started from (formats/calibration_state.hpp),
  // as the `# calibration-state ` lines carry it: the TOML text, and the first such line (0: none).
  std::string calibration_state_toml;
  std::size_t calibration_state_line = 0;
};

// The prefix of each line of the calibration state in a recording's header (after "# ").
inline constexpr std::string_view kCalibrationStatePrefix = "calibration-state ";
// The header comments (without "# ") that carry `toml`: one per line that is neither empty nor a comment.
std::vector<std::string> calibrationStateHeaderComments(std::string_view toml);

// The comment's text, without the leading "# " (the recorder adds it).
std::string acquisitionHeaderComment(int dlpf_cfg, int fs_sel, double rate_hz, int smplrt_div);

// From the header comments of a recording's text: the comment lines before the first sample,
// on either side of the column line (gyrod writes the column line first, other writers put
// comments before it); `path` names the file in errors (RecordingError).
AcquisitionHeader parseAcquisitionHeader(std::string_view text, const std::string& path);
// The same from a file (its first 64 KiB at most); a file that cannot be opened gives an
// empty header (the reader of the samples reports that).
AcquisitionHeader readAcquisitionHeader(const std::string& path);

}  // namespace gyrod::recording
