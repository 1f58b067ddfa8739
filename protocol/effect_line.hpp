#pragma once
// The live check's changes on the wire (docs/protocol.md, "EFFECT"): one JSON object per effect
// named or gone, sent to watching clients as an EFFECT line, listed in STATUS's live_check, and
// printed by `gyroctl live-check --json`. Header-only: protocol/ formats it, and whoever runs the
// check (gyrod, gyroctl) links processing's model check itself.
#include <nlohmann/json.hpp>
#include <string>

#include "processing/model_check/live_check.hpp"

namespace gyrod::protocol {

// {"class":"EFFECT","state":"new"|"gone","effect","axis","t","onset_t","onset_t_95","params",
// "evidence"}: t and onset_t on the clock of RATE's t; params with their 95 % intervals.
inline nlohmann::json effectJson(const processing::LiveEffect& e) {
  const auto pair = [](const processing::LiveInterval95& i) { return nlohmann::json::array({i.lo, i.hi}); };
  nlohmann::json params = nlohmann::json::object();
  if (e.kind == processing::LiveEffectKind::Line) {
    params = {{"centre_hz", e.centre_hz}, {"centre_hz_95", pair(e.centre_hz_95)}, {"width_hz", e.width_hz},
              {"rms_dps", e.rms_dps},     {"rms_dps_95", pair(e.rms_dps_95)},     {"power_ratio", e.power_ratio}};
    if (e.baseline_rms_dps > 0.0) params["baseline_rms_dps"] = e.baseline_rms_dps;
  } else if (e.kind == processing::LiveEffectKind::OutlierBurst) {
    params = {{"count", e.count}, {"expected", e.expected}, {"largest_z", e.largest_z}};
  } else if (e.kind == processing::LiveEffectKind::BiasStep) {
    params = {{"size_dps", e.size_dps}, {"size_dps_95", pair(e.size_dps_95)}, {"scale_s", e.scale_s}, {"z", e.z}};
  } else {
    params = {{"coefficient_dps_per_c", e.coefficient_dps_per_c},
              {"coefficient_dps_per_c_95", pair(e.coefficient_dps_per_c_95)},
              {"baseline_coefficient_dps_per_c", e.baseline_coefficient_dps_per_c},
              {"temperature_change_c", e.temperature_change_c}};
  }
  return {{"class", "EFFECT"},
          {"state", e.gone ? "gone" : "new"},
          {"effect", processing::liveEffectName(e.kind)},
          {"axis", std::string(1, "xyz"[e.axis % 3])},
          {"t", e.t},
          {"onset_t", e.onset_t},
          {"onset_t_95", pair(e.onset_95)},
          {"params", params},
          {"evidence", e.evidence}};
}

}  // namespace gyrod::protocol
