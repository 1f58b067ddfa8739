// docs/protocol.md lists names the code defines: the STATUS fields, the device states, the
// gap reasons, the driver counters, the still checks, the ALLAN and Allan-table fields, the
// EFFECTS fields, the requests and the MQTT topics. Each list is read from the page and compared
// with what the code sends or takes, so neither can change without the other.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "driver/counter_names.hpp"
#include "driver/mpu6050_types.hpp"
#include "protocol/allan_table.hpp"
#include "protocol/protocol.hpp"

using namespace gyrod;

namespace {

std::string readDoc() {
  std::ifstream in(std::string(GYROD_DOCS_DIR) + "/protocol.md");
  EXPECT_TRUE(in) << "cannot read docs/protocol.md";
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The text from the heading line `heading` to the next heading of the same or a higher level.
std::string section(const std::string& doc, const std::string& heading) {
  const std::size_t start = doc.find("\n" + heading);
  if (start == std::string::npos) {
    ADD_FAILURE() << "docs/protocol.md has no heading '" << heading << "'";
    return {};
  }
  const std::size_t level = heading.find_first_not_of('#');
  std::size_t end = start + 1;
  while ((end = doc.find("\n#", end + 1)) != std::string::npos) {
    const std::size_t hashes = doc.find_first_not_of('#', end + 1) - (end + 1);
    if (hashes <= level) break;
  }
  return doc.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

// The `code` names in the first column of the tables of `text` (header rows have none).
std::set<std::string> firstColumnNames(const std::string& text) {
  std::set<std::string> names;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("| `", 0) != 0) continue;
    const std::size_t close = line.find('`', 3);
    names.insert(line.substr(3, close - 3));
  }
  return names;
}

// Every `code` name in the first cell of each table row of `text` ("| `a`, `b` | ..." gives both).
std::set<std::string> firstCellNames(const std::string& text) {
  std::set<std::string> names;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("| `", 0) != 0) continue;
    const std::string cell = line.substr(1, line.find('|', 1) - 1);
    for (std::size_t open = cell.find('`'); open != std::string::npos; open = cell.find('`', open)) {
      const std::size_t close = cell.find('`', open + 1);
      names.insert(cell.substr(open + 1, close - open - 1));
      open = close + 1;
    }
  }
  return names;
}

// The names of enum values 0..255 that `name_of` knows (it says "unknown" for the others).
template <class Enum, class NameOf>
std::set<std::string> enumNames(NameOf name_of) {
  std::set<std::string> names;
  for (int v = 0; v < 256; ++v) {
    const std::string name = name_of(static_cast<Enum>(v));
    if (name != "unknown") names.insert(name);
  }
  return names;
}

// A STATUS line with every optional field present, as gyrod fills it.
nlohmann::json fullStatus() {
  protocol::StatusReport d;
  d.uptime_s = 1.0;
  d.device_state = "streaming";
  d.device_reason = "why";
  d.device_retrying = true;
  for (const auto& c : driver::kDriverCounterNames) d.device_counters.push_back({std::string(c.name), 1});
  d.device = "/dev/i2c-1@0x68";
  d.rate_hz = d.nominal_rate_hz = 50.0;
  d.temp_c = 30.0;
  d.bias_source = "config";
  d.still_check = "still";
  d.still_check_detail = "window 1 of at most 3: ...";
  d.rate_model = "bias";
  d.recording = "file.csv";
  d.recorder = protocol::RecorderStatus{1, 2, 3, 4, "write to file.csv: No space left on device"};
  d.mqtt = protocol::MqttStatus{false, 5, 6, "Connection refused"};
  d.calibration_state = protocol::CalibrationStateStatus{"/var/lib/gyrod/calibration.toml", true, 3, "disk full"};
  d.live_check = protocol::LiveCheckStatus{7, true, 1, 0, {R"({"class":"EFFECT","state":"new"})"}};
  protocol::ServerStatus s;
  s.client_list.push_back({1, 2, 3, true, 1, 1, 1, 1, true});
  return nlohmann::json::parse(protocol::statusLine(d, s));
}

}  // namespace

TEST(ProtocolDoc, StatusFieldsAreTheOnesSent) {
  const nlohmann::json status = fullStatus();
  std::set<std::string> sent;
  for (const auto& [key, value] : status.items()) {
    sent.insert(key);
    if (key == "client_list")
      for (const auto& [client_key, v] : value[0].items()) sent.insert("client_list[]." + client_key);
    if (key == "recorder")
      for (const auto& [recorder_key, v] : value.items()) sent.insert("recorder." + recorder_key);
  }
  std::set<std::string> documented = firstColumnNames(section(readDoc(), "### STATUS"));
  std::erase_if(documented, [](const std::string& n) { return n.starts_with("counters."); });  // below
  // The state names of the device-state table sit in the same section.
  for (const auto& state : firstColumnNames(section(readDoc(), "#### Device states"))) documented.erase(state);
  for (const auto& check : firstColumnNames(section(readDoc(), "#### Still checks"))) documented.erase(check);
  EXPECT_EQ(documented, sent);
}

TEST(ProtocolDoc, DriverCountersAreTheOnesSent) {
  std::set<std::string> documented;
  for (const auto& name : firstColumnNames(section(readDoc(), "#### Driver counters")))
    documented.insert(name.substr(std::string("counters.").size()));
  const nlohmann::json status = fullStatus();
  std::set<std::string> sent;
  for (const auto& [key, value] : status["counters"].items()) sent.insert(key);
  std::set<std::string> in_driver;
  for (const auto& c : driver::kDriverCounterNames) in_driver.insert(std::string(c.name));
  EXPECT_EQ(sent, in_driver);
  EXPECT_EQ(documented, in_driver);
}

TEST(ProtocolDoc, DeviceStatesAreTheDriverStates) {
  const auto documented = firstColumnNames(section(readDoc(), "#### Device states"));
  EXPECT_EQ(documented, enumNames<driver::DeviceState>([](auto s) { return driver::deviceStateName(s); }));
}

TEST(ProtocolDoc, GapReasonsAreTheDriverCausesAndTheDaemons) {
  const auto documented = firstColumnNames(section(readDoc(), "#### Gap reasons"));
  auto causes = enumNames<driver::GapCause>([](auto c) { return std::string(driver::gapCauseName(c)); });
  causes.insert(std::string(protocol::kDeliveryBehindGapReason));
  EXPECT_EQ(documented, causes);
}

TEST(ProtocolDoc, RateFieldsAreTheOnesSent) {
  protocol::RateSample s;
  s.raw_dps = s.mean_dps = s.kalman_dps = s.rate_dps = s.bias_dps = {1.0, 2.0, 3.0};
  s.still = true;
  s.time_s = 1.8e9;
  s.accel_g = {0.0, 0.0, 1.0};
  s.quat = {1.0, 0.0, 0.0, 0.0};
  s.roll_pitch_heading_deg = {1.0, 2.0, 3.0};
  s.inclination_std_deg = 0.1;
  s.heading_std_deg = 0.2;
  std::array<char, protocol::kMaxRateLineBytes> buf;
  const std::size_t n = protocol::formatRateLine(s, buf);
  std::set<std::string> sent;
  const nlohmann::json line = nlohmann::json::parse(std::string(buf.data(), n - 1));
  for (const auto& [key, value] : line.items()) sent.insert(key);
  EXPECT_EQ(firstColumnNames(section(readDoc(), "### RATE")), sent);
}

TEST(ProtocolDoc, StillChecksAreTheOnesTheCodeNames) {
  const auto documented = firstColumnNames(section(readDoc(), "#### Still checks"));
  EXPECT_EQ(documented,
            enumNames<protocol::StillCheck>([](auto c) { return std::string(protocol::stillCheckName(c)); }));
  EXPECT_EQ(documented.size(), 4u);
}

namespace {

// An ALLAN line with every field present: a table point with an interval and the
// non-overlapping estimator (analyze's), and every noise term with its uncertainty.
protocol::AllanReport fullAllan() {
  protocol::AllanReport r;
  r.window_s = 600.0;
  r.span_s = 100.0;
  r.samples = 5000;
  r.tau0_s = 0.02;
  r.confidence = 0.683;
  r.tau_s = {0.02};
  processing::AllanPoint p{0.02, 1, 0.1, 4998, 0.1, 4998, 0, 3000.0, 0.099, 0.101};
  processing::NoiseTerms terms{1.0, 2.0, 3.0, 4.0, 5.0};
  for (auto& axis : r.curves)
    for (auto& curve : axis) {
      curve.adev_dps = {0.1};
      curve.points = {p};
      curve.noise = terms;
      curve.noise_uncertainty = terms;
    }
  return r;
}

}  // namespace

TEST(ProtocolDoc, AllanFieldsAreTheOnesSent) {
  const auto line = nlohmann::json::parse(protocol::allanLine(fullAllan()));
  std::set<std::string> sent;
  for (const auto& [key, value] : line.items()) sent.insert(key);
  const std::string doc = readDoc();
  // The reply's own fields: the tables of the section before its "Allan tables" subsection,
  // less the noise-term table (checked below).
  std::string reply = section(doc, "### ALLAN");
  reply = reply.substr(0, reply.find("\n#### "));
  std::set<std::string> documented = firstCellNames(reply);
  const auto table_fields = firstCellNames(section(doc, "#### Allan tables"));
  std::set<std::string> term_keys;
  for (const auto t : processing::kAllNoiseTerms) term_keys.insert(std::string(processing::noiseTermKey(t)));
  for (const auto& n : term_keys) documented.erase(n);
  EXPECT_EQ(documented, sent);

  // The noise-term table lists exactly the keys sent under noise and noise_uncertainty.
  std::set<std::string> noise_keys, uncertainty_keys;
  for (const auto& [key, v] : line["noise"]["x"]["raw"].items()) noise_keys.insert(key);
  for (const auto& [key, v] : line["noise_uncertainty"]["x"]["raw"].items()) uncertainty_keys.insert(key);
  EXPECT_EQ(noise_keys, term_keys);
  EXPECT_EQ(uncertainty_keys, term_keys);

  // The Allan-table fields are those of a full point, live (the reply) and offline alike.
  std::set<std::string> point_keys;
  for (const auto& [key, v] : line["table"]["z"]["kalman"][0].items()) point_keys.insert(key);
  EXPECT_EQ(table_fields, point_keys);
}

TEST(ProtocolDoc, MqttTopicsAreTheOnesPublished) {
  const auto documented = firstColumnNames(section(readDoc(), "#### MQTT topics"));
  const std::set<std::string> published = {
      std::string(protocol::kMqttStatusTopic), std::string(protocol::kMqttRateTopic),
      std::string(protocol::kMqttGapTopic),    std::string(protocol::kMqttSummaryTopic),
      std::string(protocol::kMqttAllanTopic),  std::string(protocol::kMqttModelTopic),
      std::string(protocol::kMqttEffectTopic)};
  EXPECT_EQ(documented, published);
}

TEST(ProtocolDoc, EffectsFieldsAreTheOnesSent) {
  protocol::LiveCheckStatus live{3, true, 1, 0, {R"({"class":"EFFECT","state":"new"})"}};
  std::set<std::string> sent;
  for (const auto& line : {protocol::effectsLine(protocol::effectsReportOf(live, "")),
                           protocol::effectsLine(protocol::effectsReportOf(std::nullopt, "why"))}) {
    const nlohmann::json reply = nlohmann::json::parse(line);
    for (const auto& [key, value] : reply.items()) sent.insert(key);
  }
  EXPECT_EQ(firstColumnNames(section(readDoc(), "### EFFECTS")), sent);
}

// The request table names every command the parser takes (its unknown_cmd message lists them)
// and the ERROR table's unknown_cmd row names them too.
TEST(ProtocolDoc, RequestsAreTheOnesTheServerTakes) {
  std::string known;
  try {
    protocol::parseRequest(R"({"cmd":"zz_no_such_command"})");
  } catch (const protocol::ProtocolError& e) {
    known = e.what();
  }
  const std::size_t open = known.find("(known: ");
  ASSERT_NE(open, std::string::npos) << known;
  std::set<std::string> taken;
  std::istringstream list(known.substr(open + 8, known.rfind(')') - open - 8));
  for (std::string name; std::getline(list, name, ',');) taken.insert(name.substr(name.find_first_not_of(' ')));
  std::set<std::string> documented;
  const std::string requests = section(readDoc(), "## Client → server");
  std::istringstream lines(requests);
  for (std::string line; std::getline(lines, line);) {
    const std::string marker = R"(| `{"cmd":")";
    if (line.rfind(marker, 0) != 0) continue;
    documented.insert(line.substr(marker.size(), line.find('"', marker.size()) - marker.size()));
  }
  EXPECT_EQ(documented, taken);
  std::string unknown_cmd_row;
  std::istringstream errors(section(readDoc(), "### ERROR"));
  for (std::string line; std::getline(errors, line);)
    if (line.rfind("| `unknown_cmd`", 0) == 0) unknown_cmd_row = line;
  for (const auto& name : taken) EXPECT_NE(unknown_cmd_row.find("`" + name + "`"), std::string::npos) << name;
}
