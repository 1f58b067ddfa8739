// The MQTT topics gyrod derives from its lines and state (daemon/mqtt_derived_topics.*): the
// 1 Hz summary's means, the retained allan and model topics and when they are sent, and Home
// Assistant's discovery configs.
#include "daemon/mqtt_derived_topics.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

using gyrod::daemon::MqttDerivedSources;
using gyrod::daemon::MqttDerivedTopics;
using gyrod::daemon::MqttMessage;
using nlohmann::json;

namespace {

gyrod::protocol::RateSample sample(std::uint64_t seq, double x, bool with_rate) {
  gyrod::protocol::RateSample s;
  s.seq = seq;
  s.temp_c = 30.0 + static_cast<double>(seq) * 0.01;
  s.raw_dps = {x + 1.0, -x, 2.0 * x};
  if (with_rate) {
    s.rate_dps = {x, -x, 2.0 * x};
    s.still = seq % 2 == 0;
  }
  return s;
}

const MqttMessage* find(const std::vector<MqttMessage>& messages, const std::string& topic) {
  for (const auto& m : messages)
    if (m.topic == topic) return &m;
  return nullptr;
}

struct Counters {
  std::uint64_t refits = 0;
  int allan_calls = 0;
  std::string model = R"({"rate_model":"bias"})";
};

MqttDerivedTopics derived(Counters& c, bool home_assistant, bool orientation = false) {
  MqttDerivedSources sources;
  sources.refit_cycles = [&c] { return c.refits; };
  sources.allan_json = [&c] {
    ++c.allan_calls;
    return R"({"class":"ALLAN","samples":)" + std::to_string(c.refits) + "}";
  };
  sources.model_json = [&c] { return c.model; };
  return MqttDerivedTopics({"gyrod/rig-1", "gyrod-rig.1", "mock MPU6050", home_assistant, "homeassistant", orientation},
                           std::move(sources));
}

}  // namespace

TEST(MqttDerivedTopics, TheSummaryIsTheMeanOfEachSecondOfRateThenRaw) {
  Counters c;
  MqttDerivedTopics d = derived(c, false);
  d.due(0.0, true);  // connected: the retained topics, no summary of an empty second
  for (std::uint64_t i = 1; i <= 4; ++i) d.take(sample(i, static_cast<double>(i), false));
  auto out = d.due(1.0, false);
  const MqttMessage* summary = find(out, "gyrod/rig-1/summary");
  ASSERT_NE(summary, nullptr);
  EXPECT_FALSE(summary->retain);
  json j = json::parse(summary->payload);
  EXPECT_EQ(j["raw"], json::array({3.5, -2.5, 5.0}));  // means of 2,3,4,5 / -1..-4 / 2,4,6,8
  EXPECT_EQ(j["samples"], 4);
  EXPECT_EQ(j["seq"], 4);
  EXPECT_DOUBLE_EQ(j["temp"].get<double>(), 30.04);
  EXPECT_FALSE(j.contains("rate"));
  EXPECT_TRUE(find(d.due(1.5, false), "gyrod/rig-1/summary") == nullptr);  // not yet a second

  d.take(sample(5, 1.0, false));
  d.take(sample(6, 2.0, true));  // the rate stream starts: the second restarts with it
  d.take(sample(7, 4.0, true));
  out = d.due(2.0, false);
  summary = find(out, "gyrod/rig-1/summary");
  ASSERT_NE(summary, nullptr);
  j = json::parse(summary->payload);
  EXPECT_EQ(j["rate"], json::array({3.0, -3.0, 6.0}));
  EXPECT_EQ(j["samples"], 2);
  EXPECT_EQ(j["still"], false);                                            // seq 7's
  EXPECT_FALSE(j.contains("heading"));                                     // no orientation sent
  EXPECT_TRUE(find(d.due(3.0, false), "gyrod/rig-1/summary") == nullptr);  // no samples that second
}

TEST(MqttDerivedTopics, TheSummaryCarriesTheNewestOrientationNotItsMean) {
  Counters c;
  MqttDerivedTopics d = derived(c, false, true);
  d.due(0.0, true);
  for (std::uint64_t i = 1; i <= 3; ++i) {
    gyrod::protocol::RateSample s = sample(i, 1.0, true);
    s.quat = {1.0, 0.0, 0.0, 0.0};
    s.roll_pitch_heading_deg = {0.5 * static_cast<double>(i), -1.0, i == 3 ? -179.0 : 179.0};  // across ±180°
    s.inclination_std_deg = 0.1;
    s.heading_std_deg = 0.25 * static_cast<double>(i);
    d.take(s);
  }
  const json j = json::parse(find(d.due(1.0, false), "gyrod/rig-1/summary")->payload);
  EXPECT_EQ(j["roll"], 1.5);
  EXPECT_EQ(j["pitch"], -1.0);
  EXPECT_EQ(j["heading"], -179.0);
  EXPECT_EQ(j["heading_std"], 0.75);
}

TEST(MqttDerivedTopics, AllanAndModelAreRetainedSentOnConnectAndOnChange) {
  Counters c;
  MqttDerivedTopics d = derived(c, false);
  auto out = d.due(0.0, true);
  ASSERT_NE(find(out, "gyrod/rig-1/allan"), nullptr);
  EXPECT_TRUE(find(out, "gyrod/rig-1/allan")->retain);
  EXPECT_EQ(find(out, "gyrod/rig-1/allan")->qos, 1);
  ASSERT_NE(find(out, "gyrod/rig-1/model"), nullptr);
  EXPECT_TRUE(find(out, "gyrod/rig-1/model")->retain);
  EXPECT_EQ(c.allan_calls, 1);

  out = d.due(1.0, false);  // nothing new: neither again
  EXPECT_EQ(find(out, "gyrod/rig-1/allan"), nullptr);
  EXPECT_EQ(find(out, "gyrod/rig-1/model"), nullptr);
  EXPECT_EQ(c.allan_calls, 1);  // the state is not read for nothing

  c.refits = 1;  // a refit completed
  out = d.due(2.0, false);
  ASSERT_NE(find(out, "gyrod/rig-1/allan"), nullptr);
  EXPECT_EQ(json::parse(find(out, "gyrod/rig-1/allan")->payload)["samples"], 1);

  c.model = R"({"rate_model":"model /etc/gyrod/m.toml"})";           // a reload changed it
  EXPECT_EQ(find(d.due(4.0, false), "gyrod/rig-1/model"), nullptr);  // checked every 5 s
  out = d.due(5.5, false);
  ASSERT_NE(find(out, "gyrod/rig-1/model"), nullptr);
  EXPECT_EQ(find(out, "gyrod/rig-1/model")->payload, c.model);

  out = d.due(6.0, true);  // a reconnection: both again, retained
  EXPECT_NE(find(out, "gyrod/rig-1/allan"), nullptr);
  EXPECT_NE(find(out, "gyrod/rig-1/model"), nullptr);
}

TEST(MqttDerivedTopics, HomeAssistantDiscoveryOnlyWhenAskedAndItsConfigsPointAtOurTopics) {
  Counters c;
  EXPECT_EQ(find(derived(c, false).due(0.0, true), "homeassistant/sensor/gyrod-rig_1/rate_x/config"), nullptr);
  MqttDerivedTopics d = derived(c, true);
  EXPECT_EQ(d.homeAssistantNodeId(), "gyrod-rig_1");
  const auto out = d.due(0.0, true);
  for (const char* object : {"rate_x", "rate_y", "rate_z", "temperature", "state"}) {
    const MqttMessage* m = find(out, std::string("homeassistant/sensor/gyrod-rig_1/") + object + "/config");
    ASSERT_NE(m, nullptr) << object;
    EXPECT_TRUE(m->retain);
    const json j = json::parse(m->payload);
    EXPECT_EQ(j["unique_id"], std::string("gyrod-rig_1_") + object);
    EXPECT_EQ(j["device"]["identifiers"], json::array({"gyrod-rig_1"}));
  }
  const json rate_y = json::parse(find(out, "homeassistant/sensor/gyrod-rig_1/rate_y/config")->payload);
  EXPECT_EQ(rate_y["state_topic"], "gyrod/rig-1/summary");
  EXPECT_NE(rate_y["value_template"].get<std::string>().find("[1]"), std::string::npos);
  EXPECT_EQ(rate_y["unit_of_measurement"], "°/s");
  EXPECT_EQ(rate_y["availability_topic"], "gyrod/rig-1/status");
  const json state = json::parse(find(out, "homeassistant/sensor/gyrod-rig_1/state/config")->payload);
  EXPECT_EQ(state["state_topic"], "gyrod/rig-1/status");
  EXPECT_FALSE(state.contains("availability_topic"));
  EXPECT_EQ(json::parse(find(out, "homeassistant/sensor/gyrod-rig_1/temperature/config")->payload)["device_class"],
            "temperature");
  // Roll, pitch and heading only from a gyrod that publishes the orientation.
  EXPECT_EQ(find(out, "homeassistant/sensor/gyrod-rig_1/heading/config"), nullptr);
  const auto oriented = derived(c, true, true).due(0.0, true);
  for (const char* angle : {"roll", "pitch", "heading"}) {
    const MqttMessage* m = find(oriented, std::string("homeassistant/sensor/gyrod-rig_1/") + angle + "/config");
    ASSERT_NE(m, nullptr) << angle;
    const json j = json::parse(m->payload);
    EXPECT_EQ(j["state_topic"], "gyrod/rig-1/summary");
    EXPECT_EQ(j["value_template"], std::string("{{ value_json.") + angle + " }}");
    EXPECT_EQ(j["unit_of_measurement"], "°");
  }
}

TEST(MqttDerivedTopics, ASourceWithNothingYetIsAskedAgainUntilItAnswers) {
  Counters c;
  bool ready = false;
  MqttDerivedSources sources;
  sources.refit_cycles = [] { return std::uint64_t{0}; };
  sources.allan_json = [&ready] { return ready ? std::string(R"({"class":"ALLAN"})") : std::string(); };
  sources.model_json = [&ready] { return ready ? std::string(R"({"rate_model":"bias"})") : std::string(); };
  MqttDerivedTopics d({"p", "id", "dev", false, "homeassistant"}, std::move(sources));
  auto out = d.due(0.0, true);  // connected while gyrod still starts
  EXPECT_EQ(find(out, "p/allan"), nullptr);
  EXPECT_EQ(find(out, "p/model"), nullptr);
  ready = true;
  out = d.due(0.1, false);
  EXPECT_NE(find(out, "p/allan"), nullptr);
  EXPECT_NE(find(out, "p/model"), nullptr);
  EXPECT_EQ(find(d.due(0.2, false), "p/allan"), nullptr);  // once
}
