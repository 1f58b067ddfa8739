#pragma once
// gyroctl model-check leaves motion at the ends of a static recording out
// (processing/model_check/edge_motion.hpp), says what it left out, and keeps it with
// --keep-edges. docs/model-check.md, "Motion at the ends".
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "processing/model_check/edge_motion.hpp"
#include "tools/gyroctl/input.hpp"

namespace gyrod::gyroctl {

struct EdgeTrim {
  processing::EdgeMotion motion;
  std::size_t samples_read = 0;  // before the cut
  double rate_hz = 0.0;
  bool kept = false;  // --keep-edges: found, not cut
};

// Finds the motion at the ends of in's gyro columns and, unless `keep`, removes those samples
// from every column of the recording (t, gyro, temperature, accel, …).
EdgeTrim trimEdgeMotion(LoadedInput& in, bool keep);
// One line when something was found ("" otherwise), and the JSON object `edges`.
std::string edgeTrimText(const std::string& file, const EdgeTrim& trim);
nlohmann::json edgeTrimJson(const EdgeTrim& trim);

}  // namespace gyrod::gyroctl
