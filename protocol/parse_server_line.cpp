// Reading the server's lines: the inverse of the formatters in protocol.cpp.
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "protocol/allan_table.hpp"
#include "protocol/protocol.hpp"

namespace gyrod::protocol {
namespace {

// Insertion-ordered, so that a client sees fields (counters, unknown fields) in line order.
using json = nlohmann::ordered_json;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

[[noreturn]] void malformed(std::string_view cls, const std::string& what) {
  throw MalformedLine(std::string(cls) + " line: " + what);
}

// A field of the expected JSON type, or nullptr when absent; MalformedLine when mistyped.
const json* field(const json& j, std::string_view cls, const char* key, bool (json::*is_type)() const noexcept,
                  const char* type_name) {
  const auto it = j.find(key);
  if (it == j.end()) return nullptr;
  if (!((*it).*is_type)()) malformed(cls, std::string("\"") + key + "\" must be " + type_name + ", got " + it->dump());
  return &*it;
}

const json& required(const json* value, std::string_view cls, const char* key) {
  if (value == nullptr) malformed(cls, std::string("no \"") + key + "\" field");
  return *value;
}

double realOr(const json& j, std::string_view cls, const char* key, double absent) {
  const json* v = field(j, cls, key, &json::is_number, "a number");
  return v ? v->get<double>() : absent;
}

std::optional<double> optionalReal(const json& j, std::string_view cls, const char* key) {
  const json* v = field(j, cls, key, &json::is_number, "a number");
  return v ? std::optional<double>(v->get<double>()) : std::nullopt;
}

std::uint64_t count(const json& j, std::string_view cls, const char* key) {
  return required(field(j, cls, key, &json::is_number_unsigned, "an integer >= 0"), cls, key).get<std::uint64_t>();
}

std::optional<std::int64_t> optionalInteger(const json& j, std::string_view cls, const char* key) {
  const json* v = field(j, cls, key, &json::is_number_integer, "an integer");
  return v ? std::optional<std::int64_t>(v->get<std::int64_t>()) : std::nullopt;
}

std::optional<std::string> optionalText(const json& j, std::string_view cls, const char* key) {
  const json* v = field(j, cls, key, &json::is_string, "a string");
  return v ? std::optional<std::string>(v->get<std::string>()) : std::nullopt;
}

std::optional<bool> optionalFlag(const json& j, std::string_view cls, const char* key) {
  const json* v = field(j, cls, key, &json::is_boolean, "true or false");
  return v ? std::optional<bool>(v->get<bool>()) : std::nullopt;
}

std::array<double, 3> triple(const json& j, const char* key) {
  const json* v = field(j, "RATE", key, &json::is_array, "[x, y, z]");
  if (v == nullptr) return {kNaN, kNaN, kNaN};
  if (v->size() != 3) malformed("RATE", std::string("\"") + key + "\" must have 3 elements");
  std::array<double, 3> out{};
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(*v)[i].is_number()) malformed("RATE", std::string("\"") + key + "\" must hold numbers");
    out[i] = (*v)[i].get<double>();
  }
  return out;
}

RateSample rateOf(const json& j) {
  RateSample r;
  r.seq = count(j, "RATE", "seq");
  r.t_s = realOr(j, "RATE", "t", kNaN);
  r.temp_c = realOr(j, "RATE", "temp", kNaN);
  r.raw_dps = triple(j, "raw");
  r.mean_dps = triple(j, "mean");
  r.kalman_dps = triple(j, "kalman");
  r.rate_dps = triple(j, "rate");
  r.bias_dps = triple(j, "bias");
  r.still = optionalFlag(j, "RATE", "still");
  r.time_s = realOr(j, "RATE", "time", kNaN);
  r.accel_g = triple(j, "accel");  // "accel_ms2" is the same values × standard gravity
  if (const json* q = field(j, "RATE", "quat", &json::is_array, "[w, x, y, z]")) {
    if (q->size() != 4) malformed("RATE", "\"quat\" must have 4 elements");
    for (std::size_t i = 0; i < 4; ++i) {
      if (!(*q)[i].is_number()) malformed("RATE", "\"quat\" must hold numbers");
      r.quat[i] = (*q)[i].get<double>();
    }
  }
  r.roll_pitch_heading_deg = {realOr(j, "RATE", "roll", kNaN), realOr(j, "RATE", "pitch", kNaN),
                              realOr(j, "RATE", "heading", kNaN)};
  r.inclination_std_deg = realOr(j, "RATE", "inclination_std", kNaN);
  r.heading_std_deg = realOr(j, "RATE", "heading_std", kNaN);
  return r;
}

std::vector<double> reals(const json& list, std::string_view what) {
  std::vector<double> out;
  for (const auto& v : list) {
    if (!v.is_number()) malformed("ALLAN", std::string(what) + " must hold numbers");
    out.push_back(v.get<double>());
  }
  return out;
}

// An object member of the expected key that is itself an object, or nullptr.
const json* member(const json* object, std::string_view key) {
  if (object == nullptr) return nullptr;
  const auto it = object->find(std::string(key));
  return it != object->end() && it->is_object() ? &*it : nullptr;
}

AllanReport allanOf(const json& j) {
  AllanReport r;
  r.samples = count(j, "ALLAN", "samples");
  r.window_s = realOr(j, "ALLAN", "window", kNaN);
  r.span_s = realOr(j, "ALLAN", "span", kNaN);
  r.tau0_s = realOr(j, "ALLAN", "tau0", kNaN);
  r.confidence = realOr(j, "ALLAN", "confidence", kNaN);
  if (const json* tau = field(j, "ALLAN", "tau", &json::is_array, "a list")) r.tau_s = reals(*tau, "\"tau\"");
  const json* adev = field(j, "ALLAN", "adev", &json::is_object, "an object");
  const json* noise = field(j, "ALLAN", "noise", &json::is_object, "an object");
  const json* uncertainty = field(j, "ALLAN", "noise_uncertainty", &json::is_object, "an object");
  const json* table = field(j, "ALLAN", "table", &json::is_object, "an object");
  for (std::size_t a = 0; a < kAxisNames.size(); ++a) {
    for (std::size_t s = 0; s < kStreamNames.size(); ++s) {
      AllanCurve& curve = r.curves[a][s];
      const std::string name = std::string(kAxisNames[a]) + "/" + std::string(kStreamNames[s]);
      if (const json* axis = member(adev, kAxisNames[a])) {
        if (const auto it = axis->find(std::string(kStreamNames[s])); it != axis->end()) {
          if (!it->is_array() || it->size() != r.tau_s.size())
            malformed("ALLAN", "curve " + name + " does not match its tau list");
          curve.adev_dps = reals(*it, "curve " + name);
        }
      }
      if (const json* terms = member(member(noise, kAxisNames[a]), kStreamNames[s])) {
        processing::NoiseTerms fitted;
        for (const auto t : processing::kAllNoiseTerms) {
          const auto it = terms->find(std::string(processing::noiseTermKey(t)));
          fitted.set(t, it != terms->end() && it->is_number() ? it->get<double>() : kNaN);
        }
        curve.noise = fitted;
      }
      if (const json* terms = member(member(uncertainty, kAxisNames[a]), kStreamNames[s])) {
        processing::NoiseTerms sigma;
        for (const auto t : processing::kAllNoiseTerms) {
          const auto it = terms->find(std::string(processing::noiseTermKey(t)));
          sigma.set(t, it != terms->end() && it->is_number() ? it->get<double>() : kNaN);
        }
        curve.noise_uncertainty = sigma;
      }
      if (const json* axis = member(table, kAxisNames[a])) {
        if (const auto it = axis->find(std::string(kStreamNames[s])); it != axis->end()) {
          try {
            curve.points = allanTableFromJson(*it);
          } catch (const std::invalid_argument& e) {
            malformed("ALLAN", "table " + name + ": " + e.what());
          }
        }
      }
    }
  }
  return r;
}

ClientStatus clientOf(const json& c) {
  if (!c.is_object()) malformed("STATUS", "a \"client_list\" entry must be an object");
  ClientStatus s;
  s.id = count(c, "STATUS", "id");
  s.pid = optionalInteger(c, "STATUS", "pid");
  s.uid = optionalInteger(c, "STATUS", "uid");
  s.watch = optionalFlag(c, "STATUS", "watch").value_or(false);
  s.decimate = static_cast<std::uint32_t>(count(c, "STATUS", "decimate"));
  s.lines_queued = count(c, "STATUS", "lines_queued");
  s.lines_sent = count(c, "STATUS", "lines_sent");
  s.buffered_bytes = count(c, "STATUS", "buffered");
  s.self = optionalFlag(c, "STATUS", "self").value_or(false);
  return s;
}

// The STATUS fields this version reads; any other is kept as an OtherField.
constexpr std::string_view kStatusFields[] = {"class",
                                              "uptime",
                                              "samples",
                                              "gaps",
                                              "missing",
                                              "bus_errors",
                                              "resets",
                                              "device_state",
                                              "device_reason",
                                              "device_retrying",
                                              "device",
                                              "rate",
                                              "nominal_rate",
                                              "temp",
                                              "bias_source",
                                              "rate_model",
                                              "recording",
                                              "counters",
                                              "clients",
                                              "clients_total",
                                              "clients_dropped",
                                              "lines_dropped",
                                              "client_buffer",
                                              "client_list",
                                              "recorder",
                                              "still_check",
                                              "still_check_detail",
                                              "mqtt_connected",
                                              "mqtt_buffered",
                                              "mqtt_dropped",
                                              "mqtt_last_error",
                                              "calibration_state",
                                              "live_check"};

StatusReply statusOf(const json& j) {
  constexpr std::string_view cls = "STATUS";
  StatusReply r;
  StatusReport& d = r.daemon;
  d.uptime_s = realOr(j, cls, "uptime", kNaN);
  d.samples = count(j, cls, "samples");
  d.gaps = count(j, cls, "gaps");
  d.missing_samples = count(j, cls, "missing");
  d.bus_errors = count(j, cls, "bus_errors");
  d.resets = count(j, cls, "resets");
  d.device_state = required(field(j, cls, "device_state", &json::is_string, "a string"), cls, "device_state");
  d.device_reason = optionalText(j, cls, "device_reason").value_or("");
  d.device_retrying = optionalFlag(j, cls, "device_retrying");
  d.device = optionalText(j, cls, "device");
  d.rate_hz = optionalReal(j, cls, "rate");
  d.nominal_rate_hz = optionalReal(j, cls, "nominal_rate");
  d.temp_c = optionalReal(j, cls, "temp");
  d.bias_source = optionalText(j, cls, "bias_source");
  d.still_check = optionalText(j, cls, "still_check");
  d.still_check_detail = optionalText(j, cls, "still_check_detail");
  d.rate_model = optionalText(j, cls, "rate_model");
  d.recording = optionalText(j, cls, "recording");
  if (const json* recorder = field(j, cls, "recorder", &json::is_object, "an object")) {
    RecorderStatus& rs = d.recorder.emplace();
    rs.written = count(*recorder, cls, "written");
    rs.dropped = count(*recorder, cls, "dropped");
    rs.lost = count(*recorder, cls, "lost");
    rs.errors = count(*recorder, cls, "errors");
    rs.last_error = optionalText(*recorder, cls, "last_error").value_or("");
  }
  if (const auto connected = optionalFlag(j, cls, "mqtt_connected")) {
    MqttStatus& m = d.mqtt.emplace();
    m.connected = *connected;
    m.buffered = count(j, cls, "mqtt_buffered");
    m.dropped = count(j, cls, "mqtt_dropped");
    m.last_error = optionalText(j, cls, "mqtt_last_error").value_or("");
  }
  if (const json* state = field(j, cls, "calibration_state", &json::is_object, "an object")) {
    CalibrationStateStatus& c = d.calibration_state.emplace();
    c.file = required(field(*state, cls, "file", &json::is_string, "a string"), cls, "calibration_state.file");
    c.restored = optionalFlag(*state, cls, "restored").value_or(false);
    c.writes = count(*state, cls, "writes");
    c.last_error = optionalText(*state, cls, "last_error").value_or("");
  }
  if (const json* live = field(j, cls, "live_check", &json::is_object, "an object")) {
    LiveCheckStatus& l = d.live_check.emplace();
    l.intervals = count(*live, cls, "intervals");
    l.baseline_ready = optionalFlag(*live, cls, "baseline_ready").value_or(false);
    l.named = count(*live, cls, "named");
    l.skipped = count(*live, cls, "skipped");
    if (const json* current = field(*live, cls, "current", &json::is_array, "an array"))
      for (const json& e : *current) {
        if (!e.is_object()) malformed(cls, "live_check.current must hold objects");
        l.current.push_back(e.dump());
      }
  }
  if (const json* counters = field(j, cls, "counters", &json::is_object, "an object")) {
    for (auto it = counters->begin(); it != counters->end(); ++it) {
      if (!it->is_number_unsigned()) malformed(cls, "counter \"" + it.key() + "\" must be an integer >= 0");
      d.device_counters.push_back({it.key(), it->get<std::uint64_t>()});
    }
  }
  ServerStatus& s = r.server;
  s.clients = count(j, cls, "clients");
  s.clients_total = count(j, cls, "clients_total");
  s.clients_dropped = count(j, cls, "clients_dropped");
  s.lines_dropped = count(j, cls, "lines_dropped");
  s.client_buffer_bytes = count(j, cls, "client_buffer");
  if (const json* list = field(j, cls, "client_list", &json::is_array, "a list"))
    for (const auto& c : *list) s.client_list.push_back(clientOf(c));
  for (auto it = j.begin(); it != j.end(); ++it) {
    bool known = false;
    for (const auto k : kStatusFields) known = known || it.key() == k;
    if (known) continue;
    OtherField f{it.key(), std::nullopt, std::nullopt, it->dump()};
    if (it->is_string()) f.text = it->get<std::string>();
    if (it->is_number_float()) f.real = it->get<double>();
    r.other_fields.push_back(std::move(f));
  }
  return r;
}

EffectsReport effectsOf(const json& j) {
  constexpr std::string_view cls = "EFFECTS";
  EffectsReport r;
  r.live_check = required(field(j, cls, "live_check", &json::is_string, "a string"), cls, "live_check") == "on";
  r.reason = optionalText(j, cls, "reason").value_or("");
  r.baseline_ready = optionalFlag(j, cls, "baseline_ready").value_or(false);
  if (j.contains("intervals")) r.intervals = count(j, cls, "intervals");
  if (const json* effects = field(j, cls, "effects", &json::is_array, "an array"))
    for (const json& e : *effects) {
      if (!e.is_object()) malformed(cls, "effects must hold objects");
      r.effects.push_back(e.dump());
    }
  return r;
}

}  // namespace

ServerMessage parseServerLine(std::string_view line) {
  const json j = json::parse(line.begin(), line.end(), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object() || !j.contains("class") || !j["class"].is_string())
    throw MalformedLine("not a protocol object (a JSON object with a string \"class\")");
  const std::string& cls = j["class"].get_ref<const std::string&>();
  if (cls == "RATE") return rateOf(j);
  if (cls == "GAP") {
    const json& reason = required(field(j, cls, "reason", &json::is_string, "a string"), cls, "reason");
    return GapNotice{count(j, cls, "seq"), count(j, cls, "count"), reason.get<std::string>()};
  }
  if (cls == "VERSION")
    return VersionReply{optionalText(j, cls, "release").value_or(""), optionalInteger(j, cls, "proto_major"),
                        optionalInteger(j, cls, "proto_minor")};
  if (cls == "WATCH")
    return WatchReply{optionalFlag(j, cls, "enable").value_or(false),
                      static_cast<std::uint32_t>(count(j, cls, "decimate"))};
  if (cls == "ERROR") return ErrorReply{optionalText(j, cls, "code").value_or(""), optionalText(j, cls, "message")};
  if (cls == "ALLAN") return allanOf(j);
  if (cls == "STATUS") return statusOf(j);
  if (cls == "EFFECTS") return effectsOf(j);
  return OtherClass{cls};
}

}  // namespace gyrod::protocol
