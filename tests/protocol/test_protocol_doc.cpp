// docs/protocol.md lists names the code defines: the STATUS fields, the device states, the
// gap reasons and the driver counters. Each list is read from the page and compared with
// what the code sends, so neither can change without the other.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "driver/counter_names.hpp"
#include "driver/mpu6050_types.hpp"
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
  d.rate_model = "bias";
  d.recording = "file.csv";
  d.recorder = protocol::RecorderStatus{1, 2, 3, 4, "write to file.csv: No space left on device"};
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

TEST(ProtocolDoc, GapReasonsAreTheDriverCauses) {
  const auto documented = firstColumnNames(section(readDoc(), "#### Gap reasons"));
  const auto causes = enumNames<driver::GapCause>([](auto c) { return std::string(driver::gapCauseName(c)); });
  EXPECT_EQ(documented, causes);
}

TEST(ProtocolDoc, RateFieldsAreTheOnesSent) {
  protocol::RateSample s;
  s.raw_dps = s.mean_dps = s.kalman_dps = s.rate_dps = s.bias_dps = {1.0, 2.0, 3.0};
  s.still = true;
  s.time_s = 1.8e9;
  s.accel_g = {0.0, 0.0, 1.0};
  std::array<char, protocol::kMaxRateLineBytes> buf;
  const std::size_t n = protocol::formatRateLine(s, buf);
  std::set<std::string> sent;
  const nlohmann::json line = nlohmann::json::parse(std::string(buf.data(), n - 1));
  for (const auto& [key, value] : line.items()) sent.insert(key);
  EXPECT_EQ(firstColumnNames(section(readDoc(), "### RATE")), sent);
}
