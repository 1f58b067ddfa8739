#include "daemon/mqtt_derived_topics.hpp"

#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>

namespace gyrod::daemon {
namespace {

using Json = nlohmann::json;

constexpr double kSummaryEvery = 1.0;     // s
constexpr double kModelCheckEvery = 5.0;  // s, as the status

}  // namespace

MqttDerivedTopics::MqttDerivedTopics(MqttDerivedSettings settings, MqttDerivedSources sources)
    : settings_(std::move(settings)),
      sources_(std::move(sources)),
      summary_topic_(settings_.prefix + "/" + std::string(protocol::kMqttSummaryTopic)),
      allan_topic_(settings_.prefix + "/" + std::string(protocol::kMqttAllanTopic)),
      model_topic_(settings_.prefix + "/" + std::string(protocol::kMqttModelTopic)) {}

void MqttDerivedTopics::take(const protocol::RateSample& sample) {
  // The rate stream once gyrod has it; the raw rate until then (a second of either, not mixed).
  const bool is_rate = std::isfinite(sample.rate_dps[0]);
  if (count_ > 0 && is_rate != sum_is_rate_) count_ = 0;
  if (count_ == 0) sum_[0] = sum_[1] = sum_[2] = 0.0;
  sum_is_rate_ = is_rate;
  const auto& v = is_rate ? sample.rate_dps : sample.raw_dps;
  for (int a = 0; a < 3; ++a) sum_[a] += v[a];
  ++count_;
  last_seq_ = sample.seq;
  temp_c_ = sample.temp_c;
  still_ = sample.still;
  const auto& e = sample.roll_pitch_heading_deg;
  if (std::isfinite(e[0]) && std::isfinite(e[1]) && std::isfinite(e[2]))
    orientation_ = std::array<double, 4>{e[0], e[1], e[2], sample.heading_std_deg};
  else
    orientation_.reset();
}

void MqttDerivedTopics::addSummary(std::vector<MqttMessage>& out) {
  if (count_ == 0) return;
  const auto n = static_cast<double>(count_);
  Json j = {{"seq", last_seq_}, {"samples", count_}, {"temp", temp_c_}};
  j[sum_is_rate_ ? "rate" : "raw"] = {sum_[0] / n, sum_[1] / n, sum_[2] / n};
  if (still_) j["still"] = *still_;
  if (orientation_) {
    j["roll"] = (*orientation_)[0];
    j["pitch"] = (*orientation_)[1];
    j["heading"] = (*orientation_)[2];
    if (std::isfinite((*orientation_)[3])) j["heading_std"] = (*orientation_)[3];
  }
  out.push_back({summary_topic_, j.dump(), 0, false});
  count_ = 0;
}

std::string MqttDerivedTopics::homeAssistantNodeId() const {
  // Home Assistant's ids: [a-zA-Z0-9_-].
  std::string id = settings_.client_id;
  for (char& c : id)
    if (std::isalnum(static_cast<unsigned char>(c)) == 0 && c != '-' && c != '_') c = '_';
  return id;
}

void MqttDerivedTopics::addHomeAssistantConfigs(std::vector<MqttMessage>& out) const {
  const std::string node = homeAssistantNodeId();
  const std::string status_topic = settings_.prefix + "/" + std::string(protocol::kMqttStatusTopic);
  const Json device = {
      {"identifiers", {node}}, {"name", "gyrod " + node}, {"model", settings_.device}, {"manufacturer", "gyrod"}};
  const auto config = [&](const std::string& object, const std::string& name, const std::string& state_topic,
                          const std::string& value_template, const char* unit) {
    Json c = {{"name", name},
              {"unique_id", node + "_" + object},
              {"object_id", node + "_" + object},
              {"state_topic", state_topic},
              {"value_template", value_template},
              {"device", device}};
    if (unit != nullptr) {
      c["unit_of_measurement"] = unit;
      c["state_class"] = "measurement";
    }
    if (state_topic != status_topic) {
      c["availability_topic"] = status_topic;
      c["availability_template"] = "{{ value_json.state }}";
      c["payload_available"] = "online";
      c["payload_not_available"] = "offline";
    }
    if (object == "temperature") c["device_class"] = "temperature";
    out.push_back({settings_.home_assistant_prefix + "/sensor/" + node + "/" + object + "/config", c.dump(), 1, true});
  };
  for (int a = 0; a < 3; ++a) {
    const std::string axis(1, "xyz"[a]);
    config("rate_" + axis, "rate " + axis, summary_topic_,
           "{{ (value_json.rate if value_json.rate is defined else value_json.raw)[" + std::to_string(a) + "] }}",
           "°/s");
  }
  config("temperature", "temperature", summary_topic_, "{{ value_json.temp }}", "°C");
  if (settings_.orientation)
    for (const char* angle : {"roll", "pitch", "heading"})
      config(angle, angle, summary_topic_, std::string("{{ value_json.") + angle + " }}", "°");
  config("state", "state", status_topic, "{{ value_json.state }}", nullptr);
}

std::vector<MqttMessage> MqttDerivedTopics::due(double now_s, bool just_connected) {
  std::vector<MqttMessage> out;
  if (just_connected && settings_.home_assistant) addHomeAssistantConfigs(out);
  if (now_s >= next_summary_s_) {
    if (!just_connected) addSummary(out);
    next_summary_s_ = now_s + kSummaryEvery;
  }
  const std::uint64_t cycles = sources_.refit_cycles ? sources_.refit_cycles() : 0;
  // A source that has nothing yet (gyrod still starting) is asked again next time.
  if (just_connected) allan_pending_ = model_pending_ = true;
  if ((allan_pending_ || cycles != allan_cycles_sent_) && sources_.allan_json) {
    if (std::string allan = sources_.allan_json(); !allan.empty()) {
      out.push_back({allan_topic_, std::move(allan), 1, true});
      allan_cycles_sent_ = cycles;
      allan_pending_ = false;
    }
  }
  if ((model_pending_ || now_s >= next_model_check_s_) && sources_.model_json) {
    if (std::string model = sources_.model_json(); !model.empty()) {
      if (model_pending_ || model != model_sent_) out.push_back({model_topic_, model, 1, true});
      model_sent_ = std::move(model);
      model_pending_ = false;
      next_model_check_s_ = now_s + kModelCheckEvery;
    }
  }
  return out;
}

}  // namespace gyrod::daemon
