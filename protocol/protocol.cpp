#include "protocol/protocol.hpp"

#include "protocol/allan_table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "processing/base/units.hpp"

namespace gyrod::protocol {
namespace {

// Insertion-ordered, so that "class" comes first in every line, as in gpsd.
using json = nlohmann::ordered_json;

// Appends to a fixed buffer; the callers size the buffers for their longest line, so an
// overflow is a programming error that shows as a truncated (and then asserted) line.
class FixedWriter {
 public:
  FixedWriter(char* begin, char* end) noexcept : begin_(begin), p_(begin), end_(end) {}
  void text(std::string_view s) noexcept {
    const std::size_t n = std::min(s.size(), static_cast<std::size_t>(end_ - p_));
    std::memcpy(p_, s.data(), n);
    p_ += n;
  }
  void number(std::uint64_t v) noexcept {
    const auto r = std::to_chars(p_, end_, v);
    if (r.ec == std::errc()) p_ = r.ptr;
  }
  // Shortest representation that reads back as the same double (never "inf"/"nan": the
  // callers check finiteness first).
  void number(double v) noexcept {
    if (v == 0.0 && std::signbit(v)) {  // "-0" would be read back as the integer 0
      text("-0.0");
      return;
    }
    const auto r = std::to_chars(p_, end_, v);
    if (r.ec == std::errc()) p_ = r.ptr;
  }
  // Fixed notation with `decimals` digits after the point (a finite value); beyond 1e15 (a
  // time 31 million years away) the shortest form, so the line stays within its bound.
  void fixed(double v, int decimals) noexcept {
    if (!(std::fabs(v) < 1e15)) {
      number(v);
      return;
    }
    const auto r = std::to_chars(p_, end_, v, std::chars_format::fixed, decimals);
    if (r.ec == std::errc()) p_ = r.ptr;
  }
  void triple(std::string_view key, const std::array<double, 3>& v) noexcept {
    if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]))) return;
    text(key);
    number(v[0]);
    text(",");
    number(v[1]);
    text(",");
    number(v[2]);
    text("]");
  }
  // key then v, when v is finite.
  void real(std::string_view key, double v) noexcept {
    if (!std::isfinite(v)) return;
    text(key);
    number(v);
  }
  std::size_t size() const noexcept { return static_cast<std::size_t>(p_ - begin_); }

 private:
  char* begin_;
  char* p_;
  char* end_;
};

bool isReasonToken(std::string_view s) {
  if (s.empty() || s.size() > kMaxGapReasonBytes) return false;
  for (const char c : s) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  }
  return true;
}

std::string jsonLine(const json& j) { return j.dump() + '\n'; }

void putIfFinite(json& j, const char* key, const std::optional<double>& v) {
  if (v && std::isfinite(*v)) j[key] = *v;
}

const char* jsonTypeName(const json& j) { return j.type_name(); }

}  // namespace

std::size_t formatRateLine(const RateSample& s, std::span<char, kMaxRateLineBytes> out) noexcept {
  // One byte is kept back for the newline, so it is always there.
  FixedWriter w(out.data(), out.data() + out.size() - 1);
  w.text(R"({"class":"RATE","seq":)");
  w.number(s.seq);
  if (std::isfinite(s.t_s)) {
    w.text(R"(,"t":)");
    w.number(s.t_s);
  }
  if (std::isfinite(s.temp_c)) {
    w.text(R"(,"temp":)");
    w.number(s.temp_c);
  }
  w.triple(R"(,"raw":[)", s.raw_dps);
  w.triple(R"(,"mean":[)", s.mean_dps);
  w.triple(R"(,"kalman":[)", s.kalman_dps);
  w.triple(R"(,"rate":[)", s.rate_dps);
  w.triple(R"(,"bias":[)", s.bias_dps);
  if (s.still) w.text(*s.still ? R"(,"still":true)" : R"(,"still":false)");
  if (std::isfinite(s.time_s)) {
    w.text(R"(,"time":)");
    w.fixed(s.time_s, kRateTimeDecimals);
  }
  w.triple(R"(,"accel":[)", s.accel_g);
  const auto& a = s.accel_g;
  w.triple(R"(,"accel_ms2":[)",
           {a[0] * units::kStandardGravity, a[1] * units::kStandardGravity, a[2] * units::kStandardGravity});
  const auto& q = s.quat;
  if (std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]) && std::isfinite(q[3])) {
    w.text(R"(,"quat":[)");
    w.number(q[0]);
    w.text(",");
    w.triple("", {q[1], q[2], q[3]});
  }
  const auto& e = s.roll_pitch_heading_deg;
  if (std::isfinite(e[0]) && std::isfinite(e[1]) && std::isfinite(e[2])) {
    w.real(R"(,"roll":)", e[0]);
    w.real(R"(,"pitch":)", e[1]);
    w.real(R"(,"heading":)", e[2]);
  }
  w.real(R"(,"inclination_std":)", s.inclination_std_deg);
  w.real(R"(,"heading_std":)", s.heading_std_deg);
  w.text("}");
  const std::size_t n = w.size();
  out[n] = '\n';
  return n + 1;
}

std::size_t formatGapLine(const GapEvent& gap, std::span<char, kMaxGapLineBytes> out) {
  if (gap.count == 0) throw std::invalid_argument("GAP: count must be >= 1 (a gap of 0 samples is no gap)");
  if (!isReasonToken(gap.reason))
    throw std::invalid_argument("GAP: reason '" + std::string(gap.reason) + "' is not a token of 1.." +
                                std::to_string(kMaxGapReasonBytes) + " characters [a-z0-9_]");
  FixedWriter w(out.data(), out.data() + out.size() - 1);
  w.text(R"({"class":"GAP","seq":)");
  w.number(gap.first_missing_seq);
  w.text(R"(,"count":)");
  w.number(gap.count);
  w.text(R"(,"reason":")");
  w.text(gap.reason);
  w.text("\"}");
  const std::size_t n = w.size();
  out[n] = '\n';
  return n + 1;
}

std::string versionLine(std::string_view release) {
  return jsonLine(
      {{"class", "VERSION"}, {"release", release}, {"proto_major", kProtocolMajor}, {"proto_minor", kProtocolMinor}});
}

std::string watchLine(bool enable, std::uint32_t decimate) {
  return jsonLine({{"class", "WATCH"}, {"enable", enable}, {"decimate", decimate}});
}

std::string_view errorCodeName(ErrorCode code) {
  switch (code) {
    case ErrorCode::BadRequest: return "bad_request";
    case ErrorCode::NotJson: return "not_json";
    case ErrorCode::NotObject: return "not_object";
    case ErrorCode::MissingField: return "missing_field";
    case ErrorCode::BadType: return "bad_type";
    case ErrorCode::UnknownCommand: return "unknown_cmd";
    case ErrorCode::UnknownField: return "unknown_field";
    case ErrorCode::DuplicateField: return "duplicate_field";
    case ErrorCode::OutOfRange: return "out_of_range";
    case ErrorCode::LineTooLong: return "line_too_long";
    case ErrorCode::TooManyClients: return "too_many_clients";
    case ErrorCode::Internal: return "internal";
  }
  return "internal";
}

std::string_view stillCheckName(StillCheck check) {
  switch (check) {
    case StillCheck::Pending: return "pending";
    case StillCheck::Still: return "still";
    case StillCheck::MovedRetrying: return "moved_retrying";
    case StillCheck::MovedKept: return "moved_kept";
  }
  return "unknown";
}

std::string errorLine(ErrorCode code, std::string_view message) {
  // The message may quote client bytes that are not UTF-8: replace them, never throw.
  return json({{"class", "ERROR"}, {"code", errorCodeName(code)}, {"message", message}})
             .dump(-1, ' ', false, json::error_handler_t::replace) +
         '\n';
}

std::string allanLine(const AllanReport& r) {
  const std::size_t n = r.tau_s.size();
  for (std::size_t a = 0; a < 3; ++a)
    for (std::size_t s = 0; s < 3; ++s) {
      const auto& c = r.curves[a][s].adev_dps;
      if (!c.empty() && c.size() != n)
        throw std::invalid_argument("ALLAN: curve " + std::string(kAxisNames[a]) + "/" + std::string(kStreamNames[s]) +
                                    " has " + std::to_string(c.size()) + " values for " + std::to_string(n) + " taus");
    }
  // Keep τ only where every computed curve has a value.
  std::vector<std::size_t> keep;
  for (std::size_t i = 0; i < n; ++i) {
    bool ok = std::isfinite(r.tau_s[i]);
    for (const auto& axis : r.curves)
      for (const auto& curve : axis)
        if (!curve.adev_dps.empty() && !std::isfinite(curve.adev_dps[i])) ok = false;
    if (ok) keep.push_back(i);
  }
  json j = {{"class", "ALLAN"}, {"samples", r.samples}};
  if (std::isfinite(r.window_s)) j["window"] = r.window_s;
  if (std::isfinite(r.span_s)) j["span"] = r.span_s;
  if (std::isfinite(r.tau0_s) && r.tau0_s > 0.0) j["tau0"] = r.tau0_s;
  if (std::isfinite(r.confidence)) j["confidence"] = r.confidence;
  json taus = json::array();
  for (const std::size_t i : keep) taus.push_back(r.tau_s[i]);
  j["tau"] = std::move(taus);
  json adev = json::object();
  json noise = json::object();
  json uncertainty = json::object();
  json table = json::object();
  for (std::size_t a = 0; a < 3; ++a) {
    json axis_adev = json::object();
    json axis_noise = json::object();
    json axis_uncertainty = json::object();
    json axis_table = json::object();
    for (std::size_t s = 0; s < 3; ++s) {
      const AllanCurve& c = r.curves[a][s];
      const std::string stream(kStreamNames[s]);
      if (!c.adev_dps.empty()) {
        json values = json::array();
        for (const std::size_t i : keep) values.push_back(c.adev_dps[i]);
        axis_adev[stream] = std::move(values);
      }
      if (c.noise) {
        json terms = json::object();
        for (const auto t : processing::kAllNoiseTerms) {
          const double v = c.noise->get(t);
          if (std::isfinite(v)) terms[std::string(processing::noiseTermKey(t))] = v;
        }
        if (!terms.empty()) axis_noise[stream] = std::move(terms);
      }
      if (c.noise && c.noise_uncertainty) {
        json terms = json::object();
        for (const auto t : processing::kAllNoiseTerms) {
          const double v = c.noise_uncertainty->get(t);
          // An uncertainty only beside a value: a term left out has nothing to be uncertain about.
          if (std::isfinite(v) && std::isfinite(c.noise->get(t))) terms[std::string(processing::noiseTermKey(t))] = v;
        }
        if (!terms.empty()) axis_uncertainty[stream] = std::move(terms);
      }
      if (!c.points.empty()) axis_table[stream] = allanTableJson(c.points);
    }
    const std::string axis(kAxisNames[a]);
    if (!axis_adev.empty()) adev[axis] = std::move(axis_adev);
    if (!axis_noise.empty()) noise[axis] = std::move(axis_noise);
    if (!axis_uncertainty.empty()) uncertainty[axis] = std::move(axis_uncertainty);
    if (!axis_table.empty()) table[axis] = std::move(axis_table);
  }
  j["adev"] = std::move(adev);
  if (!noise.empty()) j["noise"] = std::move(noise);
  if (!uncertainty.empty()) j["noise_uncertainty"] = std::move(uncertainty);
  if (!table.empty()) j["table"] = std::move(table);
  return jsonLine(j);
}

std::string statusLine(const StatusReport& d, const ServerStatus& s) {
  json j = {{"class", "STATUS"},  {"uptime", d.uptime_s},          {"samples", d.samples},
            {"gaps", d.gaps},     {"missing", d.missing_samples},  {"bus_errors", d.bus_errors},
            {"resets", d.resets}, {"device_state", d.device_state}};
  if (!std::isfinite(d.uptime_s)) j.erase("uptime");
  if (!d.device_reason.empty()) j["device_reason"] = d.device_reason;
  if (d.device_retrying) j["device_retrying"] = *d.device_retrying;
  if (d.device) j["device"] = *d.device;
  putIfFinite(j, "rate", d.rate_hz);
  putIfFinite(j, "nominal_rate", d.nominal_rate_hz);
  putIfFinite(j, "temp", d.temp_c);
  if (d.bias_source) j["bias_source"] = *d.bias_source;
  if (d.still_check) j["still_check"] = *d.still_check;
  if (d.still_check_detail) j["still_check_detail"] = *d.still_check_detail;
  if (d.rate_model) j["rate_model"] = *d.rate_model;
  if (d.recording) j["recording"] = *d.recording;
  if (d.recorder) {
    json recorder = {{"written", d.recorder->written},
                     {"dropped", d.recorder->dropped},
                     {"lost", d.recorder->lost},
                     {"errors", d.recorder->errors}};
    if (!d.recorder->last_error.empty()) recorder["last_error"] = d.recorder->last_error;
    j["recorder"] = std::move(recorder);
  }
  if (d.mqtt) {
    j["mqtt_connected"] = d.mqtt->connected;
    j["mqtt_buffered"] = d.mqtt->buffered;
    j["mqtt_dropped"] = d.mqtt->dropped;
    if (!d.mqtt->last_error.empty()) j["mqtt_last_error"] = d.mqtt->last_error;
  }
  if (d.calibration_state) {
    json state = {{"file", d.calibration_state->file},
                  {"restored", d.calibration_state->restored},
                  {"writes", d.calibration_state->writes}};
    if (!d.calibration_state->last_error.empty()) state["last_error"] = d.calibration_state->last_error;
    j["calibration_state"] = std::move(state);
  }
  if (d.live_check) {
    json current = json::array();
    for (const std::string& e : d.live_check->current) current.push_back(json::parse(e, nullptr, false));
    j["live_check"] = {{"intervals", d.live_check->intervals},
                       {"baseline_ready", d.live_check->baseline_ready},
                       {"named", d.live_check->named},
                       {"skipped", d.live_check->skipped},
                       {"current", std::move(current)}};
  }
  if (!d.device_counters.empty()) {
    json counters = json::object();
    for (const NamedCount& c : d.device_counters) counters[c.name] = c.value;
    j["counters"] = std::move(counters);
  }
  j["clients"] = s.clients;
  j["clients_total"] = s.clients_total;
  j["clients_dropped"] = s.clients_dropped;
  j["lines_dropped"] = s.lines_dropped;
  j["client_buffer"] = s.client_buffer_bytes;
  json list = json::array();
  for (const ClientStatus& c : s.client_list) {
    json e = {{"id", c.id},
              {"watch", c.watch},
              {"decimate", c.decimate},
              {"lines_queued", c.lines_queued},
              {"lines_sent", c.lines_sent},
              {"buffered", c.buffered_bytes}};
    if (c.pid) e["pid"] = *c.pid;
    if (c.uid) e["uid"] = *c.uid;
    if (c.self) e["self"] = true;
    list.push_back(std::move(e));
  }
  j["client_list"] = std::move(list);
  return json(j).dump(-1, ' ', false, json::error_handler_t::replace) + '\n';
}

EffectsReport effectsReportOf(const std::optional<LiveCheckStatus>& live_check, std::string off_reason) {
  EffectsReport r;
  if (!live_check) {
    r.reason = std::move(off_reason);
    return r;
  }
  r.live_check = true;
  r.baseline_ready = live_check->baseline_ready;
  r.intervals = live_check->intervals;
  r.effects = live_check->current;
  return r;
}

std::string effectsLine(const EffectsReport& r) {
  json j = {{"class", "EFFECTS"}, {"live_check", r.live_check ? "on" : "off"}};
  if (!r.reason.empty()) j["reason"] = r.reason;
  if (r.live_check) {
    j["baseline_ready"] = r.baseline_ready;
    j["intervals"] = r.intervals;
  }
  json effects = json::array();
  for (const std::string& e : r.effects) {
    json object = json::parse(e, nullptr, false);
    if (object.is_object()) effects.push_back(std::move(object));  // never a line that is not JSON
  }
  j["effects"] = std::move(effects);
  return j.dump(-1, ' ', false, json::error_handler_t::replace) + '\n';
}

std::string requestLine(const Request& request) {
  if (const auto* w = std::get_if<WatchRequest>(&request))
    return json({{"cmd", "watch"}, {"enable", w->enable}, {"decimate", w->decimate}}).dump();
  if (std::holds_alternative<AllanRequest>(request)) return R"({"cmd":"allan"})";
  if (std::holds_alternative<EffectsRequest>(request)) return R"({"cmd":"effects"})";
  return R"({"cmd":"status"})";
}

namespace {

// A client's string in a message, as a JSON string: an escaped NUL ("\u0000") decodes to a NUL
// byte, which would end the message (exceptions carry C strings), and other control bytes
// would reach the client's terminal.
std::string quotedText(const std::string& text) {
  return json(text).dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace

Request parseRequest(std::string_view line) {
  // The JSON parser takes a NUL for the end of its input: `{"cmd":"status"}\0garbage` would be
  // answered as a status request, and whatever follows the NUL silently dropped. A request is
  // text: a control byte anywhere (tab and carriage return, JSON whitespace, excepted) refuses
  // the whole line.
  for (std::size_t i = 0; i < line.size(); ++i) {
    const auto byte = static_cast<unsigned char>(line[i]);
    if ((byte < 0x20 && byte != '\t' && byte != '\r') || byte == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02X", byte);
      throw ProtocolError(ErrorCode::BadRequest, std::string("control byte ") + hex + " at byte " +
                                                     std::to_string(i + 1) +
                                                     " of the line: a request is one line of JSON text");
    }
  }
  // JSON parsers keep the last of two equal keys; a request naming "cmd" twice is ambiguous,
  // so the first repeated key of the request object is noted and the request refused.
  std::vector<std::string> keys;
  std::optional<std::string> duplicate;
  const json::parser_callback_t noteDuplicateKeys = [&](int depth, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::key && depth == 1 && !duplicate) {
      const std::string& key = parsed.get_ref<const std::string&>();
      if (std::find(keys.begin(), keys.end(), key) != keys.end())
        duplicate = key;
      else
        keys.push_back(key);
    }
    return true;
  };
  const json j = json::parse(line.begin(), line.end(), noteDuplicateKeys, /*allow_exceptions=*/false);
  if (j.is_discarded()) throw ProtocolError(ErrorCode::NotJson, "the line is not valid JSON");
  if (duplicate && j.is_object())
    throw ProtocolError(ErrorCode::DuplicateField, "field " + quotedText(*duplicate) + " appears more than once");
  if (!j.is_object())
    throw ProtocolError(ErrorCode::NotObject, std::string("expected a JSON object, got ") + jsonTypeName(j));
  const auto cmd_it = j.find("cmd");
  if (cmd_it == j.end()) throw ProtocolError(ErrorCode::MissingField, "no \"cmd\" field");
  if (!cmd_it->is_string())
    throw ProtocolError(ErrorCode::BadType, std::string("\"cmd\" must be a string, got ") + jsonTypeName(*cmd_it));
  const std::string& cmd = cmd_it->get_ref<const std::string&>();

  auto rejectOtherFields = [&](std::initializer_list<std::string_view> allowed) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      bool known = it.key() == "cmd";
      for (const auto a : allowed) known = known || it.key() == a;
      if (!known)
        throw ProtocolError(ErrorCode::UnknownField, quotedText(cmd) + " takes no field " + quotedText(it.key()));
    }
  };

  if (cmd == "watch") {
    rejectOtherFields({"enable", "decimate"});
    WatchRequest w;
    if (const auto it = j.find("enable"); it != j.end()) {
      if (!it->is_boolean())
        throw ProtocolError(ErrorCode::BadType,
                            std::string("\"enable\" must be true or false, got ") + jsonTypeName(*it));
      w.enable = it->get<bool>();
    }
    if (const auto it = j.find("decimate"); it != j.end()) {
      if (!it->is_number_integer())
        throw ProtocolError(ErrorCode::BadType,
                            std::string("\"decimate\" must be an integer, got ") +
                                (it->is_number_float() ? std::string("a fractional number") : jsonTypeName(*it)));
      const bool in_range =
          it->is_number_unsigned() && it->get<std::uint64_t>() >= 1 && it->get<std::uint64_t>() <= kMaxDecimate;
      if (!in_range)
        throw ProtocolError(ErrorCode::OutOfRange,
                            "\"decimate\" must be in 1.." + std::to_string(kMaxDecimate) + ", got " + it->dump());
      w.decimate = static_cast<std::uint32_t>(it->get<std::uint64_t>());
    }
    return w;
  }
  if (cmd == "allan") {
    rejectOtherFields({});
    return AllanRequest{};
  }
  if (cmd == "status") {
    rejectOtherFields({});
    return StatusRequest{};
  }
  if (cmd == "effects") {
    rejectOtherFields({});
    return EffectsRequest{};
  }
  throw ProtocolError(ErrorCode::UnknownCommand,
                      "unknown cmd " + quotedText(cmd) + " (known: watch, allan, status, effects)");
}

}  // namespace gyrod::protocol
