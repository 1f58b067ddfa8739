// gyroctl fleet: every gyrod that publishes to one MQTT broker, a row per board, live
// (docs/fleet.md). Subscribes to <root>/+/status, rate and gap; the table is
// tools/gyroctl/fleet_table.*.
#include <mosquitto.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>

#include "formats/input_file.hpp"
#include "protocol/mqtt_url.hpp"
#include "tools/gyroctl/commands.hpp"
#include "tools/gyroctl/fleet_table.hpp"

namespace gyrod::gyroctl {
namespace {

constexpr int kKeepAliveSeconds = 10;
constexpr int kLoopWaitMs = 100;
constexpr auto kRetryEvery = std::chrono::seconds(2);

struct FleetOptions {
  std::string broker = "mqtt://localhost";
  std::string root = "gyrod";
  std::string username, password_file, ca_file;
  bool json = false, once = false;
  double wait_s = 2.0, interval_s = 1.0;
  std::optional<std::uint64_t> count;
};

double monotonicSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string readPassword(const std::string& path) {
  std::string p = formats::readInputFile(path, formats::kCredentialInput);
  while (!p.empty() && (p.back() == '\n' || p.back() == '\r')) p.pop_back();
  return p;
}

// The subscriber: libmosquitto driven from this thread (mosquitto_loop), its callbacks feeding
// the table.
class FleetSubscriber {
 public:
  FleetSubscriber(const FleetOptions& opt, FleetTable& table) : opt_(opt), table_(table) {
    mosquitto_lib_init();
    mosq_ = mosquitto_new(nullptr, true, this);
    if (mosq_ == nullptr) throw std::runtime_error("fleet: libmosquitto cannot create a client");
    mosquitto_connect_callback_set(mosq_, &FleetSubscriber::onConnect);
    mosquitto_message_callback_set(mosq_, &FleetSubscriber::onMessage);
  }
  ~FleetSubscriber() {
    mosquitto_disconnect(mosq_);
    mosquitto_destroy(mosq_);
    mosquitto_lib_cleanup();
  }
  FleetSubscriber(const FleetSubscriber&) = delete;
  FleetSubscriber& operator=(const FleetSubscriber&) = delete;

  // Connects (blocking: a command-line tool may wait for DNS). Throws ExitError 69 with the
  // broker's address and the cause.
  void connect(const protocol::MqttBrokerAddress& address) {
    address_ = address;
    if (!opt_.username.empty())
      mosquitto_username_pw_set(mosq_, opt_.username.c_str(),
                                opt_.password_file.empty() ? nullptr : readPassword(opt_.password_file).c_str());
    if (address.tls) {
      const int rc = opt_.ca_file.empty()
                         ? mosquitto_tls_set(mosq_, nullptr, "/etc/ssl/certs", nullptr, nullptr, nullptr)
                         : mosquitto_tls_set(mosq_, opt_.ca_file.c_str(), nullptr, nullptr, nullptr, nullptr);
      if (rc != MOSQ_ERR_SUCCESS) fail(std::string("TLS set-up: ") + mosquitto_strerror(rc));
    }
    const int rc = mosquitto_connect(mosq_, address.host.c_str(), address.port, kKeepAliveSeconds);
    if (rc != MOSQ_ERR_SUCCESS) fail(rc == MOSQ_ERR_ERRNO ? std::strerror(errno) : mosquitto_strerror(rc));
  }

  // Runs the client for up to `seconds`; after a lost connection, tries again every 2 s.
  void run(double seconds) {
    const double until = monotonicSeconds() + seconds;
    while (monotonicSeconds() < until) {
      if (refused_) fail("the broker refused the connection: " + refused_reason_);
      if (mosquitto_loop(mosq_, kLoopWaitMs, 1) != MOSQ_ERR_SUCCESS) {
        if (!lost_) std::fprintf(stderr, "gyroctl: fleet: lost the broker; reconnecting\n");
        lost_ = true;
        std::this_thread::sleep_for(kRetryEvery);
        mosquitto_reconnect(mosq_);
      }
    }
  }
  bool subscribed() const { return subscribed_; }

 private:
  [[noreturn]] void fail(const std::string& cause) const {
    throw ExitError(ExitCode::Unavailable, "fleet: cannot read the broker at " + address_.host + ":" +
                                               std::to_string(address_.port) + ": " + cause);
  }
  static void onConnect(mosquitto* mosq, void* self, int rc) {
    auto* s = static_cast<FleetSubscriber*>(self);
    if (rc != 0) {
      s->refused_ = true;
      s->refused_reason_ = mosquitto_connack_string(rc);
      return;
    }
    if (s->lost_) std::fprintf(stderr, "gyroctl: fleet: connected to the broker again\n");
    s->lost_ = false;
    for (const auto& filter : {s->table_.statusFilter(), s->table_.rateFilter(), s->table_.gapFilter()})
      mosquitto_subscribe(mosq, nullptr, filter.c_str(), 0);
    s->subscribed_ = true;
  }
  static void onMessage(mosquitto* /*mosq*/, void* self, const mosquitto_message* m) {
    auto* s = static_cast<FleetSubscriber*>(self);
    s->table_.take(m->topic,
                   std::string_view(static_cast<const char*>(m->payload), static_cast<std::size_t>(m->payloadlen)),
                   monotonicSeconds());
  }

  const FleetOptions& opt_;
  FleetTable& table_;
  protocol::MqttBrokerAddress address_;
  mosquitto* mosq_ = nullptr;
  bool refused_ = false, lost_ = false, subscribed_ = false;
  std::string refused_reason_;
};

int runFleet(const FleetOptions& opt) {
  protocol::MqttBrokerAddress address;
  try {
    address = protocol::parseMqttUrl(opt.broker);
  } catch (const std::invalid_argument& e) {
    throw ExitError(ExitCode::Usage, "--broker '" + opt.broker + "': " + e.what());
  }
  FleetTable table(opt.root);
  FleetSubscriber subscriber(opt, table);
  subscriber.connect(address);
  const bool redraw = !opt.json && !opt.once && ::isatty(STDOUT_FILENO) == 1;
  std::uint64_t shown = 0;
  subscriber.run(opt.once ? opt.wait_s : opt.interval_s);
  for (;;) {
    const double now = monotonicSeconds();
    if (redraw) std::fputs("\033[H\033[2J", stdout);
    std::fputs(opt.json ? (table.json(now) + "\n").c_str() : table.text(now).c_str(), stdout);
    if (!opt.json && !redraw) std::fputs("\n", stdout);
    std::fflush(stdout);
    if (opt.once || (opt.count && ++shown >= *opt.count)) break;
    subscriber.run(opt.interval_s);
  }
  return kExitOk;
}

}  // namespace

void addFleetCommand(CLI::App& app, CommandRunner& run) {
  auto opt = std::make_shared<FleetOptions>();
  CLI::App* sub = app.add_subcommand(
      "fleet", "every gyrod publishing to an MQTT broker, a row per board (state, rate, bias, temperature, losses)");
  sub->add_option("--broker", opt->broker, "the broker: mqtt://HOST[:PORT] or mqtts://HOST[:PORT]")
      ->envname("GYROD_MQTT_BROKER")
      ->default_val("mqtt://localhost");
  sub->add_option("--root", opt->root, "the topic levels before each board's name (gyrod's prefix is ROOT/BOARD)")
      ->default_val("gyrod");
  sub->add_option("--username", opt->username, "the broker's user name");
  sub->add_option("--password-file", opt->password_file, "a file holding the password (one line)")
      ->needs(sub->get_option("--username"));
  sub->add_option("--ca-file", opt->ca_file,
                  "for mqtts://: the CA certificate (PEM) to verify the broker with "
                  "(default: the system's, /etc/ssl/certs)");
  sub->add_flag("--json", opt->json, "one JSON object per refresh, {\"boards\":[...]}, instead of the table");
  sub->add_flag("--once", opt->once, "print the boards once, after --wait seconds, and exit");
  sub->add_option("--wait", opt->wait_s, "with --once: seconds to listen first (retained status comes at once)")
      ->check(CLI::Range(0.1, 3600.0))
      ->default_val(2.0);
  sub->add_option("--interval", opt->interval_s, "seconds between refreshes")
      ->check(CLI::Range(0.1, 3600.0))
      ->default_val(1.0);
  sub->add_option("--count", opt->count, "stop after N refreshes")->check(CLI::PositiveNumber);
  sub->callback([opt, &run] { run = [opt] { return runFleet(*opt); }; });
}

}  // namespace gyrod::gyroctl
