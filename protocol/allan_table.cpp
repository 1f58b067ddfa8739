#include "protocol/allan_table.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace gyrod::protocol {
namespace {

using json = nlohmann::ordered_json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const json& require(const json& point, const char* key, bool (json::*is_type)() const noexcept) {
  const auto it = point.find(key);
  if (it == point.end() || !((*it).*is_type)())
    throw std::invalid_argument(std::string("Allan table point: \"") + key + "\" missing or of the wrong type");
  return *it;
}

double realOr(const json& point, const char* key) {
  const auto it = point.find(key);
  if (it == point.end()) return kNaN;
  if (!it->is_number()) throw std::invalid_argument(std::string("Allan table point: \"") + key + "\" must be a number");
  return it->get<double>();
}

}  // namespace

json allanTableJson(std::span<const processing::AllanPoint> points) {
  json table = json::array();
  for (const auto& p : points) {
    if (!std::isfinite(p.oadev)) continue;
    json j = {{"tau_s", p.tau_s}, {"m", p.m}, {"oadev", p.oadev}, {"n", p.oadev_terms}};
    if (std::isfinite(p.edf)) {
      j["noise_alpha"] = p.noise_alpha;
      j["edf"] = p.edf;
      if (std::isfinite(p.oadev_lo) && std::isfinite(p.oadev_hi)) {
        j["oadev_lo"] = p.oadev_lo;
        j["oadev_hi"] = p.oadev_hi;
      }
    }
    if (std::isfinite(p.adev)) {
      j["adev"] = p.adev;
      j["adev_n"] = p.adev_terms;
    }
    table.push_back(std::move(j));
  }
  return table;
}

std::vector<processing::AllanPoint> allanTableFromJson(const json& table) {
  if (!table.is_array()) throw std::invalid_argument("an Allan table must be a list of points");
  std::vector<processing::AllanPoint> points;
  for (const json& j : table) {
    if (!j.is_object()) throw std::invalid_argument("an Allan table point must be an object");
    processing::AllanPoint p;
    p.tau_s = require(j, "tau_s", &json::is_number).get<double>();
    p.m = require(j, "m", &json::is_number_unsigned).get<std::size_t>();
    p.oadev = require(j, "oadev", &json::is_number).get<double>();
    p.oadev_terms = require(j, "n", &json::is_number_unsigned).get<std::size_t>();
    p.edf = realOr(j, "edf");
    p.oadev_lo = realOr(j, "oadev_lo");
    p.oadev_hi = realOr(j, "oadev_hi");
    if (const auto it = j.find("noise_alpha"); it != j.end() && it->is_number_integer()) p.noise_alpha = it->get<int>();
    p.adev = realOr(j, "adev");
    if (const auto it = j.find("adev_n"); it != j.end() && it->is_number_unsigned())
      p.adev_terms = it->get<std::size_t>();
    points.push_back(p);
  }
  return points;
}

}  // namespace gyrod::protocol
