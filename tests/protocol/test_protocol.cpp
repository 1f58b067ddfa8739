// The wire format: per-sample lines parse back to exactly the published numbers, nothing
// is ever null, and every bad request is named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>

#include "protocol/protocol.hpp"

using namespace gyrod::protocol;
using nlohmann::json;

namespace {

json parseLine(const char* data, std::size_t n) {
  EXPECT_GT(n, 0u);
  EXPECT_EQ(data[n - 1], '\n');
  EXPECT_EQ(std::string(data, n - 1).find('\n'), std::string::npos);
  return json::parse(std::string(data, n - 1));
}

bool sameDouble(double a, double b) { return a == b && std::signbit(a) == std::signbit(b); }

// Doubles from every part of the range, drawn by a fixed seed from their bit patterns.
double randomFiniteDouble(std::mt19937_64& rng) {
  while (true) {
    const std::uint64_t bits = rng();
    double d;
    std::memcpy(&d, &bits, sizeof d);
    if (std::isfinite(d)) return d;
  }
}

}  // namespace

TEST(ProtocolRate, EveryDoubleRoundTripsExactly) {
  std::mt19937_64 rng(20240611);
  std::array<char, kMaxRateLineBytes> buf;
  for (int trial = 0; trial < 2000; ++trial) {
    RateSample s;
    s.seq = rng();
    s.t_s = randomFiniteDouble(rng);
    s.temp_c = randomFiniteDouble(rng);
    for (std::size_t i = 0; i < 3; ++i) {
      s.raw_dps[i] = randomFiniteDouble(rng);
      s.mean_dps[i] = randomFiniteDouble(rng);
      s.kalman_dps[i] = randomFiniteDouble(rng);
    }
    const std::size_t n = formatRateLine(s, buf);
    const json j = parseLine(buf.data(), n);
    ASSERT_EQ(j["class"], "RATE");
    EXPECT_EQ(j["seq"].get<std::uint64_t>(), s.seq);
    EXPECT_TRUE(sameDouble(j["t"].get<double>(), s.t_s));
    EXPECT_TRUE(sameDouble(j["temp"].get<double>(), s.temp_c));
    for (std::size_t i = 0; i < 3; ++i) {
      // strtod is the independent reader: nlohmann and the C library must agree with the input.
      EXPECT_TRUE(sameDouble(j["raw"][i].get<double>(), s.raw_dps[i])) << std::string(buf.data(), n);
      EXPECT_TRUE(sameDouble(j["mean"][i].get<double>(), s.mean_dps[i]));
      EXPECT_TRUE(sameDouble(j["kalman"][i].get<double>(), s.kalman_dps[i]));
      EXPECT_TRUE(sameDouble(std::strtod(j["raw"][i].dump().c_str(), nullptr), s.raw_dps[i]));
    }
  }
}

TEST(ProtocolRate, SpecialValuesAndTheLongestLineFit) {
  RateSample s;
  s.seq = std::numeric_limits<std::uint64_t>::max();
  const double longest = -2.2250738585072014e-308;  // 24 characters in shortest form
  s.t_s = s.temp_c = longest;
  s.raw_dps = {longest, -0.0, std::numeric_limits<double>::denorm_min()};
  s.mean_dps = {std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(), longest};
  s.kalman_dps = {longest, longest, longest};
  std::array<char, kMaxRateLineBytes> buf;
  const std::size_t n = formatRateLine(s, buf);
  EXPECT_LT(n, kMaxRateLineBytes);
  const json j = parseLine(buf.data(), n);
  EXPECT_EQ(j["seq"].get<std::uint64_t>(), s.seq);
  EXPECT_TRUE(sameDouble(j["raw"][1].get<double>(), -0.0));
  EXPECT_TRUE(sameDouble(j["raw"][2].get<double>(), std::numeric_limits<double>::denorm_min()));
  EXPECT_TRUE(sameDouble(j["mean"][1].get<double>(), -std::numeric_limits<double>::max()));
  EXPECT_TRUE(sameDouble(j["kalman"][2].get<double>(), longest));
}

TEST(ProtocolRate, TimeHasMicrosecondDecimalsAndAccelComesInGAndSi) {
  RateSample s;
  s.seq = 3;
  s.t_s = 5123.456;
  s.temp_c = 31.25;
  s.raw_dps = s.mean_dps = s.kalman_dps = {0.5, -0.25, 0.125};
  s.time_s = 1795000000.1234567;  // one more digit than the line keeps: rounded to µs
  s.accel_g = {0.01, -0.02, 1.0};
  std::array<char, kMaxRateLineBytes> buf;
  const std::string line(buf.data(), formatRateLine(s, buf));
  EXPECT_NE(line.find(R"("time":1795000000.123457,"accel":[0.01,-0.02,1],"accel_ms2":[)"), std::string::npos) << line;
  const json j = json::parse(line);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_EQ(j["accel_ms2"][i].get<double>(), s.accel_g[i] * 9.80665) << line;  // standard gravity
  const auto parsed = std::get<RateSample>(parseServerLine(line.substr(0, line.size() - 1)));
  EXPECT_EQ(parsed.time_s, 1795000000.123457);
  EXPECT_EQ(parsed.accel_g, s.accel_g);
  // Unset (a device without accel, an unknown wall clock): left out, as every field.
  s.time_s = RateSample::kUnset;
  s.accel_g = {1.0, RateSample::kUnset, 1.0};
  const std::string without(buf.data(), formatRateLine(s, buf));
  EXPECT_EQ(without.find("time"), std::string::npos) << without;
  EXPECT_EQ(without.find("accel"), std::string::npos) << without;
  const auto none = std::get<RateSample>(parseServerLine(without.substr(0, without.size() - 1)));
  EXPECT_TRUE(std::isnan(none.time_s) && std::isnan(none.accel_g[0]));
}

TEST(ProtocolRate, TheLongestLineWithEveryFieldFits) {
  RateSample s;
  s.seq = std::numeric_limits<std::uint64_t>::max();
  const double longest = -2.2250738585072014e-308;  // 24 characters in shortest form
  s.t_s = s.temp_c = longest;
  s.raw_dps = s.mean_dps = s.kalman_dps = s.rate_dps = s.bias_dps = s.accel_g = {longest, longest, longest};
  s.still = false;
  s.quat = {longest, longest, longest, longest};
  s.roll_pitch_heading_deg = {longest, longest, longest};
  s.inclination_std_deg = s.heading_std_deg = longest;
  for (const double time : {-999999999999999.9, 1e300, longest}) {  // fixed notation, then shortest
    s.time_s = time;
    std::array<char, kMaxRateLineBytes> buf;
    const std::size_t n = formatRateLine(s, buf);
    EXPECT_LT(n, kMaxRateLineBytes);
    const json j = parseLine(buf.data(), n);
    EXPECT_NEAR(j["time"].get<double>(), time, 1e-6 * std::fabs(time) + 1e-6);
    EXPECT_EQ(j["accel_ms2"].size(), 3u);
    for (std::size_t i = 0; i < 4; ++i) EXPECT_TRUE(sameDouble(j["quat"][i].get<double>(), longest));
    EXPECT_TRUE(sameDouble(j["heading_std"].get<double>(), longest));
  }
}

TEST(ProtocolRate, NonFiniteFieldsAreOmittedNotNull) {
  RateSample s;
  s.seq = 7;
  s.t_s = 1.5;
  s.temp_c = std::numeric_limits<double>::quiet_NaN();
  s.raw_dps = {1.0, std::numeric_limits<double>::infinity(), 2.0};
  s.mean_dps = {1.0, 2.0, 3.0};
  s.kalman_dps = {std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0};
  std::array<char, kMaxRateLineBytes> buf;
  const std::size_t n = formatRateLine(s, buf);
  const json j = parseLine(buf.data(), n);
  EXPECT_EQ(j, json::parse(R"({"class":"RATE","seq":7,"t":1.5,"mean":[1,2,3]})"));
  EXPECT_EQ(std::string(buf.data(), n).find("null"), std::string::npos);
}

TEST(ProtocolGap, FormatsAndRejectsMalformedGaps) {
  std::array<char, kMaxGapLineBytes> buf;
  const std::size_t n = formatGapLine(GapEvent{41, 3, "fifo_overflow"}, buf);
  EXPECT_EQ(std::string(buf.data(), n), "{\"class\":\"GAP\",\"seq\":41,\"count\":3,\"reason\":\"fifo_overflow\"}\n");
  const std::string longest_reason(kMaxGapReasonBytes, 'z');
  const std::size_t m = formatGapLine(
      GapEvent{std::numeric_limits<std::uint64_t>::max(), std::numeric_limits<std::uint64_t>::max(), longest_reason},
      buf);
  EXPECT_EQ(parseLine(buf.data(), m)["reason"], longest_reason);
  EXPECT_THROW(formatGapLine(GapEvent{1, 0, "bus_error"}, buf), std::invalid_argument);
  EXPECT_THROW(formatGapLine(GapEvent{1, 1, ""}, buf), std::invalid_argument);
  EXPECT_THROW(formatGapLine(GapEvent{1, 1, "has space"}, buf), std::invalid_argument);
  EXPECT_THROW(formatGapLine(GapEvent{1, 1, "quote\""}, buf), std::invalid_argument);
  EXPECT_THROW(formatGapLine(GapEvent{1, 1, longest_reason + "z"}, buf), std::invalid_argument);
}

TEST(ProtocolReplies, VersionAndWatch) {
  const std::string v = versionLine("1.2.3");
  ASSERT_EQ(v.back(), '\n');
  EXPECT_EQ(json::parse(v), json::parse(R"({"class":"VERSION","release":"1.2.3","proto_major":1,"proto_minor":9})"));
  EXPECT_EQ(json::parse(watchLine(false, 5)), json::parse(R"({"class":"WATCH","enable":false,"decimate":5})"));
}

TEST(ProtocolReplies, ErrorLineSurvivesNonUtf8Bytes) {
  const std::string e = errorLine(ErrorCode::UnknownCommand, std::string("bad \xff byte"));
  const json j = json::parse(e);
  EXPECT_EQ(j["class"], "ERROR");
  EXPECT_EQ(j["code"], "unknown_cmd");
}

TEST(ProtocolReplies, AllanKeepsOnlyTausWhereEveryCurveIsDefined) {
  AllanReport r;
  r.window_s = 600.0;
  r.samples = 30000;
  r.tau0_s = 0.02;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.tau_s = {0.02, 0.04, 0.08, 0.16};
  r.curves[0][0].adev_dps = {0.1, 0.07, 0.05, 0.04};
  r.curves[0][2].adev_dps = {0.01, 0.008, nan, 0.006};  // NaN at τ = 0.08 s
  r.curves[2][1].adev_dps = {0.2, 0.1, 0.05, 0.025};
  gyrod::processing::NoiseTerms terms;
  terms.quantization_urad = nan;
  terms.arw_deg_per_sqrt_h = 0.5;
  terms.bias_instability_deg_per_h = 12.0;
  terms.rrw_deg_per_h_sqrt_h = nan;
  terms.rate_ramp_deg_per_h2 = nan;
  r.curves[0][0].noise = terms;
  const json j = json::parse(allanLine(r));
  const json expected = json::parse(R"({
    "class":"ALLAN","samples":30000,"window":600.0,"tau0":0.02,"tau":[0.02,0.04,0.16],
    "adev":{"x":{"raw":[0.1,0.07,0.04],"kalman":[0.01,0.008,0.006]},"z":{"mean":[0.2,0.1,0.025]}},
    "noise":{"x":{"raw":{"arw_deg_per_sqrt_h":0.5,"bias_instability_deg_per_h":12.0}}}})");
  EXPECT_EQ(j, expected);

  r.curves[1][1].adev_dps = {1.0};
  EXPECT_THROW(allanLine(r), std::invalid_argument);
}

TEST(ProtocolReplies, StatusOmitsUnknownFieldsAndListsClients) {
  StatusReport d;
  d.uptime_s = 12.5;
  d.samples = 600;
  d.gaps = 1;
  d.missing_samples = 4;
  d.bus_errors = 2;
  d.resets = 1;
  d.device_state = "streaming";
  d.rate_hz = 49.98;
  d.temp_c = std::numeric_limits<double>::quiet_NaN();  // unknown: omitted
  ServerStatus s;
  s.clients = 1;
  s.clients_total = 3;
  s.clients_dropped = 1;
  s.lines_dropped = 17;
  s.client_buffer_bytes = 262144;
  ClientStatus c;
  c.id = 3;
  c.pid = 1234;
  c.watch = true;
  c.decimate = 5;
  c.lines_queued = 10;
  c.lines_sent = 9;
  c.buffered_bytes = 250;
  c.self = true;
  s.client_list.push_back(c);
  const json j = json::parse(statusLine(d, s));
  const json expected = json::parse(R"({
    "class":"STATUS","uptime":12.5,"samples":600,"gaps":1,"missing":4,"bus_errors":2,"resets":1,
    "device_state":"streaming","rate":49.98,"clients":1,"clients_total":3,"clients_dropped":1,
    "lines_dropped":17,"client_buffer":262144,
    "client_list":[{"id":3,"pid":1234,"watch":true,"decimate":5,"lines_queued":10,"lines_sent":9,
                    "buffered":250,"self":true}]})");
  EXPECT_EQ(j, expected);
}

// EFFECTS: the live check's current effects as their EFFECT objects, or "off" and why.
TEST(ProtocolReplies, EffectsListsTheCurrentEffectsOrSaysTheCheckIsOff) {
  LiveCheckStatus live{9, true, 3, 1, {R"({"class":"EFFECT","state":"new","effect":"line","axis":"y","t":4200.0})"}};
  const std::string on = effectsLine(effectsReportOf(live, "unused while it runs"));
  ASSERT_EQ(on.back(), '\n');
  EXPECT_EQ(json::parse(on), json::parse(R"({"class":"EFFECTS","live_check":"on","baseline_ready":true,"intervals":9,
    "effects":[{"class":"EFFECT","state":"new","effect":"line","axis":"y","t":4200.0}]})"));
  EXPECT_EQ(on.find(R"({"class":"EFFECTS","live_check":"on")"), 0u) << on;  // class first, as in every line
  live.current.clear();
  live.baseline_ready = false;
  EXPECT_EQ(json::parse(effectsLine(effectsReportOf(live, ""))),
            json::parse(R"({"class":"EFFECTS","live_check":"on","baseline_ready":false,"intervals":9,"effects":[]})"));
  EXPECT_EQ(json::parse(effectsLine(effectsReportOf(std::nullopt, "[check] enabled = false"))),
            json::parse(R"({"class":"EFFECTS","live_check":"off","reason":"[check] enabled = false","effects":[]})"));
  // A list entry that is not a JSON object is left out: the line stays valid JSON.
  EffectsReport odd;
  odd.live_check = true;
  odd.effects = {"not json", R"({"class":"EFFECT"})"};
  EXPECT_EQ(json::parse(effectsLine(odd))["effects"], json::parse(R"([{"class":"EFFECT"}])"));
}

TEST(ProtocolRequests, ValidRequests) {
  const Request w = parseRequest(R"({"cmd":"watch","enable":true})");
  ASSERT_TRUE(std::holds_alternative<WatchRequest>(w));
  EXPECT_TRUE(std::get<WatchRequest>(w).enable);
  EXPECT_EQ(std::get<WatchRequest>(w).decimate, 1u);
  const Request w2 = parseRequest(R"(  {"decimate":1000000,"cmd":"watch","enable":false} )");
  EXPECT_FALSE(std::get<WatchRequest>(w2).enable);
  EXPECT_EQ(std::get<WatchRequest>(w2).decimate, 1000000u);
  EXPECT_TRUE(std::get<WatchRequest>(parseRequest(R"({"cmd":"watch"})")).enable);  // documented default
  EXPECT_TRUE(std::holds_alternative<AllanRequest>(parseRequest(R"({"cmd":"allan"})")));
  EXPECT_TRUE(std::holds_alternative<StatusRequest>(parseRequest(R"({"cmd":"status"})")));
  EXPECT_TRUE(std::holds_alternative<EffectsRequest>(parseRequest(R"({"cmd":"effects"})")));
}

TEST(ProtocolRequests, EachProblemIsNamed) {
  struct Case {
    const char* line;
    ErrorCode code;
    const char* message_part;
  };
  const Case cases[] = {
      {"hello", ErrorCode::NotJson, "not valid JSON"},
      {R"({"cmd":"status")", ErrorCode::NotJson, "not valid JSON"},
      {R"(["status"])", ErrorCode::NotObject, "got array"},
      {R"("status")", ErrorCode::NotObject, "got string"},
      {R"({"command":"status"})", ErrorCode::MissingField, "no \"cmd\""},
      {R"({"cmd":7})", ErrorCode::BadType, "\"cmd\" must be a string, got number"},
      {R"({"cmd":"reboot"})", ErrorCode::UnknownCommand, "unknown cmd \"reboot\""},
      {R"({"cmd":"status","verbose":true})", ErrorCode::UnknownField, "\"status\" takes no field \"verbose\""},
      {R"({"cmd":"effects","axis":"y"})", ErrorCode::UnknownField, "\"effects\" takes no field \"axis\""},
      {R"({"cmd":"watch","enabel":true})", ErrorCode::UnknownField, "no field \"enabel\""},
      {R"({"cmd":"watch","enable":"yes"})", ErrorCode::BadType, "\"enable\" must be true or false, got string"},
      {R"({"cmd":"watch","enable":1})", ErrorCode::BadType, "\"enable\" must be true or false, got number"},
      {R"({"cmd":"watch","decimate":"3"})", ErrorCode::BadType, "\"decimate\" must be an integer, got string"},
      {R"({"cmd":"watch","decimate":2.5})", ErrorCode::BadType,
       "\"decimate\" must be an integer, got a fractional number"},
      {R"({"cmd":"watch","decimate":0})", ErrorCode::OutOfRange, "must be in 1..1000000, got 0"},
      {R"({"cmd":"watch","decimate":-4})", ErrorCode::OutOfRange, "got -4"},
      {R"({"cmd":"watch","decimate":1000001})", ErrorCode::OutOfRange, "got 1000001"},
      {R"({"cmd":"watch","decimate":99999999999999999999999})", ErrorCode::BadType, "must be an integer"},
  };
  for (const Case& c : cases) {
    try {
      parseRequest(c.line);
      ADD_FAILURE() << c.line << " was accepted";
    } catch (const ProtocolError& e) {
      EXPECT_EQ(e.code(), c.code) << c.line << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(c.message_part), std::string::npos) << c.line << ": " << e.what();
    }
  }
}

// A NUL ends the JSON parser's input: without the check, `{"cmd":"status"}\0garbage` would be
// a status request. Every control byte refuses the whole line; an escaped one in a string is
// quoted back escaped, never cut.
TEST(ProtocolRequests, ControlBytesRefuseTheWholeLine) {
  using namespace std::string_literals;
  const std::pair<std::string, std::string> cases[] = {
      {"{\"cmd\":\"status\"}\0garbage"s, "control byte 0x00 at byte 17"},
      {"{\"cmd\":\"watch\",\"enable\":false}\0{\"cmd\":\"watch\"}"s, "control byte 0x00 at byte 31"},
      {"{\"cmd\":\"status\x1b[2J\"}"s, "control byte 0x1B"},
      {"\x7f{\"cmd\":\"status\"}"s, "control byte 0x7F at byte 1"},
      {"{\"cmd\":\n\"allan\"}"s, "control byte 0x0A"},
  };
  for (const auto& [line, message_part] : cases) {
    try {
      parseRequest(line);
      ADD_FAILURE() << line << " was accepted";
    } catch (const ProtocolError& e) {
      EXPECT_EQ(e.code(), ErrorCode::BadRequest) << e.what();
      EXPECT_NE(std::string(e.what()).find(message_part), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(errorCodeName(ErrorCode::BadRequest), "bad_request");
  // Tab and carriage return are JSON whitespace.
  EXPECT_TRUE(std::holds_alternative<StatusRequest>(parseRequest("{\t\"cmd\":\"status\"}\r")));
  try {
    parseRequest(R"({"cmd":"bogus\u0000x"})");
    ADD_FAILURE() << "an escaped NUL in cmd was accepted";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.code(), ErrorCode::UnknownCommand);
    EXPECT_EQ(std::string(e.what()), R"(unknown cmd "bogus\u0000x" (known: watch, allan, status, effects))");
  }
}

TEST(ProtocolRate, RateBiasAndStillAreAppendedAndTheLongestLineFits) {
  RateSample s;
  s.seq = std::numeric_limits<std::uint64_t>::max();
  const double longest = -2.2250738585072014e-308;  // 24 characters in shortest form
  s.t_s = s.temp_c = longest;
  s.raw_dps = s.mean_dps = s.kalman_dps = s.rate_dps = s.bias_dps = {longest, longest, longest};
  s.still = false;
  std::array<char, kMaxRateLineBytes> buf;
  const std::size_t n = formatRateLine(s, buf);
  EXPECT_LT(n, kMaxRateLineBytes);
  const std::string line(buf.data(), n);
  // Appended after the paper's fields, which keep their places.
  EXPECT_LT(line.find("\"kalman\""), line.find("\"rate\"")) << line;
  EXPECT_LT(line.find("\"rate\""), line.find("\"bias\"")) << line;
  EXPECT_LT(line.find("\"bias\""), line.find("\"still\"")) << line;
  const json j = parseLine(buf.data(), n);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(sameDouble(j["rate"][i].get<double>(), longest));
    EXPECT_TRUE(sameDouble(j["bias"][i].get<double>(), longest));
  }
  EXPECT_EQ(j["still"], false);
  s.still = true;
  EXPECT_EQ(parseLine(buf.data(), formatRateLine(s, buf))["still"], true);
}

TEST(ProtocolRate, UnsetRateBiasAndStillAreOmitted) {
  RateSample s;
  s.seq = 3;
  s.t_s = 1.0;
  s.temp_c = 20.0;
  std::array<char, kMaxRateLineBytes> buf;
  const json j = parseLine(buf.data(), formatRateLine(s, buf));
  EXPECT_FALSE(j.contains("rate"));
  EXPECT_FALSE(j.contains("bias"));
  EXPECT_FALSE(j.contains("still"));
}

TEST(ProtocolRate, TheAttitudeComesLastAndRoundTrips) {
  RateSample s;
  s.seq = 12;
  s.t_s = 1.5;
  s.temp_c = 30.0;
  s.raw_dps = s.rate_dps = s.bias_dps = s.accel_g = {0.5, -0.25, 1.0};
  s.still = false;
  std::array<char, kMaxRateLineBytes> buf;
  // After every earlier field; parseServerLine gives the values back bit for bit; an unset
  // quaternion is omitted with its angles' fields left as they are.
  s.quat = {0.9238795325112867, 0.0, -0.3826834323650898, 1e-17};
  s.roll_pitch_heading_deg = {-0.0, -45.00000000000001, 179.99999999999997};
  s.inclination_std_deg = 0.123;
  s.heading_std_deg = 4.56;
  const std::string ordinary(buf.data(), formatRateLine(s, buf) - 1);
  EXPECT_LT(ordinary.find("\"accel_ms2\""), ordinary.find("\"quat\"")) << ordinary;
  EXPECT_LT(ordinary.find("\"quat\""), ordinary.find("\"roll\"")) << ordinary;
  EXPECT_LT(ordinary.find("\"heading\""), ordinary.find("\"inclination_std\"")) << ordinary;
  const auto back = std::get<RateSample>(parseServerLine(ordinary));
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(back.quat[i], s.quat[i]) << ordinary;
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_EQ(std::signbit(back.roll_pitch_heading_deg[i]), std::signbit(s.roll_pitch_heading_deg[i]));
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(back.roll_pitch_heading_deg[i], s.roll_pitch_heading_deg[i]);
  EXPECT_EQ(back.inclination_std_deg, 0.123);
  EXPECT_EQ(back.heading_std_deg, 4.56);
  s.quat[2] = std::numeric_limits<double>::quiet_NaN();
  const json without = parseLine(buf.data(), formatRateLine(s, buf));
  EXPECT_FALSE(without.contains("quat"));
  EXPECT_TRUE(without.contains("roll"));
}
