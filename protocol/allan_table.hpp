#pragma once
// One Allan table as JSON, in the one shape every writer uses: `gyroctl analyze --json`
// ("allan", "allan_after_kalman" of each axis) and the ALLAN reply ("table.<axis>.<stream>").
// docs/protocol.md, "Allan tables", is the reference.
#include <nlohmann/json.hpp>
#include <span>
#include <vector>

#include "processing/allan/allan.hpp"

namespace gyrod::protocol {

// An array with one object per point, in the order given. Fields:
//   tau_s, m, oadev, n (= oadev_terms, the second differences behind oadev)  always;
//   noise_alpha, edf, oadev_lo, oadev_hi  when the noise type is known (edf finite);
//   adev, adev_n (the non-overlapping estimator)                          when it was computed.
// A point whose oadev is not finite has no value to show and is left out.
nlohmann::ordered_json allanTableJson(std::span<const processing::AllanPoint> points);

// The inverse: fields left out come back as NaN (adev, edf, oadev_lo, oadev_hi) or 0.
// Throws std::invalid_argument naming the field for a table that is not of this shape.
std::vector<processing::AllanPoint> allanTableFromJson(const nlohmann::ordered_json& table);

}  // namespace gyrod::protocol
