// gyrod on a real MQTT broker (Debian's mosquitto, started by the test on a free port): the
// retained status, every RATE line in order, "offline" at a clean stop and as the last will
// when gyrod is killed; and a broker that comes only after gyrod has started.
#include <gtest/gtest.h>
#include <mosquitto.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "gyrod_process.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using namespace std::chrono_literals;
using nlohmann::json;

namespace {

int freeTcpPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t n = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &n);
  ::close(fd);
  return ntohs(a.sin_port);
}

// Debian's broker, on the loopback only (its default without a configuration file).
class Broker {
 public:
  explicit Broker(int port) {
    pid_ = ::fork();
    if (pid_ == 0) {
      const std::string p = std::to_string(port);
      ::execl("/usr/sbin/mosquitto", "mosquitto", "-p", p.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    // Ready when it accepts a connection.
    for (int i = 0; i < 100; ++i) {
      const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
      sockaddr_in a{};
      a.sin_family = AF_INET;
      a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      a.sin_port = htons(static_cast<std::uint16_t>(port));
      const bool up = ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
      ::close(fd);
      if (up) return;
      std::this_thread::sleep_for(50ms);
    }
  }
  ~Broker() {
    ::kill(pid_, SIGTERM);
    ::waitpid(pid_, nullptr, 0);
  }

 private:
  pid_t pid_ = -1;
};

struct Message {
  std::string topic;
  std::string payload;
  bool retained = false;
};

// A subscriber to topic on the broker at port, collecting every message.
class Subscriber {
 public:
  Subscriber(int port, const std::string& topic) {
    mosquitto_lib_init();
    mosq_ = mosquitto_new(nullptr, true, this);
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

}  // namespace

TEST(GyrodMqtt, PublishesTheStatusAndEveryRateLineInOrderAndGoesOfflineAtAStop) {
  const int port = freeTcpPort();
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
  const int port = freeTcpPort();
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", mqttConfig(d, port));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient client((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(client.connected());
  ASSERT_TRUE(client.readLine());  // VERSION
  ASSERT_TRUE(client.send("{\"cmd\":\"watch\",\"enable\":true}\n"));
  for (int i = 0; i < 20; ++i) ASSERT_TRUE(client.readLine(5s)) << "no broker must not stop the socket";
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find("MQTT: cannot reach the broker at 127.0.0.1:" + std::to_string(port)), std::string::npos) << log;

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
