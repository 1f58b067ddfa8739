#pragma once
// The client side of gyrod: a Unix stream socket, many non-blocking clients, the protocol
// of protocol/protocol.hpp, and a bounded output buffer per client.
//
// Backpressure policy (gpsd's weakness to avoid: slow clients silently losing data): each
// client has a preallocated output buffer of ServerOptions::client_buffer_bytes.
//  - RATE and GAP lines: a line that does not fit means the client has stopped reading for
//    longer than the buffer covers (256 KiB: 750–1 300 RATE lines of 200–350 bytes, 15–25 s
//    at 50 Hz): it is disconnected, logged and counted (STATUS: clients_dropped,
//    lines_dropped). No client ever sees a gap because of another client.
//  - Replies to requests: a reply that does not fit (a watching client keeps a quarter of
//    its buffer for RATE lines) is held, and the client's input is not read until its
//    output drains enough to take it: a client that pipelines requests faster than it reads
//    replies is slowed down, not dropped. Only a client whose held reply has waited
//    ServerOptions::stalled_reply_timeout without any byte of output leaving is dropped.
//  - The event loop never waits on a client: each turn a client gets at most
//    ServerOptions::max_requests_per_turn requests answered; the rest of its input is read
//    and answered on later turns (EventLoop::defer).
//  - Requests together take at most ServerOptions::request_cpu_share of a CPU over time
//    (a token bucket of the loop thread's CPU time spent answering, at most
//    kMaxRequestTimeBanked banked): past it, they wait for a timer while RATE and GAP lines
//    go on, and a flood never takes the whole CPU the server's thread runs on.
// A dropped client has received a prefix of its stream; its last line may be incomplete if
// the kernel had taken part of it (docs/protocol.md: a line without its newline at EOF is
// to be discarded).
//
// Threads: everything but publishRate and publishGap runs on the loop's thread. With
// ServerOptions::publish_off_loop, those two run on another thread (gyrod's delivery thread)
// and only move lines into the watching clients' buffers and sockets: each client's buffer,
// counts and sends are guarded by a priority-inheritance mutex of its own, the client list by
// another (held for one publish pass, and by the loop's thread while it adds or removes a
// client). What a publish finds for the loop's thread to do (a client to drop for a full
// buffer, a socket to watch for EPOLLOUT, a failed send) it flags on the client and signals
// through an eventfd the loop watches; it never calls into the loop itself.
#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/event_loop.hpp"
#include "daemon/priority_inheritance_mutex.hpp"
#include "protocol/fd.hpp"
#include "protocol/protocol.hpp"
#include "protocol/socket_path.hpp"

namespace gyrod::daemon {

// The server speaks in the protocol's types.
using protocol::AllanReport;
using protocol::ClientStatus;
using protocol::GapEvent;
using protocol::RateSample;
using protocol::ServerStatus;
using protocol::StatusReport;

// FileDescriptorName= of the socket unit that gyrod takes when systemd passes several.
inline constexpr const char* kActivatedSocketName = "gyrod";

struct SocketOptions {
  std::string path = protocol::kDefaultSocketPath;
  mode_t mode = 0660;                // permission bits of the socket file (connect needs w)
  std::optional<std::string> group;  // group owning the socket file (name); none: keep ours
};

// A listening socket and, when we bound it ourselves, the file to remove at exit.
struct ListeningSocket {
  Fd fd;
  std::string path;  // empty when adopted from systemd (systemd owns the file)
  dev_t device = 0;  // identity of the file we bound, so that we never remove
  ino_t inode = 0;   //   a socket that another process bound there later
  bool activated = false;
};

// Binds options.path: creates missing parent folders (0755), replaces a stale socket file
// (one nobody listens on: connect() is refused), refuses a live one (std::runtime_error:
// "already in use") and anything that is not a socket; the file is never more permissive
// than 0600 before mode and group are applied. Throws std::invalid_argument for a path too
// long for sockaddr_un, mode bits outside 0777 or an unknown group; std::system_error when
// a system call fails (the message names the call and the path).
ListeningSocket bindListeningSocket(const SocketOptions& options);

// The socket passed by systemd socket activation (sd_listen_fds_with_names), if any: the
// one named `name` (FileDescriptorName=), or the only one when exactly one is passed.
// Throws std::runtime_error when fds were passed but none fits, or the chosen one is not
// a listening Unix stream socket. Other passed fds are left alone. The environment
// (LISTEN_FDS, ...) is left set so that other names can still be looked up.
std::optional<ListeningSocket> adoptActivatedSocket(std::string_view name = kActivatedSocketName);

// Socket activation if systemd passed a socket, otherwise bindListeningSocket(options).
ListeningSocket openListeningSocket(const SocketOptions& options);

// O_NONBLOCK and FD_CLOEXEC on `fd`; throws std::system_error.
void setNonBlockingCloseOnExec(int fd);

// What the daemon answers to "allan", "status" and "effects". Not on the per-sample path: may
// allocate. An exception thrown here becomes an ERROR "internal" line for that client.
class ServerContent {
 public:
  virtual ~ServerContent() = default;
  virtual AllanReport allanReport() = 0;
  // The whole ALLAN reply line. By default allanReport() formatted on each request; gyrod
  // serves a line cached at each noise refit instead (daemon/allan_reply_cache.hpp).
  virtual std::string allanReplyLine() { return protocol::allanLine(allanReport()); }
  virtual StatusReport statusReport() = 0;
  // The reply to "effects": by default what statusReport() says of the live check; gyrod reads
  // only the live check's part, under the lock STATUS takes, and says why it is off.
  virtual protocol::EffectsReport effectsReport() {
    return protocol::effectsReportOf(statusReport().live_check, "the daemon does not run the live check");
  }
};

struct ServerOptions {
  std::string release = GYROD_RELEASE;           // VERSION "release" (the project version)
  std::size_t client_buffer_bytes = 256 * 1024;  // per client, preallocated
  std::size_t max_clients = 32;                  // more are refused with ERROR too_many_clients
  std::size_t max_requests_per_turn = 16;        // per client per loop turn; the rest waits
  double request_cpu_share = 1.0;                // of one CPU, for all requests; 1: no limit
  // A client whose reply has waited this long for room, with none of its output read
  // meanwhile, is dropped as not reading.
  std::chrono::milliseconds stalled_reply_timeout = std::chrono::seconds(10);
  // publishRate and publishGap are called from another thread than the loop's: what they
  // leave for the loop's thread reaches it through an eventfd. false: they are called on the
  // loop's thread, and do it before they return.
  bool publish_off_loop = false;
};

class UnixSocketServer {
 public:
  // Serves `listening` on `loop`; `content` must outlive the server. Throws
  // std::invalid_argument for client_buffer_bytes < 4096 or max_clients = 0.
  UnixSocketServer(EventLoop& loop, ListeningSocket listening, ServerContent& content, ServerOptions options = {});
  // Disconnects every client and removes the socket file if it is still the one bound.
  ~UnixSocketServer();
  UnixSocketServer(const UnixSocketServer&) = delete;
  UnixSocketServer& operator=(const UnixSocketServer&) = delete;

  // Per sample: formats one RATE line into a stack buffer and copies it into the buffer of
  // each watching client whose decimation is due, and sends it when that client's socket is
  // not known to be full. Allocates nothing (a client dropped for a full buffer frees its
  // memory and logs, on the loop's thread, which is not the steady state). On the loop's
  // thread, or on one other thread with ServerOptions::publish_off_loop.
  void publishRate(const RateSample& sample);
  // A GAP line to every watching client, whatever its decimation. Throws
  // std::invalid_argument for a malformed gap (see formatGapLine). As publishRate.
  void publishGap(const GapEvent& gap);
  // An EFFECT line (with its newline) to every watching client, whatever its decimation. As
  // publishRate.
  void publishEffect(std::string_view line);

  // The loop's thread only.
  ServerStatus serverStatus() const;
  std::size_t clientCount() const noexcept { return clients_.size(); }
  std::size_t watcherCount() const noexcept;
  const std::string& socketPath() const noexcept { return listening_.path; }

 private:
  struct Client;

  void onListenerReadable();
  void acceptClient(Fd fd);
  void onClientEvents(Client& c, std::uint32_t events);
  // Answers at most max_requests_per_turn requests of c, reading its socket as needed,
  // when the requests' CPU share allows; otherwise defers c.
  void serveRequests(Client& c);
  void answerRequests(Client& c);
  // Earns request time since the last call; true when some is left.
  bool requestTimeLeft();
  void deferRequests(Client& c);
  void serveDeferredRequests();
  void handleLine(Client& c, std::string_view line);
  // A reply goes into c's buffer if it fits, else it is held and c's input pauses. A WATCH
  // request's settings (`watch`) take effect in the same step as its reply is queued.
  void queueReply(Client& c, std::string reply, const protocol::WatchRequest* watch = nullptr);
  // Appends a whole line to c's buffer, or drops c if it does not fit.
  void queueLine(Client& c, const char* data, std::size_t size);
  void queueLine(Client& c, const std::string& line) { queueLine(c, line.data(), line.size()); }
  void flush(Client& c);
  void updateInterest(Client& c);
  void beginClose(Client& c);
  void dropSlowClient(Client& c, std::size_t line_size);
  void armStallCheck(std::chrono::nanoseconds delay);
  void dropStalledClients();
  void reapDeadClients();
  ServerStatus serverStatusFor(const Client* self) const;
  // The publishing side: one line to every watching client; true when a client was flagged
  // for the loop's thread.
  void publishLine(const char* data, std::size_t size, bool decimated);
  bool deliverLine(Client& c, const char* data, std::size_t size, bool decimated);
  // The loop's thread: acts on what publishing flagged on the clients.
  void serviceDeliveryFlags();

  EventLoop& loop_;
  ListeningSocket listening_;
  ServerContent& content_;
  ServerOptions options_;
  // Written by the loop's thread under clients_mutex_, read by the publishing thread under it.
  std::vector<std::unique_ptr<Client>> clients_;
  PriorityInheritanceMutex clients_mutex_;
  std::vector<std::unique_ptr<Client>> reaped_;  // the loop's thread: removed, not yet destroyed
  Fd delivery_flags_fd_;                         // eventfd: publishing flagged a client
  std::uint64_t next_client_id_ = 1;
  std::uint64_t clients_total_ = 0;
  std::uint64_t clients_dropped_ = 0;
  std::uint64_t lines_dropped_ = 0;
  std::optional<EventLoop::SourceId> accept_pause_timer_;
  std::optional<EventLoop::SourceId> stall_check_timer_;
  bool deferred_requests_pending_ = false;
  std::size_t deferred_pass_start_ = 0;
  static constexpr std::chrono::nanoseconds kMaxRequestTimeBanked = std::chrono::milliseconds(2);
  std::chrono::nanoseconds request_time_left_ = kMaxRequestTimeBanked;
  std::chrono::steady_clock::time_point request_time_refilled_ = std::chrono::steady_clock::now();
  // Deferred callbacks may outlive the server in the loop: they check this first.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace gyrod::daemon
