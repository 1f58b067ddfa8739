#pragma once
// gyrod's samples and status on an MQTT broker (libmosquitto), for a fleet of boards read from
// one place (docs/protocol.md "MQTT"). The sample thread only pushes into a lock-free ring
// (push: no lock, no allocation, no system call) and, once per loop turn, wakes the publisher
// (wake: one eventfd write); a thread of the publisher's own, at normal
// priority, takes from it, formats the messages and drives libmosquitto (mosquitto_loop): DNS,
// TLS, connect, reconnect after 0.5, 1, 2, ... 30 s (±20 %), send. A broker that is down or
// unreachable is not an error: gyrod streams on its socket and the publisher keeps retrying.
// With qos 1 the messages made meanwhile wait in a bounded buffer of this thread (the oldest
// dropped past buffer_messages) and are sent in order when the broker is back, after those
// libmosquitto still holds in flight; the session is persistent (clean_session false) so that
// the broker keeps its side of them. With qos 0 nothing waits for a broker that is not there.
// Whatever is dropped (the ring full, the buffer full, qos 0 while disconnected) is counted.
// Topics under the prefix: status (retained; "online" when connected, "offline" as the last
// will and at a clean stop), rate (every rate_every-th RATE line), gap (every GAP line), effect
// (every EFFECT line of the live check, QoS 1 whatever qos says, kept while the broker is away),
// and those of daemon/mqtt_derived_topics.hpp (summary, allan, model, Home Assistant discovery).
// EFFECT lines come a few an hour and vary in length: each is a string of its own whose
// ownership passes to the publisher through a small lock-free ring of pointers, so the sample
// thread's share stays a copy and a push.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "daemon/client_handover.hpp"
#include "daemon/kept_lines.hpp"
#include "daemon/mqtt_derived_topics.hpp"
#include "daemon/spsc_ring.hpp"
#include "protocol/fd.hpp"

struct mosquitto;

namespace gyrod::daemon {

struct MqttSettings {
  std::string host;
  int port = 1883;
  bool tls = false;       // mqtts://: the broker's certificate is always verified
  std::string ca_file;    // tls: PEM CA certificates; empty: the system's, /etc/ssl/certs
  std::string cert_file;  // tls: a client certificate, with key_file; empty: none
  std::string key_file;
  std::string prefix;     // topics are prefix + "/status", "/rate", "/gap"
  std::string client_id;  // unique per board
  int qos = 0;            // 0 or 1, for rate and gap (status: always 1)
  std::size_t rate_every = 1;
  std::string username;  // empty: none
  std::string password;
  std::string device;  // for the status message
  double rate_hz = 0.0;
  std::size_t queue_lines = 4096;   // the ring between the sample thread and the publisher
  std::size_t buffer_messages = 0;  // qos 1: kept while the broker is away (0: none)
  bool home_assistant = false;      // Home Assistant's discovery configs (daemon/mqtt_derived_topics.hpp)
  std::string home_assistant_prefix = "homeassistant";
  bool orientation = false;  // RATE carries the orientation (a sensor model and the accel)
};

struct MqttStats {
  bool connected = false;
  std::uint64_t published = 0;  // messages handed to libmosquitto (rate, gap and status)
  std::uint64_t buffered = 0;   // rate and gap messages waiting for the broker now
  std::uint64_t dropped = 0;    // rate and gap messages the broker will never get from gyrod
  std::uint64_t connects = 0;   // successful connections (1 + reconnections)
  std::string last_error;       // why the last attempt or connection failed; empty: none yet
};

class MqttPublisher {
 public:
  // Starts the publisher's thread, which connects in the background. Throws std::runtime_error
  // when libmosquitto cannot make a client.
  // `sources` feed the summary, allan and model topics (daemon/mqtt_derived_topics.hpp); they are
  // called on the publisher's thread.
  explicit MqttPublisher(MqttSettings settings, MqttDerivedSources sources = {});
  // stop().
  ~MqttPublisher();
  // Publishes "offline" (retained), waits up to 2 s for it to leave, disconnects, and ends the
  // thread. Not on the sample thread.
  void stop();
  MqttPublisher(const MqttPublisher&) = delete;
  MqttPublisher& operator=(const MqttPublisher&) = delete;

  // Sample thread only: never waits.
  void push(const LineForClients& line) noexcept;
  // Sample thread only: an EFFECT line (one JSON object, without its newline) for
  // <prefix>/effect. Copies it and never waits; wake() hands it on at once. Dropped (and logged
  // by the publisher) when kEffectQueueLines are waiting for the publisher's thread.
  void pushEffect(std::string_view line) noexcept;
  // Sample thread, once per loop turn that pushed lines (one write to an eventfd): the
  // publisher takes them at once rather than at its next keep-alive wake-up.
  void wake() noexcept;

  MqttStats stats() const;
  const std::string& statusTopic() const { return status_topic_; }

  // EFFECT lines between the sample thread and the publisher's, and kept for the broker while it
  // is away (the oldest dropped beyond it): the live check names a few an hour.
  static constexpr std::size_t kEffectQueueLines = 64;
  static constexpr std::size_t kMaxKeptEffects = 256;

 private:
  void threadMain();
  void setUpTls();
  void publishStatus(const char* state);
  void takeLine(const LineForClients& line);
  bool publishLine(const LineForClients& line);
  void sendBuffered();
  void takeEffects();
  void sendEffects();
  void attemptConnection(std::chrono::steady_clock::time_point now);
  void runLoop();
  bool checkConnecting();
  void stopCleanly();
  void connectionFailed(const std::string& why);
  void setLastError(const std::string& why);
  void reportOutageOver();
  void publishDerived(bool just_connected);
  void waitForNetworkOrLines();
  static void onConnect(mosquitto* mosq, void* self, int rc);
  static void onDisconnect(mosquitto* mosq, void* self, int rc);
  static void onPublish(mosquitto* mosq, void* self, int mid);
  static void onLog(mosquitto* mosq, void* self, int level, const char* text);

  MqttSettings settings_;
  std::string status_topic_, rate_topic_, gap_topic_, effect_topic_;
  SpscRing<LineForClients> ring_;
  // Each pointer owns its line: the sample thread releases it into the ring, the publisher's
  // thread takes it back (the destructor frees what is left).
  SpscRing<std::string*> effect_ring_{kEffectQueueLines};
  std::atomic<std::uint64_t> effects_refused_{0};  // the effect ring was full (sample thread)
  std::uint64_t effects_refused_logged_ = 0;       // publisher thread
  std::deque<std::string> effects_kept_;           // publisher thread: not yet handed to libmosquitto
  std::atomic<bool> stop_{false};
  std::atomic<bool> connected_{false};
  bool connecting_ = false;  // publisher thread (and libmosquitto's callbacks, on it)
  std::atomic<std::uint64_t> published_{0}, dropped_{0}, connects_{0}, buffered_{0};
  std::atomic<int> last_status_mid_{-1};
  std::atomic<bool> last_status_sent_{false};
  std::uint64_t samples_seen_ = 0, gaps_seen_ = 0, samples_lost_ = 0;  // publisher thread
  // Publisher thread: qos 1 messages not yet handed to libmosquitto, oldest first, and the
  // qos 1 messages handed to it and not yet acknowledged (PUBACK).
  KeptLines<LineForClients> buffer_;
  std::size_t unacknowledged_ = 0;
  // Publisher thread: the retries' schedule, and the current outage (since the connection was
  // lost or the first attempt failed) for the line that says what it cost.
  int failures_ = 0;
  bool attempted_ = false, in_outage_ = false;
  std::chrono::steady_clock::time_point next_attempt_{}, outage_start_{};
  std::uint64_t outage_dropped_start_ = 0, outage_buffered_ = 0;
  std::vector<std::string> logged_causes_;  // the causes of failure logged in this outage
  // Why the attempt under way failed, as libmosquitto tells it before its calls return an
  // error code: the broker's refusal (CONNACK) or OpenSSL's reason (its log).
  std::string pending_cause_;
  bool disconnected_ = false;  // onDisconnect saw the connection end
  int connect_errno_ = 0;      // errno right after the last connect call
  std::minstd_rand jitter_;
  MqttDerivedTopics derived_;       // publisher thread
  protocol::Fd wake_fd_;            // eventfd: the sample thread's wake() to the publisher's poll
  mutable std::mutex error_mutex_;  // last_error_: publisher thread writes, STATUS reads
  std::string last_error_;
  mosquitto* mosq_ = nullptr;
  std::thread thread_;
};

}  // namespace gyrod::daemon
