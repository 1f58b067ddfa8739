#include "daemon/mqtt_publisher.hpp"

#include <mosquitto.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
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
// Retries after 0.5 s, doubling to 30 s, each ±20 % so that a fleet of boards that lost the
// same broker does not come back to it in step.
constexpr double kFirstRetrySeconds = 0.5;
constexpr double kMaxRetrySeconds = 30.0;
constexpr double kRetryJitter = 0.2;
// qos 1 messages handed to libmosquitto and not yet acknowledged, at most: beyond it they wait
// in the publisher's buffer, which is bounded, instead of libmosquitto's queue, which is not.
// Also libmosquitto's in-flight window, so that it never queues behind it either.
constexpr std::size_t kMaxUnacknowledged = 1000;
// Where OpenSSL finds the system's CA certificates on Debian (ca-certificates).
constexpr const char* kSystemCaPath = "/etc/ssl/certs";
constexpr int kSslVerifyPeer = 1;
// Different causes of failure logged in one outage, at most (the last error is in STATUS).
constexpr std::size_t kMaxLoggedCauses = 8;  // OpenSSL's SSL_VERIFY_PEER, which mosquitto_tls_opts_set takes

// libmosquitto's global state, set up once per process.
void initialiseLibraryOnce() {
  static std::once_flag once;
  std::call_once(once, [] { mosquitto_lib_init(); });
}

// A libmosquitto error code for a person.
std::string describe(int rc) {
  if (rc == MOSQ_ERR_ERRNO) return std::strerror(errno);
  if (rc == MOSQ_ERR_KEEPALIVE)
    return "no answer from the broker within " + std::to_string(kKeepAliveSeconds) + " s (the keep-alive)";
  return mosquitto_strerror(rc);
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

MqttPublisher::MqttPublisher(MqttSettings settings, MqttDerivedSources sources)
    : settings_(std::move(settings)),
      status_topic_(settings_.prefix + "/" + std::string(protocol::kMqttStatusTopic)),
      rate_topic_(settings_.prefix + "/" + std::string(protocol::kMqttRateTopic)),
      gap_topic_(settings_.prefix + "/" + std::string(protocol::kMqttGapTopic)),
      effect_topic_(settings_.prefix + "/" + std::string(protocol::kMqttEffectTopic)),
      ring_(settings_.queue_lines),
      buffer_(settings_.qos == 1 ? settings_.buffer_messages : 0),
      jitter_(std::random_device{}()),
      derived_({settings_.prefix, settings_.client_id, settings_.device, settings_.home_assistant,
                settings_.home_assistant_prefix, settings_.orientation},
               std::move(sources)),
      wake_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {
  if (!wake_fd_) throw std::runtime_error("MQTT: no eventfd for the publisher's thread");
  initialiseLibraryOnce();
  // qos 1: a persistent session, so that the broker keeps what it has not acknowledged or
  // delivered across a lost connection; qos 0 promises nothing of the kind.
  const bool clean_session = settings_.qos != 1;
  mosq_ = mosquitto_new(settings_.client_id.c_str(), clean_session, this);
  if (mosq_ == nullptr) throw std::runtime_error("MQTT: libmosquitto cannot create a client");
  const std::string offline = R"({"state":"offline"})";
  mosquitto_will_set(mosq_, status_topic_.c_str(), static_cast<int>(offline.size()), offline.data(), 1, true);
  if (!settings_.username.empty())
    mosquitto_username_pw_set(mosq_, settings_.username.c_str(),
                              settings_.password.empty() ? nullptr : settings_.password.c_str());
  mosquitto_max_inflight_messages_set(mosq_, static_cast<unsigned>(kMaxUnacknowledged));
  setUpTls();
  mosquitto_connect_callback_set(mosq_, &MqttPublisher::onConnect);
  mosquitto_disconnect_callback_set(mosq_, &MqttPublisher::onDisconnect);
  mosquitto_publish_callback_set(mosq_, &MqttPublisher::onPublish);
  mosquitto_log_callback_set(mosq_, &MqttPublisher::onLog);
  thread_ = std::thread([this] { threadMain(); });
}

MqttPublisher::~MqttPublisher() {
  stop();
  mosquitto_destroy(mosq_);
  std::string* line = nullptr;
  while (effect_ring_.tryPop(line)) delete line;  // lines the thread did not take: the ring owns them
}

void MqttPublisher::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void MqttPublisher::setUpTls() {
  if (!settings_.tls) return;
  const auto orNull = [](const std::string& s) { return s.empty() ? nullptr : s.c_str(); };
  const char* ca_path = settings_.ca_file.empty() ? kSystemCaPath : nullptr;
  int rc = mosquitto_tls_set(mosq_, orNull(settings_.ca_file), ca_path, orNull(settings_.cert_file),
                             orNull(settings_.key_file), nullptr);
  if (rc == MOSQ_ERR_SUCCESS) rc = mosquitto_tls_opts_set(mosq_, kSslVerifyPeer, nullptr, nullptr);
  if (rc == MOSQ_ERR_SUCCESS) rc = mosquitto_tls_insecure_set(mosq_, false);  // the host name is checked too
  if (rc != MOSQ_ERR_SUCCESS) {
    mosquitto_destroy(mosq_);
    throw std::runtime_error(std::string("MQTT: libmosquitto refuses the TLS settings (mqtt.ca_file, cert_file, "
                                         "key_file): ") +
                             mosquitto_strerror(rc));
  }
}

void MqttPublisher::push(const LineForClients& line) noexcept {
  if (!ring_.tryPush(line)) dropped_.fetch_add(1, std::memory_order_relaxed);
}

void MqttPublisher::pushEffect(std::string_view line) noexcept {
  try {
    auto copy = std::make_unique<std::string>(line);
    if (effect_ring_.tryPush(copy.get()))
      (void)copy.release();  // the publisher's thread owns it now
    else
      effects_refused_.fetch_add(1, std::memory_order_relaxed);
  } catch (const std::bad_alloc&) {
    effects_refused_.fetch_add(1, std::memory_order_relaxed);
  }
}

void MqttPublisher::wake() noexcept {
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(wake_fd_.get(), &one, sizeof one);
}

MqttStats MqttPublisher::stats() const {
  MqttStats s{connected_.load(), published_.load(), buffered_.load(), dropped_.load(), connects_.load(), {}};
  const std::lock_guard lock(error_mutex_);
  s.last_error = last_error_;
  return s;
}

void MqttPublisher::setLastError(const std::string& why) {
  const std::lock_guard lock(error_mutex_);
  last_error_ = why;
}

// The callbacks run on the publisher's thread, inside mosquitto_loop and the connect calls.
void MqttPublisher::onConnect(mosquitto* /*mosq*/, void* self, int rc) {
  auto* p = static_cast<MqttPublisher*>(self);
  if (rc != 0) {  // libmosquitto closes the connection next; connectionFailed says why
    p->pending_cause_ = std::string("the broker refused the connection: ") + mosquitto_connack_string(rc);
    return;
  }
  p->connects_.fetch_add(1);
  p->connecting_ = false;
  p->connected_ = true;
  p->failures_ = 0;
  p->logged_causes_.clear();
  // Nothing is published from here: libmosquitto resends what it holds in flight after this
  // callback, and the buffer must go after those (sendBuffered, once mosquitto_loop returns).
  p->reportOutageOver();
}

void MqttPublisher::onDisconnect(mosquitto* /*mosq*/, void* self, int rc) {
  auto* p = static_cast<MqttPublisher*>(self);
  if (rc != 0 && p->pending_cause_.empty()) p->pending_cause_ = describe(rc);
  if (rc != 0) p->disconnected_ = true;
}

void MqttPublisher::onPublish(mosquitto* /*mosq*/, void* self, int mid) {
  auto* p = static_cast<MqttPublisher*>(self);
  if (mid == p->last_status_mid_.load()) p->last_status_sent_ = true;
  if (p->unacknowledged_ > 0) --p->unacknowledged_;  // qos 1: the broker's PUBACK
}

void MqttPublisher::onLog(mosquitto* /*mosq*/, void* self, int level, const char* text) {
  // libmosquitto reports why a TLS handshake failed only here ("OpenSSL Error[0]: ...").
  auto* p = static_cast<MqttPublisher*>(self);
  constexpr std::string_view openssl = "OpenSSL Error";
  const std::string_view t(text);
  if (level != MOSQ_LOG_ERR || t.rfind(openssl, 0) != 0 || !p->pending_cause_.empty()) return;
  const auto colon = t.find(": ");
  p->pending_cause_ = "TLS handshake failed: " + std::string(colon == std::string_view::npos ? t : t.substr(colon + 2));
}

void MqttPublisher::reportOutageOver() {
  if (!in_outage_) {
    spdlog::info("MQTT: connected to {}:{} as {}; publishing under {}/", settings_.host, settings_.port,
                 settings_.client_id, settings_.prefix);
    return;
  }
  in_outage_ = false;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - outage_start_).count();
  spdlog::info(
      "MQTT: connected to {}:{} as {} after {:.1f} s without the broker; {} messages kept meanwhile are sent now, {} "
      "dropped",
      settings_.host, settings_.port, settings_.client_id, seconds, outage_buffered_,
      dropped_.load() - outage_dropped_start_);
}

void MqttPublisher::connectionFailed(const std::string& why) {
  const auto now = std::chrono::steady_clock::now();
  const std::string cause = pending_cause_.empty() ? why : pending_cause_;
  pending_cause_.clear();
  disconnected_ = false;
  connecting_ = false;
  const bool was_connected = connected_.exchange(false);
  setLastError(cause);
  if (!in_outage_) {
    in_outage_ = true;
    outage_start_ = now;
    outage_dropped_start_ = dropped_.load();
    outage_buffered_ = 0;
  }
  const std::string keeping = settings_.qos == 1 && settings_.buffer_messages > 0
                                  ? "keeping up to " + std::to_string(settings_.buffer_messages) + " messages"
                                  : "dropping the messages meanwhile";
  // Each cause once per outage: the retries go on for as long as the broker is away, and a
  // cause that comes and goes (a handshake that times out now and then) is not news either.
  const bool new_cause = std::find(logged_causes_.begin(), logged_causes_.end(), cause) == logged_causes_.end();
  if (was_connected && !stop_) {
    spdlog::warn("MQTT: lost the broker at {}:{} ({}); reconnecting, {}", settings_.host, settings_.port, cause,
                 keeping);
  } else if (new_cause && logged_causes_.size() < kMaxLoggedCauses && !stop_) {
    spdlog::warn("MQTT: cannot connect to the broker at {}:{}: {}; streaming on the socket and retrying, {}",
                 settings_.host, settings_.port, cause, keeping);
  }
  if (new_cause && logged_causes_.size() < kMaxLoggedCauses) logged_causes_.push_back(cause);
  ++failures_;
  const double base = std::min(kMaxRetrySeconds, kFirstRetrySeconds * std::pow(2.0, std::min(failures_ - 1, 16)));
  const double factor = std::uniform_real_distribution<double>(1.0 - kRetryJitter, 1.0 + kRetryJitter)(jitter_);
  next_attempt_ = now + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(base * factor));
}

void MqttPublisher::publishStatus(const char* state) {
  std::string s = std::string(R"({"state":")") + state + R"(","device":)" + jsonString(settings_.device) +
                  R"(,"rate_hz":)" + formats::shortest(settings_.rate_hz) + R"(,"samples":)" +
                  std::to_string(samples_seen_) + R"(,"gaps":)" + std::to_string(gaps_seen_) + R"(,"samples_lost":)" +
                  std::to_string(samples_lost_) + R"(,"mqtt_buffered":)" + std::to_string(buffer_.size()) +
                  R"(,"mqtt_dropped":)" + std::to_string(dropped_.load()) + "}";
  int mid = 0;
  if (mosquitto_publish(mosq_, &mid, status_topic_.c_str(), static_cast<int>(s.size()), s.data(), 1, true) ==
      MOSQ_ERR_SUCCESS) {
    last_status_mid_ = mid;
    published_.fetch_add(1, std::memory_order_relaxed);
    if (settings_.qos == 1) ++unacknowledged_;
  }
}

// A line from the ring: counted, then sent, kept for the broker (qos 1) or dropped.
void MqttPublisher::takeLine(const LineForClients& line) {
  if (line.kind == LineForClients::Kind::Rate) {
    derived_.take(line.rate);
    ++samples_seen_;
    if ((samples_seen_ - 1) % settings_.rate_every != 0) return;
  } else {
    ++gaps_seen_;
    samples_lost_ += line.gap_count;
  }
  if (settings_.qos == 1 && settings_.buffer_messages > 0) {
    if (!buffer_.pushBack(line)) dropped_.fetch_add(1, std::memory_order_relaxed);  // the oldest went
    if (!connected_) ++outage_buffered_;
    buffered_.store(buffer_.size(), std::memory_order_relaxed);
    return;
  }
  // Nothing formatted or queued for a broker that is not there, or (qos 1 without a buffer)
  // past what libmosquitto may hold unacknowledged.
  const bool room = settings_.qos == 0 || unacknowledged_ < kMaxUnacknowledged;
  if (!connected_ || !room || !publishLine(line)) dropped_.fetch_add(1, std::memory_order_relaxed);
}

bool MqttPublisher::publishLine(const LineForClients& line) {
  const bool rate = line.kind == LineForClients::Kind::Rate;
  std::array<char, protocol::kMaxRateLineBytes> buffer;
  std::array<char, protocol::kMaxGapLineBytes> gap_buffer;
  char* text = rate ? buffer.data() : gap_buffer.data();
  std::size_t n = rate
                      ? protocol::formatRateLine(line.rate, buffer)
                      : protocol::formatGapLine(
                            {line.gap_first_seq, line.gap_count, std::string_view(line.gap_reason.data())}, gap_buffer);
  if (n > 0 && text[n - 1] == '\n') --n;  // a message is one JSON object, without the line's newline
  const std::string& topic = rate ? rate_topic_ : gap_topic_;
  if (mosquitto_publish(mosq_, nullptr, topic.c_str(), static_cast<int>(n), text, settings_.qos, false) !=
      MOSQ_ERR_SUCCESS)
    return false;
  published_.fetch_add(1, std::memory_order_relaxed);
  if (settings_.qos == 1) ++unacknowledged_;
  return true;
}

// The EFFECT lines from the sample thread, kept until the broker has them. Kept whatever qos
// says: they are few, and each is news a fleet's dashboard would otherwise miss.
void MqttPublisher::takeEffects() {
  std::string* line = nullptr;
  while (effect_ring_.tryPop(line)) {
    const std::unique_ptr<std::string> owned(line);
    if (effects_kept_.size() == kMaxKeptEffects) {
      effects_kept_.pop_front();
      spdlog::warn("MQTT: {} EFFECT lines wait for the broker; the oldest is dropped", kMaxKeptEffects);
    }
    effects_kept_.push_back(std::move(*owned));
  }
  const std::uint64_t refused = effects_refused_.load(std::memory_order_relaxed);
  if (refused != effects_refused_logged_) {
    spdlog::warn("MQTT: {} EFFECT line(s) could not be handed to the publisher and are not published",
                 refused - effects_refused_logged_);
    effects_refused_logged_ = refused;
  }
}

// QoS 1: every change reaches a subscriber at least once. Not retained: a topic keeps only its
// last message, which would show a later subscriber one change of one effect (a "gone", say)
// as if it were the board's state; what is named now is STATUS's live_check and the socket's
// "effects" reply.
void MqttPublisher::sendEffects() {
  while (connected_ && !effects_kept_.empty()) {
    const std::string& e = effects_kept_.front();
    if (mosquitto_publish(mosq_, nullptr, effect_topic_.c_str(), static_cast<int>(e.size()), e.data(), 1, false) !=
        MOSQ_ERR_SUCCESS)
      break;  // kept: the connection is being lost
    published_.fetch_add(1, std::memory_order_relaxed);
    if (settings_.qos == 1) ++unacknowledged_;
    effects_kept_.pop_front();
  }
}

// The buffer, oldest first, as far as the broker keeps up with its acknowledgements.
void MqttPublisher::sendBuffered() {
  while (connected_ && !buffer_.empty() && unacknowledged_ < kMaxUnacknowledged) {
    if (!publishLine(buffer_.front())) break;  // kept: the connection is being lost
    buffer_.popFront();
  }
  buffered_.store(buffer_.size(), std::memory_order_relaxed);
}

void MqttPublisher::attemptConnection(std::chrono::steady_clock::time_point now) {
  if (connected_ || connecting_ || now < next_attempt_) return;
  pending_cause_.clear();
  errno = 0;
  const int rc = attempted_ ? mosquitto_reconnect_async(mosq_)
                            : mosquitto_connect_async(mosq_, settings_.host.c_str(), settings_.port, kKeepAliveSeconds);
  connect_errno_ = errno;
  attempted_ = true;
  if (rc == MOSQ_ERR_SUCCESS) {
    connecting_ = true;
  } else {
    connectionFailed(describe(rc));
  }
}

// A connection being made: libmosquitto 2.0 does not notice a TCP connection that failed
// under TLS (its handshake swallows the error and it waits for the keep-alive to end), so a
// socket that hung up before the broker answered is a failure here. Its cause is what errno
// said right after the connect call, when that is a connection error. False when it failed.
bool MqttPublisher::checkConnecting() {
  const int sock = mosquitto_socket(mosq_);
  if (sock < 0) return true;
  pollfd p{sock, POLLOUT, 0};
  if (::poll(&p, 1, 0) != 1 || (p.revents & (POLLHUP | POLLERR)) == 0) return true;
  const int e = connect_errno_;
  const bool known = e == ECONNREFUSED || e == ECONNRESET || e == ETIMEDOUT || e == EHOSTUNREACH || e == ENETUNREACH;
  connectionFailed(known ? std::strerror(e) : "the connection was closed before the broker answered");
  return false;
}

// Until the broker's socket has something to read (or room for what libmosquitto wants to
// write), the sample thread hands over lines, or kIdleWait passes: lines leave as soon as they
// come, and an idle gyrod wakes a few times a second for the keep-alive.
void MqttPublisher::waitForNetworkOrLines() {
  std::array<pollfd, 2> fds{};
  fds[0] = {wake_fd_.get(), POLLIN, 0};
  nfds_t n = 1;
  if (const int sock = mosquitto_socket(mosq_); sock >= 0)
    fds[n++] = {sock, static_cast<short>(POLLIN | (mosquitto_want_write(mosq_) ? POLLOUT : 0)), 0};
  if (::poll(fds.data(), n, static_cast<int>(kIdleWait.count())) > 0 && (fds[0].revents & POLLIN) != 0) {
    std::uint64_t count = 0;
    [[maybe_unused]] const ssize_t r = ::read(wake_fd_.get(), &count, sizeof count);
  }
}

void MqttPublisher::runLoop() {
  if (connecting_ && !connected_ && !checkConnecting()) return;
  waitForNetworkOrLines();
  const int rc = mosquitto_loop(mosq_, 0, 1);  // what the wait found: read, write, keep-alive
  if (rc != MOSQ_ERR_SUCCESS) {                // refused, lost or never made: try again later
    connectionFailed(describe(rc));
  } else if (disconnected_) {
    connectionFailed("the connection was closed");
  }
}

void MqttPublisher::publishDerived(bool just_connected) {
  const double now = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  for (const MqttMessage& m : derived_.due(now, just_connected))
    if (mosquitto_publish(mosq_, nullptr, m.topic.c_str(), static_cast<int>(m.payload.size()), m.payload.data(), m.qos,
                          m.retain) == MOSQ_ERR_SUCCESS)
      published_.fetch_add(1, std::memory_order_relaxed);
}

void MqttPublisher::threadMain() {
  // Never in competition with the sample loop, which may run SCHED_FIFO.
  const sched_param normal{};
  ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &normal);
  // The client is driven from here (mosquitto_loop): DNS, TLS, connect and every send happen
  // on this thread, and libmosquitto's callbacks run on it.
  bool was_connected = false;
  auto next_status = std::chrono::steady_clock::now();
  LineForClients line;
  while (!stop_) {
    const auto now = std::chrono::steady_clock::now();
    attemptConnection(now);
    const bool connected = connected_.load();
    if (connected && (!was_connected || now >= next_status)) {
      publishStatus("online");
      next_status = now + kStatusEvery;
    }
    while (ring_.tryPop(line)) takeLine(line);
    takeEffects();
    sendBuffered();
    sendEffects();
    if (connected) publishDerived(!was_connected);
    was_connected = connected;
    if (connected_ || connecting_) {
      runLoop();
    } else {
      std::this_thread::sleep_for(kIdleWait);
    }
  }
  stopCleanly();
}

void MqttPublisher::stopCleanly() {
  if (!connected_) return;
  // A clean stop: say so, and give it a moment to leave.
  last_status_sent_ = false;
  publishStatus("offline");
  const auto until = std::chrono::steady_clock::now() + kOfflineWait;
  while (!last_status_sent_ && connected_ && std::chrono::steady_clock::now() < until)
    if (mosquitto_loop(mosq_, static_cast<int>(kIdleWait.count()), 1) != MOSQ_ERR_SUCCESS) break;
  mosquitto_disconnect(mosq_);
  mosquitto_loop(mosq_, static_cast<int>(kIdleWait.count()), 1);  // the DISCONNECT out
}

}  // namespace gyrod::daemon
