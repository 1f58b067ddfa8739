#pragma once
// What gyrod publishes on its broker beside the lines themselves (docs/protocol.md "MQTT"):
//  - <prefix>/summary, once a second: the mean rate over the second, the newest temperature and
//    still verdict, and the newest orientation when RATE has one — what a dashboard plots,
//    without taking every sample;
//  - <prefix>/allan, retained: the ALLAN reply (rolling deviations and noise terms), at connect
//    and after each noise refit;
//  - <prefix>/model, retained: the calibration the rate stream uses, at connect and on change;
//  - with home_assistant, Home Assistant's MQTT discovery (retained configs under
//    <discovery prefix>/sensor/<node>/...): rates x, y, z, temperature (and with the orientation
//    roll, pitch, heading) from the summary, the state from the status.
// Pure apart from the sources it is handed (which take gyrod's state lock): lines in, messages
// out; the publisher's thread sends them.
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "protocol/protocol.hpp"

namespace gyrod::daemon {

struct MqttDerivedSources {
  std::function<std::uint64_t()> refit_cycles;  // changes after each completed noise refit
  std::function<std::string()> allan_json;      // the ALLAN reply, one JSON object
  std::function<std::string()> model_json;      // the calibration in use, one JSON object
};

struct MqttDerivedSettings {
  std::string prefix;     // gyrod's topics: prefix/summary, prefix/allan, prefix/model
  std::string client_id;  // Home Assistant's node id and unique ids are made from it
  std::string device;     // the device's description, for Home Assistant's device entry
  bool home_assistant = false;
  std::string home_assistant_prefix = "homeassistant";
  bool orientation = false;  // RATE carries the orientation (a sensor model and the accel): its sensors too
};

struct MqttMessage {
  std::string topic;
  std::string payload;
  int qos = 0;
  bool retain = false;
};

class MqttDerivedTopics {
 public:
  MqttDerivedTopics(MqttDerivedSettings settings, MqttDerivedSources sources);

  // Every RATE line (before any rate_every decimation).
  void take(const protocol::RateSample& sample);
  // What is due now (`now_s` on any monotonic clock): after a (re)connection, the retained
  // topics and the discovery configs; then the summary each second, the Allan reply after a
  // refit, the model when it changed (checked every 5 s).
  std::vector<MqttMessage> due(double now_s, bool just_connected);

  std::string homeAssistantNodeId() const;

 private:
  void addSummary(std::vector<MqttMessage>& out);
  void addHomeAssistantConfigs(std::vector<MqttMessage>& out) const;

  MqttDerivedSettings settings_;
  MqttDerivedSources sources_;
  std::string summary_topic_, allan_topic_, model_topic_;
  // The second being summed.
  std::uint64_t count_ = 0, last_seq_ = 0;
  double sum_[3] = {0.0, 0.0, 0.0};
  bool sum_is_rate_ = false;
  double temp_c_ = 0.0;
  std::optional<bool> still_;
  // The newest roll, pitch, heading and heading 1σ [°] of the second (angles are not averaged:
  // a heading crossing ±180° would average to nonsense); none while RATE carries none.
  std::optional<std::array<double, 4>> orientation_;
  double next_summary_s_ = 0.0, next_model_check_s_ = 0.0;
  std::uint64_t allan_cycles_sent_ = 0;
  bool allan_pending_ = false, model_pending_ = false;  // to send once their source has them
  std::string model_sent_;
};

}  // namespace gyrod::daemon
