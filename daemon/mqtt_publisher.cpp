#include "daemon/mqtt_publisher.hpp"

#include <mosquitto.h>
#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>

#include <array>
#include <chrono>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include "formats/toml_document.hpp"
#include "protocol/protocol.hpp"

namespace gyrod::daemon {
namespace {

constexpr int kKeepAliveSeconds = 10;
constexpr auto kIdleWait = std::chrono::milliseconds(10);
constexpr auto kStatusEvery = std::chrono::seconds(5);
constexpr auto kOfflineWait = std::chrono::seconds(2);
constexpr int kMaxRetrySeconds = 10;

// libmosquitto's global state, set up once per process.
void initialiseLibraryOnce() {
  static std::once_flag once;
  std::call_once(once, [] { mosquitto_lib_init(); });
}

std::string jsonString(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

MqttPublisher::MqttPublisher(MqttSettings settings)
    : settings_(std::move(settings)),
      status_topic_(settings_.prefix + "/" + std::string(protocol::kMqttStatusTopic)),
      rate_topic_(settings_.prefix + "/" + std::string(protocol::kMqttRateTopic)),
      gap_topic_(settings_.prefix + "/" + std::string(protocol::kMqttGapTopic)),
      ring_(settings_.queue_lines) {
  initialiseLibraryOnce();
  mosq_ = mosquitto_new(settings_.client_id.c_str(), true, this);
  if (mosq_ == nullptr) throw std::runtime_error("MQTT: libmosquitto cannot create a client");
  const std::string offline = R"({"state":"offline"})";
  mosquitto_will_set(mosq_, status_topic_.c_str(), static_cast<int>(offline.size()), offline.data(), 1, true);
  if (!settings_.username.empty())
    mosquitto_username_pw_set(mosq_, settings_.username.c_str(),
                              settings_.password.empty() ? nullptr : settings_.password.c_str());
  mosquitto_connect_callback_set(mosq_, &MqttPublisher::onConnect);
  mosquitto_disconnect_callback_set(mosq_, &MqttPublisher::onDisconnect);
  mosquitto_publish_callback_set(mosq_, &MqttPublisher::onPublish);
  thread_ = std::thread([this] { threadMain(); });
}

MqttPublisher::~MqttPublisher() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  mosquitto_destroy(mosq_);
}

void MqttPublisher::push(const LineForClients& line) noexcept {
  if (!ring_.tryPush(line)) dropped_.fetch_add(1, std::memory_order_relaxed);
}

MqttStats MqttPublisher::stats() const {
  return {connected_.load(), published_.load(), dropped_.load(), connects_.load()};
}

void MqttPublisher::onConnect(mosquitto* /*mosq*/, void* self, int rc) {
  auto* p = static_cast<MqttPublisher*>(self);
  if (rc != 0) {
    spdlog::warn("MQTT: the broker at {}:{} refused the connection: {}", p->settings_.host, p->settings_.port,
                 mosquitto_connack_string(rc));
    return;
  }
  p->connects_.fetch_add(1);
  p->connecting_ = false;
  p->connected_ = true;
  spdlog::info("MQTT: connected to {}:{} as {}; publishing under {}/", p->settings_.host, p->settings_.port,
               p->settings_.client_id, p->settings_.prefix);
}

void MqttPublisher::onDisconnect(mosquitto* /*mosq*/, void* self, int rc) {
  auto* p = static_cast<MqttPublisher*>(self);
  p->connecting_ = false;
  if (p->connected_.exchange(false) && rc != 0 && !p->stop_)
    spdlog::warn("MQTT: lost the broker at {}:{} ({}); reconnecting", p->settings_.host, p->settings_.port,
                 mosquitto_strerror(rc));
}

void MqttPublisher::onPublish(mosquitto* /*mosq*/, void* self, int mid) {
  auto* p = static_cast<MqttPublisher*>(self);
  if (mid == p->last_status_mid_.load()) p->last_status_sent_ = true;
}

void MqttPublisher::publishStatus(const char* state) {
  std::string s = std::string(R"({"state":")") + state + R"(","device":)" + jsonString(settings_.device) +
                  R"(,"rate_hz":)" + formats::shortest(settings_.rate_hz) + R"(,"samples":)" +
                  std::to_string(samples_seen_) + R"(,"gaps":)" + std::to_string(gaps_seen_) + R"(,"samples_lost":)" +
                  std::to_string(samples_lost_) + R"(,"mqtt_dropped":)" + std::to_string(dropped_.load()) + "}";
  int mid = 0;
  if (mosquitto_publish(mosq_, &mid, status_topic_.c_str(), static_cast<int>(s.size()), s.data(), 1, true) ==
      MOSQ_ERR_SUCCESS) {
    last_status_mid_ = mid;
    published_.fetch_add(1, std::memory_order_relaxed);
  }
}

void MqttPublisher::publishLine(const LineForClients& line) {
  const bool rate = line.kind == LineForClients::Kind::Rate;
  if (rate) {
    ++samples_seen_;
    if ((samples_seen_ - 1) % settings_.rate_every != 0) return;
  } else {
    ++gaps_seen_;
    samples_lost_ += line.gap_count;
  }
  if (!connected_) return;  // counted, but nothing formatted or queued for a broker that is not there
  std::array<char, protocol::kMaxRateLineBytes> buffer;
  std::array<char, protocol::kMaxGapLineBytes> gap_buffer;
  char* text = rate ? buffer.data() : gap_buffer.data();
  std::size_t n = rate
                      ? protocol::formatRateLine(line.rate, buffer)
                      : protocol::formatGapLine(
                            {line.gap_first_seq, line.gap_count, std::string_view(line.gap_reason.data())}, gap_buffer);
  if (n > 0 && text[n - 1] == '\n') --n;  // a message is one JSON object, without the line's newline
  const std::string& topic = rate ? rate_topic_ : gap_topic_;
  if (mosquitto_publish(mosq_, nullptr, topic.c_str(), static_cast<int>(n), text, settings_.qos, false) ==
      MOSQ_ERR_SUCCESS)
    published_.fetch_add(1, std::memory_order_relaxed);
}

void MqttPublisher::threadMain() {
  // Never in competition with the sample loop, which may run SCHED_FIFO.
  const sched_param normal{};
  ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &normal);
  // The client is driven from here (mosquitto_loop): DNS, connect and every send happen on this
  // thread, and a connection that fails or is lost is tried again after 1, 2, ... 10 s.
  bool attempted = false, warned = false, was_connected = false;
  int failures = 0;
  auto now = std::chrono::steady_clock::now();
  auto next_attempt = now, next_status = now;
  LineForClients line;
  while (!stop_) {
    now = std::chrono::steady_clock::now();
    if (!connected_ && !connecting_ && now >= next_attempt) {
      const int rc = attempted
                         ? mosquitto_reconnect_async(mosq_)
                         : mosquitto_connect_async(mosq_, settings_.host.c_str(), settings_.port, kKeepAliveSeconds);
      attempted = true;
      if (rc == MOSQ_ERR_SUCCESS) {
        connecting_ = true;
      } else {
        if (!warned)
          spdlog::warn("MQTT: cannot reach the broker at {}:{} ({}); streaming on the socket and retrying",
                       settings_.host, settings_.port,
                       rc == MOSQ_ERR_ERRNO ? std::strerror(errno) : mosquitto_strerror(rc));
        warned = true;
        failures = std::min(failures + 1, kMaxRetrySeconds);
        next_attempt = now + std::chrono::seconds(failures);
      }
    }
    const bool connected = connected_.load();
    if (connected && (!was_connected || now >= next_status)) {
      publishStatus("online");
      next_status = now + kStatusEvery;
      warned = false;
      failures = 0;
    }
    was_connected = connected;
    while (ring_.tryPop(line)) publishLine(line);
    if (connected_ || connecting_) {
      const int rc = mosquitto_loop(mosq_, static_cast<int>(kIdleWait.count()), 1);
      if (rc != MOSQ_ERR_SUCCESS) {  // refused, lost or never made: try again later
        connecting_ = false;
        if (connected_.exchange(false) && !stop_)
          spdlog::warn("MQTT: lost the broker at {}:{} ({}); reconnecting", settings_.host, settings_.port,
                       mosquitto_strerror(rc));
        failures = std::min(failures + 1, kMaxRetrySeconds);
        next_attempt = std::chrono::steady_clock::now() + std::chrono::seconds(failures);
      }
    } else {
      std::this_thread::sleep_for(kIdleWait);
    }
  }
  if (connected_) {  // a clean stop: say so, and give it a moment to leave
    last_status_sent_ = false;
    publishStatus("offline");
    const auto until = std::chrono::steady_clock::now() + kOfflineWait;
    while (!last_status_sent_ && connected_ && std::chrono::steady_clock::now() < until)
      if (mosquitto_loop(mosq_, static_cast<int>(kIdleWait.count()), 1) != MOSQ_ERR_SUCCESS) break;
    mosquitto_disconnect(mosq_);
    mosquitto_loop(mosq_, static_cast<int>(kIdleWait.count()), 1);  // the DISCONNECT out
  }
}

}  // namespace gyrod::daemon
