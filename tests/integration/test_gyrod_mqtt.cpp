// gyrod on a real MQTT broker (Debian's mosquitto, started by the test on a free port): the
// retained status, every RATE line in order, "offline" at a clean stop and as the last will
// when gyrod is killed; a broker that comes only after gyrod has started; a broker restarted
// under a persistent session (qos 1: no message lost or reordered); TLS with a throw-away CA
// and password authentication, and the failures STATUS reports (wrong CA, wrong password, no
// broker); the live check's EFFECT line on the effect topic, and the same effect listed by the
// socket's "effects" and `gyroctl effects`.
#include <gtest/gtest.h>
#include <mosquitto.h>
#include <netinet/in.h>
#include <pwd.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>

#include "gyrod_process.hpp"
#include "live_sensor_model.hpp"
#include "mqtt_broker.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using namespace std::chrono_literals;
using nlohmann::json;

namespace {

// The lines of a mosquitto configuration that keep it on the loopback as the user running the
// test (as root, mosquitto would otherwise become the user mosquitto and could not write into
// the test's folder).
std::string brokerBasics(int port) {
  const passwd* user = ::getpwuid(::geteuid());
  return "listener " + std::to_string(port) + " 127.0.0.1\nuser " + std::string(user ? user->pw_name : "root") + "\n";
}

struct Message {
  std::string topic;
  std::string payload;
  bool retained = false;
};

// A subscriber to topic on the broker at port, collecting every message. With a client id, its
// session is persistent (the broker keeps its subscription and queues its messages while it
// is away); it reconnects by itself (libmosquitto's thread) when the broker restarts.
class Subscriber {
 public:
  Subscriber(int port, const std::string& topic, const std::string& client_id = {}, const std::string& username = {},
             const std::string& password = {}) {
    mosquitto_lib_init();
    mosq_ = mosquitto_new(client_id.empty() ? nullptr : client_id.c_str(), client_id.empty(), this);
    if (!username.empty()) mosquitto_username_pw_set(mosq_, username.c_str(), password.c_str());
    mosquitto_message_callback_set(mosq_, [](mosquitto*, void* self, const mosquitto_message* m) {
      auto* s = static_cast<Subscriber*>(self);
      const std::lock_guard lock(s->mutex_);
      s->messages_.push_back({m->topic, std::string(static_cast<const char*>(m->payload), m->payloadlen), m->retain});
    });
    connected_ = mosquitto_connect(mosq_, "127.0.0.1", port, 10) == MOSQ_ERR_SUCCESS &&
                 mosquitto_subscribe(mosq_, nullptr, topic.c_str(), 1) == MOSQ_ERR_SUCCESS &&
                 mosquitto_loop_start(mosq_) == MOSQ_ERR_SUCCESS;
  }
  ~Subscriber() {
    mosquitto_disconnect(mosq_);
    mosquitto_loop_stop(mosq_, false);
    mosquitto_destroy(mosq_);
  }
  bool connected() const { return connected_; }
  std::vector<Message> messages() const {
    const std::lock_guard lock(mutex_);
    return messages_;
  }
  // Waits until `pred` holds for the messages so far (or the timeout).
  template <typename Pred>
  bool waitFor(Pred pred, std::chrono::milliseconds timeout) const {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      if (pred(messages())) return true;
      std::this_thread::sleep_for(50ms);
    }
    return pred(messages());
  }

 private:
  mosquitto* mosq_ = nullptr;
  bool connected_ = false;
  mutable std::mutex mutex_;
  std::vector<Message> messages_;
};

std::size_t count(const std::vector<Message>& m, const std::string& topic) {
  std::size_t n = 0;
  for (const auto& x : m) n += x.topic == topic ? 1 : 0;
  return n;
}

bool hasState(const std::vector<Message>& m, const std::string& topic, const std::string& state) {
  for (const auto& x : m)
    if (x.topic == topic && json::parse(x.payload).value("state", "") == state) return true;
  return false;
}

std::string mqttConfig(const ScratchDir& d, int port) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[bias]\nsource = \"config\"\nvalues = [-3.34, 1.09, -0.5]\n"
    << "[socket]\npath = \"" << (d.path() / "gyrod.sock").string() << "\"\n"
    << "[mock]\nseed = 3\n"
    << "[mqtt]\nurl = \"mqtt://127.0.0.1:" << port << "\"\nprefix = \"test/board-1\"\nqos = 1\n";
  return c.str();
}

// gyrod's STATUS, asked on a connection of its own.
json statusOf(const std::filesystem::path& socket) {
  LineClient c(socket.string());
  if (!c.readLine()) return {};  // VERSION
  c.send("{\"cmd\":\"status\"}\n");
  for (int i = 0; i < 10; ++i) {
    const auto line = c.readLine();
    if (!line) break;
    json j = json::parse(*line);
    if (j.value("class", "") == "STATUS") return j;
  }
  return {};
}

// The seq of each RATE line a watching client reads for `duration`, appended to `seqs`.
void watchFor(LineClient& client, std::chrono::milliseconds duration, std::vector<std::uint64_t>& seqs) {
  const auto until = std::chrono::steady_clock::now() + duration;
  while (std::chrono::steady_clock::now() < until) {
    const auto line = client.readLine(1s);
    if (!line) continue;
    const json j = json::parse(*line);
    if (j.value("class", "") == "RATE") seqs.push_back(j["seq"].get<std::uint64_t>());
  }
}

std::vector<std::uint64_t> rateSeqs(const std::vector<Message>& messages, const std::string& topic) {
  std::vector<std::uint64_t> seqs;
  for (const auto& m : messages)
    if (m.topic == topic) seqs.push_back(json::parse(m.payload)["seq"].get<std::uint64_t>());
  return seqs;
}

// The first break in `seqs` (a seq that is neither the next one nor a repeat of one already
// seen), or "" when there is none: QoS 1 is at least once, so a message may come twice.
std::string firstBreak(const std::vector<std::uint64_t>& seqs) {
  for (std::size_t i = 1, next = seqs.empty() ? 0 : seqs[0] + 1; i < seqs.size(); ++i) {
    if (seqs[i] == next) {
      ++next;
    } else if (seqs[i] >= next || seqs[i] < seqs[0]) {
      return "seq " + std::to_string(seqs[i]) + " at " + std::to_string(i) + " where " + std::to_string(next) +
             " was due";
    }
  }
  return "";
}

std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST(GyrodMqtt, PublishesTheStatusAndEveryRateLineInOrderAndGoesOfflineAtAStop) {
  const int port = freeLoopbackPort();
  Broker broker(port);
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", mqttConfig(d, port));
  Subscriber sub(port, "test/board-1/#");
  ASSERT_TRUE(sub.connected()) << "no broker on port " << port << " (/usr/sbin/mosquitto: Debian's mosquitto)";
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  ASSERT_TRUE(sub.waitFor([](const auto& m) { return count(m, "test/board-1/rate") >= 100; }, 20s))
      << readWholeFile(d.path() / "log.txt");
  const auto online = sub.messages();
  EXPECT_TRUE(hasState(online, "test/board-1/status", "online"));
  std::optional<std::uint64_t> last;
  for (const auto& m : online) {
    if (m.topic != "test/board-1/rate") continue;
    const json j = json::parse(m.payload);  // one JSON object, no newline
    EXPECT_EQ(j["class"], "RATE");
    const auto seq = j["seq"].get<std::uint64_t>();
    if (last) {
      EXPECT_EQ(seq, *last + 1);
    }
    last = seq;
  }
  gyrod.signal(SIGTERM);
  const auto status = gyrod.waitExit(10s);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(*status, 0);
  ASSERT_TRUE(sub.waitFor([](const auto& m) { return hasState(m, "test/board-1/status", "offline"); }, 5s));
  // The last status says what was published: at least the lines the subscriber saw.
  for (const auto& m : sub.messages()) {
    if (m.topic == "test/board-1/status" && json::parse(m.payload)["state"] == "offline") {
      EXPECT_GE(json::parse(m.payload)["samples"].get<std::uint64_t>(), 100u);
    }
  }
  // Retained: a subscriber that comes later is told at once.
  Subscriber late(port, "test/board-1/status");
  ASSERT_TRUE(late.waitFor([](const auto& m) { return !m.empty(); }, 5s));
  EXPECT_TRUE(late.messages().front().retained);
  EXPECT_TRUE(hasState(late.messages(), "test/board-1/status", "offline"));
}

TEST(GyrodMqtt, StreamsWithoutABrokerConnectsWhenOneComesAndItsLastWillIsOffline) {
  const int port = freeLoopbackPort();
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", mqttConfig(d, port));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient client((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(client.connected());
  ASSERT_TRUE(client.readLine());  // VERSION
  ASSERT_TRUE(client.send("{\"cmd\":\"watch\",\"enable\":true}\n"));
  for (int i = 0; i < 20; ++i) ASSERT_TRUE(client.readLine(5s)) << "no broker must not stop the socket";
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find("MQTT: cannot connect to the broker at 127.0.0.1:" + std::to_string(port)), std::string::npos)
      << log;

  Broker broker(port);  // now it comes: gyrod retries within 10 s
  Subscriber sub(port, "test/board-1/#");
  ASSERT_TRUE(sub.connected());
  ASSERT_TRUE(sub.waitFor([](const auto& m) { return count(m, "test/board-1/rate") >= 10; }, 20s))
      << readWholeFile(d.path() / "log.txt");
  EXPECT_TRUE(hasState(sub.messages(), "test/board-1/status", "online"));
  gyrod.signal(SIGKILL);  // no clean stop: the broker publishes the last will
  gyrod.waitExit(5s);
  EXPECT_TRUE(sub.waitFor([](const auto& m) { return hasState(m, "test/board-1/status", "offline"); }, 10s));
}

// qos 1 across a broker restart: the messages made while it is away are kept and delivered in
// order when it is back, to a subscriber with a persistent session; the socket streams on.
TEST(GyrodMqtt, KeepsEveryRateMessageInOrderAcrossABrokerRestart) {
  const int port = freeLoopbackPort();
  ScratchDir d;
  std::filesystem::create_directories(d.path() / "broker");
  const auto broker_config =
      d.write("mosquitto.conf", brokerBasics(port) + "allow_anonymous true\npersistence true\npersistence_location " +
                                    (d.path() / "broker").string() + "/\nmax_queued_messages 0\n");
  Broker broker(port, broker_config);
  Subscriber sub(port, "test/board-1/rate", "gyrod-test-outage");
  ASSERT_TRUE(sub.connected()) << "no broker on port " << port << " (/usr/sbin/mosquitto: Debian's mosquitto)";
  const auto cfg = d.write("gyrod.toml", mqttConfig(d, port));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient watcher((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(watcher.readLine());  // VERSION
  ASSERT_TRUE(watcher.send("{\"cmd\":\"watch\",\"enable\":true}\n"));
  std::vector<std::uint64_t> socket_seqs;
  const auto until_online = std::chrono::steady_clock::now() + 30s;
  while (count(sub.messages(), "test/board-1/rate") < 50 && std::chrono::steady_clock::now() < until_online)
    watchFor(watcher, 200ms, socket_seqs);
  ASSERT_GE(count(sub.messages(), "test/board-1/rate"), 50u) << readWholeFile(d.path() / "log.txt");

  broker.stop();
  watchFor(watcher, 5s, socket_seqs);
  ASSERT_FALSE(socket_seqs.empty());
  const std::uint64_t during_outage = socket_seqs.back();
  broker.start();
  // Back: everything kept comes, then new lines (50 past the outage: the buffer was sent).
  const auto until_caught_up = std::chrono::steady_clock::now() + 60s;
  while (std::chrono::steady_clock::now() < until_caught_up) {
    watchFor(watcher, 200ms, socket_seqs);
    const auto seqs = rateSeqs(sub.messages(), "test/board-1/rate");
    if (!seqs.empty() && seqs.back() >= during_outage + 50) break;
  }
  const auto seqs = rateSeqs(sub.messages(), "test/board-1/rate");
  const std::string log = readWholeFile(d.path() / "log.txt");
  ASSERT_FALSE(seqs.empty());
  ASSERT_GE(seqs.back(), during_outage + 50) << log;
  EXPECT_EQ(firstBreak(seqs), "") << log;
  EXPECT_EQ(firstBreak(socket_seqs), "");
  for (std::size_t i = 1; i < socket_seqs.size(); ++i) {
    if (socket_seqs[i] != socket_seqs[i - 1] + 1) {
      ADD_FAILURE() << "the socket's stream broke at seq " << socket_seqs[i];
      break;
    }
  }
  EXPECT_NE(log.find("MQTT: lost the broker at 127.0.0.1:" + std::to_string(port)), std::string::npos) << log;
  EXPECT_NE(log.find("without the broker;"), std::string::npos) << log;
  EXPECT_NE(log.find("messages kept meanwhile are sent now, 0 dropped"), std::string::npos) << log;
  const json status = statusOf(d.path() / "gyrod.sock");
  EXPECT_EQ(status.value("mqtt_connected", false), true) << status.dump();
  EXPECT_EQ(status.value("mqtt_dropped", 1), 0) << status.dump();
  EXPECT_TRUE(status.contains("mqtt_last_error")) << status.dump();  // the lost connection
  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(10s), std::optional<int>(0));
}

namespace {

// A throw-away CA, a second CA that signed nothing here, a server certificate for 127.0.0.1
// and a client certificate signed by the first, and a mosquitto password file (user gyrod,
// password s3cret).
bool makeTlsFiles(const std::filesystem::path& dir) {
  const std::string key = " -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes";
  const std::string script =
      "cd '" + dir.string() + "' && " +                                                                //
      "openssl req -x509" + key + " -keyout ca.key -out ca.crt -days 2 -subj /CN=gyrod-test-ca && " +  //
      "openssl req -x509" + key + " -keyout other-ca.key -out other-ca.crt -days 2 -subj /CN=other-ca && " +
      "openssl req -new" + key + " -keyout server.key -out server.csr -subj /CN=localhost && " +
      "printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\\n' > san.cnf && " +
      "openssl x509 -req -in server.csr -CA ca.crt -CAkey ca.key -CAcreateserial -out server.crt -days 2 "
      "-extfile san.cnf && "
      "openssl req -new" +
      key + " -keyout client.key -out client.csr -subj /CN=gyrod-board && " +
      "openssl x509 -req -in client.csr -CA ca.crt -CAkey ca.key -CAcreateserial -out client.crt -days 2 && "
      "mosquitto_passwd -b -c passwd gyrod s3cret && chmod 0600 passwd";
  return std::system(("(" + script + ") >/dev/null 2>&1").c_str()) == 0;
}

// gyrod publishing to the TLS listener at port, checking its certificate against ca; with a
// password (user gyrod) or, with extra, its own certificate.
std::string tlsConfig(const ScratchDir& d, int port, const std::string& ca, const std::string& password,
                      const std::string& extra = {}) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[bias]\nsource = \"config\"\nvalues = [-3.34, 1.09, -0.5]\n"
    << "[socket]\npath = \"" << (d.path() / "gyrod.sock").string() << "\"\n"
    << "[mqtt]\nurl = \"mqtts://127.0.0.1:" << port << "\"\nprefix = \"test/board-1\"\nqos = 1\n"
    << "ca_file = \"" << ca << "\"\n"
    << extra;
  if (!password.empty())
    c << "username = \"gyrod\"\npassword_file = \"" << d.write("mqtt-password", password + "\n").string() << "\"\n";
  return c.str();
}

// gyrod publishing to port with ca and password cannot: one log line says why (`cause`),
// however often it retries, STATUS mqtt_last_error says the same, and the socket streams on.
// (libmosquitto 2.0 now and then leaves a TLS handshake waiting until its keep-alive ends it:
// that cause is logged once too, so the log is read for `cause` alone.)
void expectFailureReported(int port, const std::string& ca, const std::string& password, const std::string& cause) {
  SCOPED_TRACE(cause);
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", tlsConfig(d, port, ca, password));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient watcher((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(watcher.readLine());  // VERSION
  ASSERT_TRUE(watcher.send("{\"cmd\":\"watch\",\"enable\":true}\n"));
  json status;
  std::vector<std::uint64_t> seqs;
  const auto until = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < until) {
    status = statusOf(d.path() / "gyrod.sock");
    if (status.value("mqtt_last_error", "").find(cause) != std::string::npos) break;
    watchFor(watcher, 200ms, seqs);
  }
  EXPECT_NE(status.value("mqtt_last_error", "").find(cause), std::string::npos) << status.dump();
  EXPECT_EQ(status.value("mqtt_connected", true), false) << status.dump();
  seqs.clear();
  watchFor(watcher, 4s, seqs);  // retries after 0.5, 1, 2 s meanwhile (±20 %)
  EXPECT_GE(seqs.size(), 100u) << "the socket must stream on";
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_EQ(occurrences(log, cause), 1u) << log;
  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(10s), std::optional<int>(0));
}

}  // namespace

// mqtts:// with the broker's CA and the right password publishes; the wrong CA, the wrong
// password and a port nobody listens on are each one clear log line and a STATUS field.
TEST(GyrodMqtt, PublishesOverTlsWithAPasswordAndReportsWhatKeepsItFromConnecting) {
  ScratchDir certs;
  ASSERT_TRUE(makeTlsFiles(certs.path())) << "openssl and mosquitto_passwd make the test's CA and password file";
  const int tls_port = freeLoopbackPort(), plain_port = freeLoopbackPort();
  const auto dir = certs.path().string();
  const auto broker_config =
      certs.write("mosquitto.conf", "per_listener_settings false\nallow_anonymous false\npassword_file " + dir +
                                        "/passwd\n" + "listener " + std::to_string(tls_port) + " 127.0.0.1\ncafile " +
                                        dir + "/ca.crt\n" + "certfile " + dir + "/server.crt\nkeyfile " + dir +
                                        "/server.key\n" + brokerBasics(plain_port));
  Broker broker(plain_port, broker_config);
  ASSERT_TRUE(acceptsConnections(tls_port));
  {
    Subscriber sub(plain_port, "test/board-1/rate", {}, "gyrod", "s3cret");
    ASSERT_TRUE(sub.connected());
    ScratchDir d;
    const auto cfg = d.write("gyrod.toml", tlsConfig(d, tls_port, dir + "/ca.crt", "s3cret"));
    GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
    ASSERT_TRUE(sub.waitFor([](const auto& m) { return count(m, "test/board-1/rate") >= 10; }, 30s))
        << readWholeFile(d.path() / "log.txt");
    const json status = statusOf(d.path() / "gyrod.sock");
    EXPECT_EQ(status.value("mqtt_connected", false), true) << status.dump();
    gyrod.signal(SIGTERM);
    EXPECT_EQ(gyrod.waitExit(10s), std::optional<int>(0));
  }
  expectFailureReported(tls_port, dir + "/other-ca.crt", "s3cret", "certificate verify failed");
  expectFailureReported(tls_port, dir + "/ca.crt", "wrong", "not authorised");
  expectFailureReported(freeLoopbackPort(), dir + "/ca.crt", "s3cret", "Connection refused");
}

// A broker that asks for a client certificate: gyrod presents mqtt.cert_file and key_file.
TEST(GyrodMqtt, PresentsItsClientCertificateWhenTheBrokerAsksForOne) {
  ScratchDir certs;
  ASSERT_TRUE(makeTlsFiles(certs.path())) << "openssl and mosquitto_passwd make the test's CA and password file";
  const int tls_port = freeLoopbackPort(), plain_port = freeLoopbackPort();
  const auto dir = certs.path().string();
  const auto broker_config = certs.write(
      "mosquitto.conf", "per_listener_settings false\nallow_anonymous true\nlistener " + std::to_string(tls_port) +
                            " 127.0.0.1\ncafile " + dir + "/ca.crt\ncertfile " + dir + "/server.crt\nkeyfile " + dir +
                            "/server.key\nrequire_certificate true\n" + brokerBasics(plain_port));
  Broker broker(plain_port, broker_config);
  ASSERT_TRUE(acceptsConnections(tls_port));
  Subscriber sub(plain_port, "test/board-1/rate");
  ASSERT_TRUE(sub.connected());
  ScratchDir d;
  const std::string client = "cert_file = \"" + dir + "/client.crt\"\nkey_file = \"" + dir + "/client.key\"\n";
  const auto cfg = d.write("gyrod.toml", tlsConfig(d, tls_port, dir + "/ca.crt", "", client));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  ASSERT_TRUE(sub.waitFor([](const auto& m) { return count(m, "test/board-1/rate") >= 10; }, 30s))
      << readWholeFile(d.path() / "log.txt");
  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(10s), std::optional<int>(0));
}

// What gyrod derives for dashboards: a summary each second, the retained allan and model
// topics, and with home_assistant the discovery configs, retained, pointing at them.
TEST(GyrodMqtt, PublishesTheSummaryTheRetainedAllanAndModelAndHomeAssistantDiscovery) {
  const int port = freeLoopbackPort();
  Broker broker(port);
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", mqttConfig(d, port) + "client_id = \"board.1\"\nhome_assistant = true\n");
  Subscriber sub(port, "#");
  ASSERT_TRUE(sub.connected());
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  ASSERT_TRUE(sub.waitFor([](const auto& m) { return count(m, "test/board-1/summary") >= 3; }, 30s))
      << readWholeFile(d.path() / "log.txt");
  const auto messages = sub.messages();
  int summaries = 0;
  for (const auto& m : messages) {
    if (m.topic != "test/board-1/summary") continue;
    const json j = json::parse(m.payload);
    const json& mean = j.contains("rate") ? j["rate"] : j["raw"];
    ASSERT_EQ(mean.size(), 3u) << m.payload;
    if (++summaries > 1) {                                  // the first second may be cut by the connection
      EXPECT_GE(j["samples"].get<int>(), 40) << m.payload;  // 50 Hz
      EXPECT_LE(j["samples"].get<int>(), 60) << m.payload;
    }
    // The mock's bias is -3.34 deg/s on x: in raw, and taken out of the rate stream.
    EXPECT_NEAR(mean[0].get<double>(), j.contains("rate") ? 0.0 : -3.34, 1.0) << m.payload;
  }
  Subscriber late(port, "test/board-1/+");  // the retained topics reach a subscriber that comes later
  ASSERT_TRUE(late.waitFor(
      [](const auto& m) { return count(m, "test/board-1/allan") == 1 && count(m, "test/board-1/model") == 1; }, 10s));
  for (const auto& m : late.messages()) {
    if (m.topic == "test/board-1/allan") {
      EXPECT_TRUE(m.retained);
      EXPECT_EQ(json::parse(m.payload)["class"], "ALLAN");
    }
    if (m.topic == "test/board-1/model") {
      EXPECT_TRUE(m.retained);
      EXPECT_EQ(json::parse(m.payload)["rate_model"], "bias") << m.payload;
    }
  }
  Subscriber home(port, "homeassistant/#");
  ASSERT_TRUE(home.waitFor([](const auto& m) { return m.size() >= 5; }, 10s));
  for (const auto& m : home.messages()) {
    EXPECT_TRUE(m.retained) << m.topic;
    EXPECT_EQ(m.topic.rfind("homeassistant/sensor/board_1/", 0), 0u) << m.topic;
  }
  EXPECT_EQ(json::parse(home.messages().front().payload)["device"]["identifiers"], json::array({"board_1"}));
}

namespace {

// The live check's set-up of test_gyrod_live_check.cpp: the accelerated mock at rest with a
// sensor model (the still detector), a 12.5 Hz vibration of 0.02 deg/s on y from 300 s of data.
constexpr double kMqttEffectOnsetS = 300.0;

// qos 0 and one RATE message in 1000: the broker is not flooded at 100 x real time, and the
// effect topic is QoS 1 all the same.
std::string mqttEffectConfig(const ScratchDir& d, const std::filesystem::path& model, int port) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[filter]\nmodel = \"" << model.string() << "\"\n"
    << "[socket]\npath = \"" << (d.path() / "gyrod.sock").string() << "\"\n"
    << "[check]\ninterval_s = 60\nbaseline_s = 120\n"
    << "[mock]\nspeed = 100\nseed = 4\nmotion = \"sine:axis=y,freq=12.5,amp=0.02,start=" << kMqttEffectOnsetS << "\"\n"
    << "[mqtt]\nurl = \"mqtt://127.0.0.1:" << port << "\"\nprefix = \"test/board-1\"\nqos = 0\nrate_every = 1000\n";
  return c.str();
}

// The reply of one request on a connection of its own, skipping other classes.
json replyOf(const std::filesystem::path& socket, const std::string& request, const std::string& cls) {
  LineClient c(socket.string());
  if (!c.readLine()) return {};  // VERSION
  c.send(request + "\n");
  for (int i = 0; i < 10; ++i) {
    const auto line = c.readLine(10s);
    if (!line) break;
    json j = json::parse(*line);
    if (j.value("class", "") == cls) return j;
  }
  return {};
}

}  // namespace

// An effect the live check names goes to <prefix>/effect (not retained), and while it lasts the
// socket's "effects" and `gyroctl effects` list it: the same object on all three.
TEST(GyrodMqtt, PublishesEachEffectAndTheSocketListsIt) {
  const int port = freeLoopbackPort();
  Broker broker(port);
  ScratchDir d;
  const auto model = d.write("model.toml", liveCheckSensorModel());
  const auto cfg = d.write("gyrod.toml", mqttEffectConfig(d, model, port));
  Subscriber sub(port, "test/board-1/effect");
  ASSERT_TRUE(sub.connected()) << "no broker on port " << port << " (/usr/sbin/mosquitto: Debian's mosquitto)";
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  const auto socket = d.path() / "gyrod.sock";
  // Before the baseline is complete the check runs and names nothing.
  const json early = replyOf(socket, R"({"cmd":"effects"})", "EFFECTS");
  ASSERT_EQ(early.value("class", ""), "EFFECTS") << readWholeFile(d.path() / "log.txt");
  EXPECT_EQ(early["live_check"], "on") << early;
  EXPECT_FALSE(early.contains("reason")) << early;

  ASSERT_TRUE(sub.waitFor([](const auto& m) { return !m.empty(); }, 90s)) << readWholeFile(d.path() / "log.txt");
  const Message message = sub.messages().front();
  EXPECT_FALSE(message.retained);
  const json published = json::parse(message.payload);  // one JSON object, no newline
  EXPECT_EQ(published["class"], "EFFECT") << message.payload;
  EXPECT_EQ(published["state"], "new") << message.payload;
  EXPECT_EQ(published["effect"], "line") << message.payload;
  EXPECT_EQ(published["axis"], "y") << message.payload;

  const json listed = replyOf(socket, R"({"cmd":"effects"})", "EFFECTS");
  EXPECT_EQ(listed["live_check"], "on") << listed;
  EXPECT_TRUE(listed["baseline_ready"].get<bool>()) << listed;
  EXPECT_GE(listed["intervals"].get<int>(), 3) << listed;
  ASSERT_GE(listed["effects"].size(), 1u) << listed;
  EXPECT_EQ(listed["effects"][0], published) << listed;
  // STATUS's live_check lists the same.
  EXPECT_EQ(statusOf(socket)["live_check"]["current"], listed["effects"]);

  const CommandResult text = runGyroctl("effects --socket " + socket.string(), d.path());
  EXPECT_EQ(text.exit_status, 0) << text.err;
  std::cout << text.out;
  EXPECT_NE(text.out.find("live check: on, "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("baseline ready"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("centre_hz 12.5"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find(published["evidence"].get<std::string>()), std::string::npos) << text.out;
  const CommandResult raw = runGyroctl("effects --json --socket " + socket.string(), d.path());
  EXPECT_EQ(raw.exit_status, 0) << raw.err;
  EXPECT_EQ(json::parse(raw.out)["effects"][0], published) << raw.out;

  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(10s), std::optional<int>(0));
  // A subscriber that comes later is given no old change: the topic retains nothing.
  Subscriber late(port, "test/board-1/effect");
  ASSERT_TRUE(late.connected());
  EXPECT_FALSE(late.waitFor([](const auto& m) { return !m.empty(); }, 1s));
}
