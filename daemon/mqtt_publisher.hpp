#pragma once
// gyrod's samples and status on an MQTT broker (libmosquitto), for a fleet of boards read from
// one place (docs/protocol.md "MQTT"). The sample thread only pushes into a lock-free ring
// (push: no lock, no allocation, no system call); a thread of the publisher's own, at normal
// priority, takes from it, formats the messages and drives libmosquitto (mosquitto_loop): DNS,
// connect, reconnect after 1, 2, ... 10 s, send. A broker that is down or
// unreachable is not an error: gyrod streams on its socket and the publisher keeps retrying;
// what the ring cannot hold meanwhile is counted (gyrod's stop line), never waited for; while
// no broker is connected, lines are not queued for it.
// Topics under the prefix: status (retained; "online" when connected, "offline" as the last
// will and at a clean stop), rate (every rate_every-th RATE line), gap (every GAP line).
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "daemon/client_handover.hpp"
#include "daemon/spsc_ring.hpp"

struct mosquitto;

namespace gyrod::daemon {

struct MqttSettings {
  std::string host;
  int port = 1883;
  std::string prefix;     // topics are prefix + "/status", "/rate", "/gap"
  std::string client_id;  // unique per board
  int qos = 0;            // 0 or 1, for rate and gap (status: always 1)
  std::size_t rate_every = 1;
  std::string username;  // empty: none
  std::string password;
  std::string device;  // for the status message
  double rate_hz = 0.0;
  std::size_t queue_lines = 4096;  // the ring between the sample thread and the publisher
};

struct MqttStats {
  bool connected = false;
  std::uint64_t published = 0;  // messages handed to libmosquitto (rate, gap and status)
  std::uint64_t dropped = 0;    // lines the ring could not take (the publisher fell behind)
  std::uint64_t connects = 0;   // successful connections (1 + reconnections)
};

class MqttPublisher {
 public:
  // Starts the publisher's thread, which connects in the background. Throws std::runtime_error
  // when libmosquitto cannot make a client.
  explicit MqttPublisher(MqttSettings settings);
  // Publishes "offline" (retained), waits up to 2 s for it to leave, disconnects.
  ~MqttPublisher();
  MqttPublisher(const MqttPublisher&) = delete;
  MqttPublisher& operator=(const MqttPublisher&) = delete;

  // Sample thread only: never waits.
  void push(const LineForClients& line) noexcept;

  MqttStats stats() const;
  const std::string& statusTopic() const { return status_topic_; }

 private:
  void threadMain();
  void publishStatus(const char* state);
  void publishLine(const LineForClients& line);
  static void onConnect(mosquitto* mosq, void* self, int rc);
  static void onDisconnect(mosquitto* mosq, void* self, int rc);
  static void onPublish(mosquitto* mosq, void* self, int mid);

  MqttSettings settings_;
  std::string status_topic_, rate_topic_, gap_topic_;
  SpscRing<LineForClients> ring_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> connected_{false};
  bool connecting_ = false;  // publisher thread (and libmosquitto's callbacks, on it)
  std::atomic<std::uint64_t> published_{0}, dropped_{0}, connects_{0};
  std::atomic<int> last_status_mid_{-1};
  std::atomic<bool> last_status_sent_{false};
  std::uint64_t samples_seen_ = 0, gaps_seen_ = 0, samples_lost_ = 0;  // publisher thread
  mosquitto* mosq_ = nullptr;
  std::thread thread_;
};

}  // namespace gyrod::daemon
