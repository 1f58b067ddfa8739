#pragma once
// gyroctl model-check --write-model: the extended model as a sensor-model TOML file that
// `gyroctl simulate --model` and gyrod read (docs/model-check.md, "Writing the extended model").
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "processing/model_check/model_check.hpp"
#include "tools/gyroctl/input.hpp"

namespace gyrod::gyroctl {

// Fails before the check runs (it can take minutes) when OUT cannot be written: a folder, a
// missing or read-only folder, a FIFO, a device, the input itself. Throws ExitError.
void requireWritableTarget(const std::string& path, const std::string& input);

// The model file's text: the refitted five terms of each checked axis plus its explained
// effects as [axis.extra] tables, the acquisition chain, the temperature warm-up fitted to the
// recording, each axis's rate calibration; effects that cannot be written become comments.
std::string extendedModelToml(const std::string& file, std::uint64_t seed, std::size_t replicas, const LoadedInput& in,
                              const std::vector<std::pair<std::string, processing::AxisModelCheck>>& results);

}  // namespace gyrod::gyroctl
