#include "tools/gyroctl/fleet_table.hpp"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <variant>

#include "protocol/protocol.hpp"

namespace gyrod::gyroctl {
namespace {

using Json = nlohmann::json;

template <typename T>
std::optional<T> field(const Json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) return std::nullopt;
  try {
    return it->get<T>();
  } catch (const Json::exception&) {
    return std::nullopt;
  }
}

std::string formatted(const char* format, double v) {
  char text[64];
  std::snprintf(text, sizeof text, format, v);
  return text;
}

std::string optionalCount(const std::optional<std::uint64_t>& v) { return v ? std::to_string(*v) : "-"; }

// Rate messages per second as this subscriber received them (gyrod's rate_every decimates).
std::optional<double> messageRate(const FleetBoard& b) {
  if (b.rate_messages < 2 || b.last_rate_s <= b.first_rate_s) return std::nullopt;
  return static_cast<double>(b.rate_messages - 1) / (b.last_rate_s - b.first_rate_s);
}

}  // namespace

void FleetTable::take(std::string_view topic, std::string_view payload, double now_s) {
  // <root>/<board>/<kind>, the board one topic level.
  if (topic.size() <= root_.size() + 1 || topic.compare(0, root_.size(), root_) != 0 || topic[root_.size()] != '/') {
    ++ignored_;
    return;
  }
  const std::string_view rest = topic.substr(root_.size() + 1);
  const auto slash = rest.find('/');
  if (slash == std::string_view::npos || slash == 0 || rest.find('/', slash + 1) != std::string_view::npos) {
    ++ignored_;
    return;
  }
  const std::string_view kind = rest.substr(slash + 1);
  FleetBoard& b = boards_[std::string(rest.substr(0, slash))];
  b.last_seen_s = now_s;
  if (kind == protocol::kMqttStatusTopic) {
    takeStatus(b, payload);
  } else if (kind == protocol::kMqttRateTopic) {
    takeRate(b, payload, now_s);
  } else if (kind == protocol::kMqttGapTopic) {
    ++b.gap_messages;
  } else {
    ++ignored_;
  }
}

void FleetTable::takeStatus(FleetBoard& b, std::string_view payload) {
  const Json j = Json::parse(payload, nullptr, false);
  if (!j.is_object()) {
    ++b.malformed;
    return;
  }
  b.state = field<std::string>(j, "state").value_or("");
  if (auto v = field<std::string>(j, "device")) b.device = *v;
  if (auto v = field<double>(j, "rate_hz")) b.configured_rate_hz = v;
  if (auto v = field<std::uint64_t>(j, "samples")) b.samples = v;
  if (auto v = field<std::uint64_t>(j, "gaps")) b.gaps = v;
  if (auto v = field<std::uint64_t>(j, "samples_lost")) b.samples_lost = v;
  if (auto v = field<std::uint64_t>(j, "mqtt_dropped")) b.mqtt_dropped = v;
}

void FleetTable::takeRate(FleetBoard& b, std::string_view payload, double now_s) {
  protocol::ServerMessage message;
  try {
    message = protocol::parseServerLine(payload);
  } catch (const std::exception&) {
    ++b.malformed;
    return;
  }
  const auto* r = std::get_if<protocol::RateSample>(&message);
  if (r == nullptr) {
    ++b.malformed;
    return;
  }
  if (b.rate_messages == 0) b.first_rate_s = now_s;
  ++b.rate_messages;
  b.last_rate_s = now_s;
  b.seq = r->seq;
  // `rate` once gyrod sends it (after its start-up estimate), the raw rate until then.
  b.has_rate = std::isfinite(r->rate_dps[0]);
  b.rate_dps = b.has_rate ? r->rate_dps : r->raw_dps;
  b.has_bias = std::isfinite(r->bias_dps[0]);
  if (b.has_bias) b.bias_dps = r->bias_dps;
  b.temp_c = r->temp_c;
  b.still = r->still;
}

std::string FleetTable::shownState(const FleetBoard& b, double now_s) {
  if (b.state == "online" && now_s - b.last_seen_s > kSilentAfterSeconds) return "silent";
  return b.state.empty() ? "?" : b.state;
}

std::string FleetTable::text(double now_s) const {
  char line[512];
  std::string out;
  std::snprintf(line, sizeof line, "%-20s %-8s %8s %8s  %-26s  %-26s %7s %6s %10s %6s %7s %8s\n", "board", "state",
                "rate_hz", "msgs/s", "rate x y z [deg/s]", "bias x y z [deg/s]", "temp_C", "still", "samples", "gaps",
                "lost", "seen");
  out += line;
  for (const auto& [name, b] : boards_) {
    const auto triple = [](bool has, const std::array<double, 3>& v) {
      if (!has) return std::string("-");
      return formatted("%+8.3f", v[0]) + " " + formatted("%+8.3f", v[1]) + " " + formatted("%+8.3f", v[2]);
    };
    const auto rate = messageRate(b);
    std::snprintf(
        line, sizeof line, "%-20s %-8s %8s %8s  %-26s  %-26s %7s %6s %10s %6s %7s %8s\n", name.c_str(),
        shownState(b, now_s).c_str(), b.configured_rate_hz ? formatted("%.4g", *b.configured_rate_hz).c_str() : "-",
        rate ? formatted("%.1f", *rate).c_str() : "-", triple(b.rate_messages > 0, b.rate_dps).c_str(),
        triple(b.has_bias, b.bias_dps).c_str(), b.temp_c ? formatted("%.2f", *b.temp_c).c_str() : "-",
        b.still ? (*b.still ? "yes" : "no") : "-", optionalCount(b.samples).c_str(), optionalCount(b.gaps).c_str(),
        optionalCount(b.samples_lost).c_str(), formatted("%.1fs", now_s - b.last_seen_s).c_str());
    out += line;
  }
  return out;
}

std::string FleetTable::json(double now_s) const {
  Json boards = Json::array();
  for (const auto& [name, b] : boards_) {
    Json row = {{"board", name},
                {"state", shownState(b, now_s)},
                {"device", b.device},
                {"rate_messages", b.rate_messages},
                {"gap_messages", b.gap_messages},
                {"seen_s_ago", now_s - b.last_seen_s}};
    const auto put = [&row](const char* key, const auto& v) {
      if (v) row[key] = *v;
    };
    put("rate_hz", b.configured_rate_hz);
    put("messages_per_s", messageRate(b));
    put("samples", b.samples);
    put("gaps", b.gaps);
    put("samples_lost", b.samples_lost);
    put("mqtt_dropped", b.mqtt_dropped);
    put("seq", b.seq);
    put("temp", b.temp_c);
    put("still", b.still);
    if (b.rate_messages > 0) row[b.has_rate ? "rate" : "raw"] = b.rate_dps;
    if (b.has_bias) row["bias"] = b.bias_dps;
    if (b.malformed > 0) row["malformed"] = b.malformed;
    boards.push_back(std::move(row));
  }
  return Json{{"boards", std::move(boards)}}.dump();
}

}  // namespace gyrod::gyroctl
