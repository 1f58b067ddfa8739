// What the server formats, a client parses back to the same values (parseServerLine is the
// inverse of the formatters), and a line that breaks the protocol is refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "protocol/protocol.hpp"

using namespace gyrod::protocol;

namespace {

constexpr double kParsedNaN = std::numeric_limits<double>::quiet_NaN();

// Same bits: NaN equals NaN, and -0.0 differs from 0.0.
bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b)); }

template <class T>
T parsed(const std::string& line) {
  const std::string without_newline = line.substr(0, line.size() - (line.ends_with('\n') ? 1 : 0));
  const ServerMessage m = parseServerLine(without_newline);
  const T* value = std::get_if<T>(&m);
  if (value == nullptr) throw std::runtime_error("parsed to another class: " + line);
  return *value;
}

std::string rateLine(const RateSample& s) {
  std::array<char, kMaxRateLineBytes> buf;
  return std::string(buf.data(), formatRateLine(s, buf));
}

void expectSameRate(const RateSample& a, const RateSample& b) {
  EXPECT_EQ(a.seq, b.seq);
  EXPECT_TRUE(sameBits(a.t_s, b.t_s)) << a.t_s << " " << b.t_s;
  EXPECT_TRUE(sameBits(a.temp_c, b.temp_c));
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(sameBits(a.raw_dps[i], b.raw_dps[i]));
    EXPECT_TRUE(sameBits(a.mean_dps[i], b.mean_dps[i]));
    EXPECT_TRUE(sameBits(a.kalman_dps[i], b.kalman_dps[i]));
  }
}

}  // namespace

TEST(ParseServerLine, RateRoundTripsBitForBit) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> rate(0.0, 50.0);
  for (int trial = 0; trial < 500; ++trial) {
    RateSample s;
    s.seq = rng();
    s.t_s = 1e3 + trial * 0.02;
    s.temp_c = 25.0 + rate(rng) * 0.01;
    for (std::size_t i = 0; i < 3; ++i) {
      s.raw_dps[i] = rate(rng);
      s.mean_dps[i] = rate(rng);
      s.kalman_dps[i] = rate(rng);
    }
    s.raw_dps[trial % 3] = trial % 2 ? -0.0 : 0.0;
    expectSameRate(parsed<RateSample>(rateLine(s)), s);
  }
}

TEST(ParseServerLine, OmittedRateFieldsComeBackAsNaN) {
  RateSample s;
  s.seq = 12;
  s.t_s = kParsedNaN;  // omitted
  s.temp_c = 31.5;
  s.raw_dps = {1.0, 2.0, 3.0};
  s.mean_dps = {kParsedNaN, 0.0, 0.0};  // the whole array is omitted
  s.kalman_dps = {kParsedNaN, kParsedNaN, kParsedNaN};
  const RateSample back = parsed<RateSample>(rateLine(s));
  EXPECT_TRUE(std::isnan(back.t_s));
  EXPECT_EQ(back.temp_c, 31.5);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.raw_dps[i], s.raw_dps[i]);
    EXPECT_TRUE(std::isnan(back.mean_dps[i]));
    EXPECT_TRUE(std::isnan(back.kalman_dps[i]));
  }
}

TEST(ParseServerLine, GapRoundTrips) {
  std::array<char, kMaxGapLineBytes> buf;
  const GapEvent gap{1002, 7, "fifo_overflow"};
  const GapNotice back = parsed<GapNotice>(std::string(buf.data(), formatGapLine(gap, buf)));
  EXPECT_EQ(back.first_missing_seq, 1002u);
  EXPECT_EQ(back.count, 7u);
  EXPECT_EQ(back.reason, "fifo_overflow");
}

TEST(ParseServerLine, VersionWatchAndErrorRoundTrip) {
  const VersionReply v = parsed<VersionReply>(versionLine("1.2.3"));
  EXPECT_EQ(v.release, "1.2.3");
  EXPECT_EQ(v.proto_major, kProtocolMajor);
  EXPECT_EQ(v.proto_minor, kProtocolMinor);
  const WatchReply w = parsed<WatchReply>(watchLine(true, 50));
  EXPECT_TRUE(w.enable);
  EXPECT_EQ(w.decimate, 50u);
  const ErrorReply e = parsed<ErrorReply>(errorLine(ErrorCode::OutOfRange, "decimate 0"));
  EXPECT_EQ(e.code, "out_of_range");
  EXPECT_EQ(e.message, "decimate 0");
}

TEST(ParseServerLine, AllanRoundTripsCurvesAndNoiseTerms) {
  AllanReport a;
  a.window_s = 600.0;
  a.samples = 30000;
  a.tau0_s = 0.02;
  a.tau_s = {0.02, 0.2, 2.0};
  for (std::size_t axis = 0; axis < 3; ++axis)
    for (const double tau : a.tau_s) {
      a.curves[axis][0].adev_dps.push_back(0.01 * (axis + 1) / std::sqrt(tau / 0.02));
      a.curves[axis][2].adev_dps.push_back(0.001 * (axis + 1) / std::sqrt(tau / 0.02));
    }
  gyrod::processing::NoiseTerms t;
  t.quantization_urad = kParsedNaN;
  t.arw_deg_per_sqrt_h = 0.42;
  t.bias_instability_deg_per_h = 1.5;
  t.rrw_deg_per_h_sqrt_h = kParsedNaN;
  t.rate_ramp_deg_per_h2 = kParsedNaN;
  a.curves[1][2].noise = t;

  const AllanReport back = parsed<AllanReport>(allanLine(a));
  EXPECT_EQ(back.samples, a.samples);
  EXPECT_EQ(back.window_s, a.window_s);
  EXPECT_EQ(back.tau0_s, a.tau0_s);
  EXPECT_EQ(back.tau_s, a.tau_s);
  for (std::size_t axis = 0; axis < 3; ++axis)
    for (std::size_t stream = 0; stream < 3; ++stream) {
      EXPECT_EQ(back.curves[axis][stream].adev_dps, a.curves[axis][stream].adev_dps) << axis << stream;
      ASSERT_EQ(back.curves[axis][stream].noise.has_value(), a.curves[axis][stream].noise.has_value());
    }
  for (const auto term : gyrod::processing::kAllNoiseTerms)
    EXPECT_TRUE(sameBits(back.curves[1][2].noise->get(term), t.get(term)));
  // Re-formatting what was parsed gives the very same line.
  EXPECT_EQ(allanLine(back), allanLine(a));
}

TEST(ParseServerLine, StatusRoundTripsEveryField) {
  StatusReport d;
  d.uptime_s = 12.5;
  d.samples = 625;
  d.gaps = 2;
  d.missing_samples = 9;
  d.bus_errors = 3;
  d.resets = 1;
  d.device_state = "recovering";
  d.device_reason = "the chip stopped answering";
  d.device_retrying = true;
  d.device_counters = {{"transfers_failed", 3}, {"retries", 2}, {"fifo_overflows", 1}};
  d.device = "/dev/i2c-1@0x68";
  d.rate_hz = 49.97;
  d.nominal_rate_hz = 50.0;
  d.temp_c = 31.25;
  d.bias_source = "config [0, 0, 0] deg/s";
  d.recording = "/var/lib/gyrod/gyro.csv";
  d.mqtt = MqttStatus{true, 12, 3, "TLS handshake failed: certificate verify failed"};
  d.calibration_state = CalibrationStateStatus{"/var/lib/gyrod/calibration.toml", true, 7, ""};
  // The current effects travel as their EFFECT objects (compact JSON, keys sorted).
  d.live_check = LiveCheckStatus{12, true, 2, 1, {R"({"axis":"y","class":"EFFECT","effect":"line","state":"new"})"}};
  ServerStatus s;
  s.clients = 2;
  s.clients_total = 5;
  s.clients_dropped = 1;
  s.lines_dropped = 40;
  s.client_buffer_bytes = 262144;
  s.client_list = {{1, 4242, 1000, true, 5, 100, 98, 300, false},
                   {2, std::nullopt, std::nullopt, false, 1, 1, 1, 0, true}};

  const std::string line = statusLine(d, s);
  const StatusReply back = parsed<StatusReply>(line);
  EXPECT_TRUE(back.other_fields.empty());
  EXPECT_EQ(back.daemon.device_counters, d.device_counters);  // in the order sent
  EXPECT_EQ(back.daemon.device_reason, d.device_reason);
  EXPECT_EQ(back.daemon.device_retrying, d.device_retrying);
  EXPECT_EQ(back.daemon.rate_hz, d.rate_hz);
  EXPECT_EQ(back.daemon.mqtt, d.mqtt);
  EXPECT_EQ(back.daemon.calibration_state, d.calibration_state);
  EXPECT_EQ(back.daemon.live_check, d.live_check);
  EXPECT_EQ(back.server.client_list.size(), 2u);
  EXPECT_EQ(back.server.client_list[0].pid, 4242);
  EXPECT_FALSE(back.server.client_list[1].pid.has_value());
  EXPECT_TRUE(back.server.client_list[1].self);
  // Formatting what was parsed gives the very same line: no field is lost or changed.
  EXPECT_EQ(statusLine(back.daemon, back.server), line);
}

TEST(ParseServerLine, StatusKeepsFieldsOfANewerGyrodAndOmitsAbsentOnes) {
  const StatusReply r = parsed<StatusReply>(
      R"({"class":"STATUS","samples":1,"gaps":0,"missing":0,"bus_errors":0,"resets":0,"device_state":"streaming",)"
      R"("clients":1,"clients_total":1,"clients_dropped":0,"lines_dropped":0,"client_buffer":1024,)"
      R"("client_list":[],"zeta":"new","alpha":0.25,"count":3})");
  EXPECT_TRUE(std::isnan(r.daemon.uptime_s));
  EXPECT_FALSE(r.daemon.device.has_value());
  EXPECT_FALSE(r.daemon.device_retrying.has_value());
  EXPECT_TRUE(r.daemon.device_reason.empty());
  ASSERT_EQ(r.other_fields.size(), 3u);
  EXPECT_EQ(r.other_fields[0].key, "zeta");  // in line order
  EXPECT_EQ(r.other_fields[0].text, "new");
  EXPECT_EQ(r.other_fields[1].real, 0.25);
  EXPECT_EQ(r.other_fields[2].json, "3");
}

TEST(ParseServerLine, UnknownClassesAreNamedNotRefused) {
  const ServerMessage m = parseServerLine(R"({"class":"SKY","sats":3})");
  ASSERT_TRUE(std::holds_alternative<OtherClass>(m));
  EXPECT_EQ(std::get<OtherClass>(m).name, "SKY");
}

TEST(ParseServerLine, LinesThatBreakTheProtocolAreRefused) {
  for (const char* bad :
       {"", "not json", "[1,2]", R"({"seq":1})", R"({"class":3})", R"({"class":"RATE"})",
        R"({"class":"RATE","seq":-1})", R"({"class":"RATE","seq":1,"raw":[1,2]})",
        R"({"class":"RATE","seq":1,"t":"soon"})", R"({"class":"GAP","seq":1,"count":2})",
        R"({"class":"ALLAN","samples":3,"tau":[1,2],"adev":{"x":{"raw":[1]}}})", R"({"class":"EFFECTS","effects":[]})",
        R"({"class":"EFFECTS","live_check":true})", R"({"class":"EFFECTS","live_check":"on","effects":[3]})",
        R"({"class":"EFFECTS","live_check":"on","intervals":-1})"}) {
    EXPECT_THROW(parseServerLine(bad), MalformedLine) << bad;
  }
}

TEST(RequestLine, ParsesBackToTheSameRequest) {
  const Request watch = parseRequest(requestLine(WatchRequest{false, 25}));
  ASSERT_TRUE(std::holds_alternative<WatchRequest>(watch));
  EXPECT_FALSE(std::get<WatchRequest>(watch).enable);
  EXPECT_EQ(std::get<WatchRequest>(watch).decimate, 25u);
  EXPECT_TRUE(std::holds_alternative<AllanRequest>(parseRequest(requestLine(AllanRequest{}))));
  EXPECT_TRUE(std::holds_alternative<StatusRequest>(parseRequest(requestLine(StatusRequest{}))));
  EXPECT_TRUE(std::holds_alternative<EffectsRequest>(parseRequest(requestLine(EffectsRequest{}))));
}

TEST(ParseServerLine, EffectsRoundTripsOnAndOff) {
  EffectsReport on;
  on.live_check = true;
  on.baseline_ready = true;
  on.intervals = 14;
  on.effects = {R"({"class":"EFFECT","state":"new","effect":"line","axis":"y","params":{"centre_hz":12.5}})",
                R"({"class":"EFFECT","state":"new","effect":"some_later_kind","axis":"x","params":{}})"};
  EXPECT_EQ(parsed<EffectsReport>(effectsLine(on)), on);
  EffectsReport off;
  off.reason = "it runs on still samples, and the still detector needs filter.model";
  EXPECT_EQ(parsed<EffectsReport>(effectsLine(off)), off);
  // Fields of a later minor version are ignored.
  EXPECT_EQ(
      parsed<EffectsReport>(R"({"class":"EFFECTS","live_check":"on","intervals":2,"effects":[],"next":1})").intervals,
      2u);
}

TEST(ParseServerLine, RateBiasAndStillRoundTripBitForBit) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> rate(0.0, 50.0);
  for (int trial = 0; trial < 200; ++trial) {
    RateSample s;
    s.seq = rng();
    s.t_s = 1e3 + trial * 0.02;
    s.temp_c = 25.0;
    for (std::size_t i = 0; i < 3; ++i) {
      s.raw_dps[i] = rate(rng);
      s.mean_dps[i] = rate(rng);
      s.kalman_dps[i] = rate(rng);
      s.rate_dps[i] = rate(rng);
      s.bias_dps[i] = rate(rng) * 1e-3;
    }
    s.still = trial % 2 == 0;
    const RateSample back = parsed<RateSample>(rateLine(s));
    expectSameRate(s, back);
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_TRUE(sameBits(s.rate_dps[i], back.rate_dps[i]));
      EXPECT_TRUE(sameBits(s.bias_dps[i], back.bias_dps[i]));
    }
    EXPECT_EQ(back.still, s.still);
  }
  // An older gyrod's line: no rate, bias or still.
  const RateSample old = parsed<RateSample>(R"({"class":"RATE","seq":1,"t":2,"raw":[1,2,3]})");
  EXPECT_TRUE(std::isnan(old.rate_dps[0]) && std::isnan(old.bias_dps[2]));
  EXPECT_FALSE(old.still.has_value());
  EXPECT_THROW(parseServerLine(R"({"class":"RATE","seq":1,"still":1})"), MalformedLine);
}

TEST(ParseServerLine, StatusRecorderRoundTrips) {
  StatusReport d;
  d.device_state = "streaming";
  d.recorder = RecorderStatus{10, 2, 300, 4, "write to a.csv: No space left on device"};
  const auto reply = std::get<StatusReply>(parseServerLine(statusLine(d, {})));
  EXPECT_EQ(reply.daemon.recorder, d.recorder);
  EXPECT_TRUE(reply.other_fields.empty());
  d.recorder->last_error.clear();  // omitted, read back empty
  EXPECT_EQ(std::get<StatusReply>(parseServerLine(statusLine(d, {}))).daemon.recorder, d.recorder);
  d.recorder.reset();
  EXPECT_FALSE(std::get<StatusReply>(parseServerLine(statusLine(d, {}))).daemon.recorder);
}
