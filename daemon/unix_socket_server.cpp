#include "daemon/unix_socket_server.hpp"

#include "daemon/client_output_buffer.hpp"

#include <fcntl.h>
#include <grp.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <sys/un.h>
#include <systemd/sd-daemon.h>

#include <spdlog/spdlog.h>
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <stdexcept>

namespace gyrod::daemon {

// The server side of the protocol: its requests, replies and limits are used throughout.
using namespace protocol;
namespace {

// The CPU time this thread has used: what the requests are charged, so that the time the
// thread waits (preempted by the real-time threads, or for a client's mutex) is not counted.
std::chrono::nanoseconds threadCpuTime() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
}

constexpr int kMaxAcceptsPerWake = 16;
constexpr int kMaxReadsPerWake = 8;
constexpr std::size_t kMinClientBufferBytes = 4096;
// Room for the longest accepted line plus "\r\n".
constexpr std::size_t kInputBufferBytes = kMaxRequestLineBytes + 2;

std::int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

enum class SendResult { Drained, Blocked, Failed };

}  // namespace

// ---- clients -------------------------------------------------------------------------------

// Owned by the loop's thread, except what `mutex` guards (shared with the publishing thread)
// and the atomic flags.
struct UnixSocketServer::Client {
  Client(Fd f, std::uint64_t i, std::size_t buffer_bytes)
      : fd(std::move(f)), id(i), in(new char[kInputBufferBytes]), out(buffer_bytes) {}
  Fd fd;
  std::uint64_t id;
  std::optional<std::int64_t> pid, uid;
  std::unique_ptr<char[]> in;
  std::size_t in_start = 0;  // first byte of in not yet handled
  std::size_t in_used = 0;
  bool deferred = false;           // requests left for a later turn (input not watched meanwhile)
  std::uint32_t events = EPOLLIN;  // the epoll events requested now
  std::string held_reply;          // a reply waiting for room in out (input paused meanwhile)

  // Guards out, every send on fd and the fields below it; watch and closing change under it.
  PriorityInheritanceMutex mutex;
  ClientOutputBuffer out;
  std::uint32_t decimate = 1;
  std::uint32_t countdown = 0;        // RATE lines to skip before the next one is sent
  std::int64_t last_progress_ns = 0;  // when a reply was held or output last left
  std::uint64_t lines_queued = 0;
  std::uint64_t lines_sent = 0;
  std::size_t drop_line_bytes = 0;  // the line that did not fit (with drop_requested)

  // Written by the loop's thread (watch and closing under mutex), read by the publishing one.
  std::atomic<bool> watch{false};
  std::atomic<bool> closing{false};  // no more input; close once the output is flushed
  std::atomic<bool> dead{false};     // to be removed by reapDeadClients()
  // Set by the publishing thread for the loop's thread (delivery_flags_fd_).
  std::atomic<bool> drop_requested{false};  // a line did not fit: drop the client
  std::atomic<bool> wants_output{false};    // bytes left in out: watch for EPOLLOUT
  std::atomic<bool> send_failed{false};     // EPIPE, ECONNRESET: the client has gone

  // Sends what out holds until the socket takes no more. Under mutex.
  SendResult sendBuffered() {
    std::array<iovec, 2> iov{};
    bool progress = false;
    SendResult result = SendResult::Drained;
    while (!out.empty()) {
      msghdr msg{};
      msg.msg_iov = iov.data();
      msg.msg_iovlen = static_cast<std::size_t>(out.pieces(iov));
      const ssize_t n = ::sendmsg(fd.get(), &msg, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n > 0) {
        lines_sent += out.consume(static_cast<std::size_t>(n));
        progress = true;
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      result = n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK) ? SendResult::Blocked : SendResult::Failed;
      break;
    }
    if (progress) last_progress_ns = steadyNowNs();
    return result;
  }
};

UnixSocketServer::UnixSocketServer(EventLoop& loop, ListeningSocket listening, ServerContent& content,
                                   ServerOptions options)
    : loop_(loop), listening_(std::move(listening)), content_(content), options_(std::move(options)) {
  if (!listening_.fd) throw std::invalid_argument("the socket server needs a listening socket; none given");
  if (options_.client_buffer_bytes < kMinClientBufferBytes)
    throw std::invalid_argument("the socket server's client buffer of " + std::to_string(options_.client_buffer_bytes) +
                                " bytes is below the minimum of " + std::to_string(kMinClientBufferBytes) + " bytes");
  if (options_.max_clients == 0)
    throw std::invalid_argument("the socket server needs room for at least 1 client, got 0");
  if (!(options_.request_cpu_share > 0.0 && options_.request_cpu_share <= 1.0))
    throw std::invalid_argument("the socket server's request CPU share must be in (0, 1], got " +
                                std::to_string(options_.request_cpu_share));
  if (options_.max_requests_per_turn == 0)
    throw std::invalid_argument("the socket server needs at least 1 request per client per turn, got 0");
  // Reserved once, so that adding and removing clients never reallocates the lists.
  clients_.reserve(options_.max_clients);
  reaped_.reserve(options_.max_clients);
  delivery_flags_fd_ = Fd(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  if (!delivery_flags_fd_) throw errnoError("eventfd for the socket server");
  setNonBlockingCloseOnExec(listening_.fd.get());
  loop_.addFd(listening_.fd.get(), EPOLLIN, [this](std::uint32_t) { onListenerReadable(); });
  loop_.addFd(delivery_flags_fd_.get(), EPOLLIN, [this](std::uint32_t) {
    std::uint64_t count = 0;
    [[maybe_unused]] const ssize_t n = ::read(delivery_flags_fd_.get(), &count, sizeof count);
    serviceDeliveryFlags();
  });
}

UnixSocketServer::~UnixSocketServer() {
  if (accept_pause_timer_) loop_.removeSource(*accept_pause_timer_);
  if (stall_check_timer_) loop_.removeSource(*stall_check_timer_);
  for (const auto& c : clients_) loop_.removeFd(c->fd.get());
  {
    const std::lock_guard list(clients_mutex_);
    clients_.clear();
  }
  loop_.removeFd(delivery_flags_fd_.get());
  loop_.removeFd(listening_.fd.get());
  if (!listening_.path.empty()) {
    struct stat st {};
    if (::lstat(listening_.path.c_str(), &st) == 0 && st.st_dev == listening_.device && st.st_ino == listening_.inode)
      ::unlink(listening_.path.c_str());
  }
}

std::size_t UnixSocketServer::watcherCount() const noexcept {
  return static_cast<std::size_t>(
      std::count_if(clients_.begin(), clients_.end(), [](const auto& c) { return c->watch && !c->dead; }));
}

void UnixSocketServer::onListenerReadable() {
  for (int i = 0; i < kMaxAcceptsPerWake; ++i) {
    Fd fd(::accept4(listening_.fd.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC));
    if (fd) {
      acceptClient(std::move(fd));
      continue;
    }
    if (errno == EAGAIN || errno == EWOULDBLOCK) return;
    if (errno == EINTR || errno == ECONNABORTED) continue;
    if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
      // Out of descriptors or memory: the pending connection stays in the backlog and
      // would wake us at once again. Pause accepting for a moment instead of spinning.
      spdlog::warn("accept: {}; not accepting clients for 1 s", std::strerror(errno));
      loop_.modifyFd(listening_.fd.get(), 0);
      accept_pause_timer_ = loop_.addOneShotTimer(std::chrono::seconds(1), [this](std::uint64_t) {
        accept_pause_timer_.reset();
        loop_.modifyFd(listening_.fd.get(), EPOLLIN);
      });
      return;
    }
    throw errnoError("accept4 on the gyrod socket");
  }
}

void UnixSocketServer::acceptClient(Fd fd) {
  ++clients_total_;
  if (clients_.size() >= options_.max_clients) {
    const std::string line = errorLine(
        ErrorCode::TooManyClients, "gyrod serves at most " + std::to_string(options_.max_clients) + " clients at once");
    [[maybe_unused]] const ssize_t n = ::send(fd.get(), line.data(), line.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    spdlog::warn("refused a client: {} clients already connected", clients_.size());
    return;  // fd closes here
  }
  auto client = std::make_unique<Client>(std::move(fd), next_client_id_++, options_.client_buffer_bytes);
  ucred cred{};
  socklen_t len = sizeof cred;
  if (::getsockopt(client->fd.get(), SOL_SOCKET, SO_PEERCRED, &cred, &len) == 0) {
    client->pid = cred.pid;
    client->uid = cred.uid;
  }
  Client& c = *client;
  loop_.addFd(c.fd.get(), EPOLLIN, [this, &c](std::uint32_t events) { onClientEvents(c, events); });
  {
    const std::lock_guard list(clients_mutex_);
    clients_.push_back(std::move(client));
  }
  spdlog::info("client {} connected (pid {}, uid {})", c.id, c.pid.value_or(-1), c.uid.value_or(-1));
  queueLine(c, versionLine(options_.release));
  reapDeadClients();
}

void UnixSocketServer::onClientEvents(Client& c, std::uint32_t events) {
  if (events & EPOLLERR) {
    c.dead = true;
  } else {
    if ((events & EPOLLIN) && !c.closing && !c.deferred && c.held_reply.empty()) serveRequests(c);
    if ((events & EPOLLHUP) && !(events & EPOLLIN)) c.dead = true;  // both directions closed
    if ((events & EPOLLOUT) && !c.dead) flush(c);
  }
  reapDeadClients();
}

bool UnixSocketServer::requestTimeLeft() {
  if (options_.request_cpu_share >= 1.0) return true;
  const auto now = std::chrono::steady_clock::now();
  const auto earned = std::chrono::duration_cast<std::chrono::nanoseconds>(now - request_time_refilled_);
  request_time_refilled_ = now;
  request_time_left_ = std::min(
      kMaxRequestTimeBanked,
      request_time_left_ + std::chrono::duration_cast<std::chrono::nanoseconds>(earned * options_.request_cpu_share));
  return request_time_left_ > std::chrono::nanoseconds::zero();
}

void UnixSocketServer::serveRequests(Client& c) {
  if (!requestTimeLeft()) return deferRequests(c);
  const auto start = threadCpuTime();
  answerRequests(c);
  if (options_.request_cpu_share < 1.0) request_time_left_ -= threadCpuTime() - start;
}

void UnixSocketServer::answerRequests(Client& c) {
  std::size_t budget = options_.max_requests_per_turn;
  int reads = 0;
  while (!c.closing && !c.dead && c.held_reply.empty()) {
    const char* first = c.in.get() + c.in_start;
    if (const void* nl = std::memchr(first, '\n', c.in_used - c.in_start)) {
      if (budget == 0) return deferRequests(c);
      --budget;
      const auto end = static_cast<std::size_t>(static_cast<const char*>(nl) - c.in.get());
      std::size_t line_end = end;
      if (line_end > c.in_start && c.in[line_end - 1] == '\r') --line_end;
      const std::string_view line(first, line_end - c.in_start);
      c.in_start = end + 1;
      handleLine(c, line);
      continue;
    }
    // No whole line left: keep the partial one at the front and read more.
    std::memmove(c.in.get(), first, c.in_used - c.in_start);
    c.in_used -= c.in_start;
    c.in_start = 0;
    if (c.in_used == kInputBufferBytes) {
      handleLine(c, std::string_view(c.in.get(), c.in_used));  // reports the over-long line
      break;
    }
    if (reads++ == kMaxReadsPerWake) return deferRequests(c);
    const ssize_t n = ::recv(c.fd.get(), c.in.get() + c.in_used, kInputBufferBytes - c.in_used, 0);
    if (n == 0) {  // the client will send nothing more; answer what it asked, then close
      beginClose(c);
      return;
    }
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) {
        spdlog::info("client {}: read failed: {}", c.id, std::strerror(errno));
        c.dead = true;
        return;
      }
      break;  // all read and answered: wait for more input
    }
    c.in_used += static_cast<std::size_t>(n);
  }
  if (!c.dead) updateInterest(c);
}

void UnixSocketServer::deferRequests(Client& c) {
  c.deferred = true;
  updateInterest(c);  // its input is served from the deferred pass, not from epoll, meanwhile
  if (deferred_requests_pending_) return;
  deferred_requests_pending_ = true;
  auto serve = [this, alive = std::weak_ptr<bool>(alive_)] {
    if (!alive.expired()) serveDeferredRequests();
  };
  if (request_time_left_ > std::chrono::nanoseconds::zero()) {
    loop_.defer(std::move(serve));
    return;
  }
  // The requests' share of the CPU is spent: wait until it is earned back (at least 1 ms).
  const auto wait = std::max<std::chrono::nanoseconds>(
      std::chrono::milliseconds(1),
      std::chrono::duration_cast<std::chrono::nanoseconds>(-request_time_left_ / options_.request_cpu_share));
  loop_.addOneShotTimer(wait, [serve](std::uint64_t) { serve(); });
}

void UnixSocketServer::serveDeferredRequests() {
  deferred_requests_pending_ = false;
  // By index: serving never adds or removes clients (reaping waits until the end). Each pass
  // starts after the client served first last time: when the requests' CPU share runs out
  // within a pass, the clients late in the list are not always the ones left waiting.
  const std::size_t n = clients_.size();
  const std::size_t start = n == 0 ? 0 : deferred_pass_start_ % n;
  deferred_pass_start_ = start + 1;
  for (std::size_t k = 0; k < n; ++k) {
    Client& c = *clients_[(start + k) % n];
    if (!c.deferred || c.dead) continue;
    c.deferred = false;
    if (c.held_reply.empty() && !c.closing) serveRequests(c);
    if (!c.dead) updateInterest(c);
  }
  reapDeadClients();
}

void UnixSocketServer::handleLine(Client& c, std::string_view line) {
  if (line.size() > kMaxRequestLineBytes) {
    spdlog::warn("client {}: request line longer than {} bytes; disconnecting it", c.id, kMaxRequestLineBytes);
    queueLine(c, errorLine(ErrorCode::LineTooLong, "request lines are limited to " +
                                                       std::to_string(kMaxRequestLineBytes) + " bytes; disconnecting"));
    beginClose(c);
    return;
  }
  if (line.find_first_not_of(" \t\r") == std::string_view::npos) return;  // blank lines are ignored
  try {
    const Request request = parseRequest(line);
    if (const auto* w = std::get_if<WatchRequest>(&request)) {
      queueReply(c, watchLine(w->enable, w->decimate), w);
    } else if (std::holds_alternative<AllanRequest>(request)) {
      std::string reply;
      try {
        reply = content_.allanReplyLine();
      } catch (const std::exception& e) {
        spdlog::error("ALLAN reply for client {} failed: {}", c.id, e.what());
        reply = errorLine(ErrorCode::Internal, std::string("the daemon could not produce ALLAN: ") + e.what());
      }
      queueReply(c, std::move(reply));
    } else if (std::holds_alternative<EffectsRequest>(request)) {
      std::string reply;
      try {
        reply = effectsLine(content_.effectsReport());
      } catch (const std::exception& e) {
        spdlog::error("EFFECTS reply for client {} failed: {}", c.id, e.what());
        reply = errorLine(ErrorCode::Internal, std::string("the daemon could not produce EFFECTS: ") + e.what());
      }
      queueReply(c, std::move(reply));
    } else {
      std::string reply;
      try {
        reply = statusLine(content_.statusReport(), serverStatusFor(&c));
      } catch (const std::exception& e) {
        spdlog::error("STATUS reply for client {} failed: {}", c.id, e.what());
        reply = errorLine(ErrorCode::Internal, std::string("the daemon could not produce STATUS: ") + e.what());
      }
      queueReply(c, std::move(reply));
    }
  } catch (const ProtocolError& e) {
    queueReply(c, errorLine(e.code(), e.what()));
  }
}

namespace {
// Room a reply may take in a client's buffer: a watching client keeps a quarter of it for
// the RATE lines that arrive while it reads its replies.
bool replyFits(std::size_t reply_bytes, std::size_t free_bytes, std::size_t capacity, bool watching) {
  return reply_bytes + (watching ? capacity / 4 : 0) <= free_bytes;
}
}  // namespace

void UnixSocketServer::queueReply(Client& c, std::string reply, const WatchRequest* watch) {
  if (c.dead) return;
  enum class Outcome { Queued, Held, TooLong } outcome = Outcome::Queued;
  {
    // A WATCH request changes what the publishing thread sends in the same step as its reply
    // is queued: no RATE line comes before the reply to WATCH true, none after WATCH false.
    const std::lock_guard lock(c.mutex);
    if (watch) {
      c.watch = watch->enable;
      c.decimate = watch->decimate;
      c.countdown = 0;  // the next sample is sent, then every decimate-th
    }
    if (replyFits(reply.size(), c.out.free(), c.out.capacity(), c.watch)) {
      c.out.append(reply.data(), reply.size());
      ++c.lines_queued;
    } else if (reply.size() > c.out.capacity()) {
      outcome = Outcome::TooLong;  // an empty buffer could not take it: dropped at once
    } else {
      c.last_progress_ns = steadyNowNs();
      outcome = Outcome::Held;
    }
  }
  switch (outcome) {
    case Outcome::Queued:
      if (!(c.events & EPOLLOUT)) flush(c);
      return;
    case Outcome::TooLong: dropSlowClient(c, reply.size()); return;
    case Outcome::Held: break;
  }
  c.held_reply = std::move(reply);
  updateInterest(c);
  if (!stall_check_timer_) armStallCheck(options_.stalled_reply_timeout);
}

void UnixSocketServer::queueLine(Client& c, const char* data, std::size_t size) {
  if (c.dead) return;
  bool fits = false;
  {
    const std::lock_guard lock(c.mutex);
    fits = size <= c.out.free();
    if (fits) {
      c.out.append(data, size);
      ++c.lines_queued;
    }
  }
  if (!fits) {
    dropSlowClient(c, size);
    return;
  }
  // Write at once unless the socket is already known to be full (EPOLLOUT pending): most
  // lines then leave in the same wake-up, and the buffer only holds what the kernel refused.
  if (!(c.events & EPOLLOUT)) flush(c);
}

void UnixSocketServer::flush(Client& c) {
  bool failed = false;
  bool released = false;  // the held reply went into the buffer
  bool closed = false;    // closing, and everything sent
  {
    const std::lock_guard lock(c.mutex);
    failed = c.sendBuffered() == SendResult::Failed;
    if (!failed && !c.held_reply.empty() && replyFits(c.held_reply.size(), c.out.free(), c.out.capacity(), c.watch)) {
      // Room again: the held reply goes out and the client's requests resume next turn.
      c.out.append(c.held_reply.data(), c.held_reply.size());
      ++c.lines_queued;
      c.held_reply.clear();
      released = true;
      failed = c.sendBuffered() == SendResult::Failed;
    }
    closed = c.closing && c.out.empty();
  }
  if (failed || closed) {  // failed: EPIPE, ECONNRESET, the client has gone away
    c.dead = true;
    return;
  }
  if (released) {
    deferRequests(c);  // updates the interest
    return;
  }
  updateInterest(c);
}

void UnixSocketServer::updateInterest(Client& c) {
  const bool read_input = !c.closing && !c.deferred && c.held_reply.empty();
  bool write_output = false;
  {
    // Bytes to send, or a held reply that fits now (the publishing thread may have sent the
    // bytes it waited for): the flush on EPOLLOUT takes it.
    const std::lock_guard lock(c.mutex);
    write_output = !c.out.empty() ||
                   (!c.held_reply.empty() && replyFits(c.held_reply.size(), c.out.free(), c.out.capacity(), c.watch));
  }
  const std::uint32_t events =
      (read_input ? std::uint32_t{EPOLLIN} : 0u) | (write_output ? std::uint32_t{EPOLLOUT} : 0u);
  if (events == c.events) return;
  loop_.modifyFd(c.fd.get(), events);
  c.events = events;
}

void UnixSocketServer::beginClose(Client& c) {
  bool empty = false;
  {
    const std::lock_guard lock(c.mutex);  // no RATE line is queued after this
    c.closing = true;
    c.watch = false;
    empty = c.out.empty();
  }
  if (empty) {
    c.dead = true;
    return;
  }
  flush(c);
}

void UnixSocketServer::dropSlowClient(Client& c, std::size_t line_size) {
  // Unsent lines, the one that did not fit and a held reply.
  std::uint64_t lost = 0;
  {
    const std::lock_guard lock(c.mutex);
    lost = c.lines_queued - c.lines_sent + 1 + (c.held_reply.empty() ? 0 : 1);
  }
  ++clients_dropped_;
  lines_dropped_ += lost;
  spdlog::warn(
      "client {} (pid {}) is not reading: its {} byte buffer cannot take a {} byte line; "
      "disconnecting it ({} lines not delivered)",
      c.id, c.pid.value_or(-1), options_.client_buffer_bytes, line_size, lost);
  c.dead = true;
}

void UnixSocketServer::armStallCheck(std::chrono::nanoseconds delay) {
  stall_check_timer_ =
      loop_.addOneShotTimer(std::max(delay, std::chrono::nanoseconds(1'000'000)), [this](std::uint64_t) {
        stall_check_timer_.reset();
        dropStalledClients();
      });
}

void UnixSocketServer::dropStalledClients() {
  const std::int64_t now = steadyNowNs();
  const std::int64_t timeout_ns = std::chrono::nanoseconds(options_.stalled_reply_timeout).count();
  std::optional<std::int64_t> next_due;
  for (const auto& client : clients_) {
    Client& c = *client;
    if (c.dead || c.held_reply.empty()) continue;
    std::int64_t last_progress_ns = 0;
    std::uint64_t unsent = 0;
    {
      const std::lock_guard lock(c.mutex);
      last_progress_ns = c.last_progress_ns;
      unsent = c.lines_queued - c.lines_sent;
    }
    const std::int64_t due = last_progress_ns + timeout_ns;
    if (due > now) {
      next_due = std::min(next_due.value_or(due), due);
      continue;
    }
    ++clients_dropped_;
    const std::uint64_t lost = unsent + 1;
    lines_dropped_ += lost;
    spdlog::warn(
        "client {} (pid {}) is not reading: a reply has waited {} ms for room in its {} byte buffer; "
        "disconnecting it ({} lines not delivered)",
        c.id, c.pid.value_or(-1), options_.stalled_reply_timeout.count(), options_.client_buffer_bytes, lost);
    c.dead = true;
  }
  if (next_due) armStallCheck(std::chrono::nanoseconds(*next_due - now));
  reapDeadClients();
}

void UnixSocketServer::reapDeadClients() {
  // The list changes only here and in acceptClient, both on this thread: it is read without
  // the list's mutex, and changed under it.
  if (std::none_of(clients_.begin(), clients_.end(), [](const auto& c) { return c->dead.load(); })) return;
  {
    const std::lock_guard list(clients_mutex_);
    for (auto& client : clients_)
      if (client->dead) reaped_.push_back(std::move(client));
    std::erase(clients_, nullptr);
  }
  // Out of the list: the publishing thread no longer sees them.
  for (const auto& c : reaped_) {
    loop_.removeFd(c->fd.get());
    spdlog::info("client {} disconnected ({} lines sent)", c->id, c->lines_sent);
  }
  reaped_.clear();
}

void UnixSocketServer::publishRate(const RateSample& sample) {
  std::array<char, kMaxRateLineBytes> line;
  const std::size_t n = formatRateLine(sample, line);
  publishLine(line.data(), n, true);
}

void UnixSocketServer::publishGap(const GapEvent& gap) {
  std::array<char, kMaxGapLineBytes> line;
  const std::size_t n = formatGapLine(gap, line);
  publishLine(line.data(), n, false);
}

void UnixSocketServer::publishEffect(std::string_view line) { publishLine(line.data(), line.size(), false); }

void UnixSocketServer::publishLine(const char* data, std::size_t size, bool decimated) {
  bool flagged = false;
  {
    const std::lock_guard list(clients_mutex_);
    for (const auto& client : clients_) flagged = deliverLine(*client, data, size, decimated) || flagged;
  }
  if (!flagged) return;
  if (!options_.publish_off_loop) {
    serviceDeliveryFlags();
    return;
  }
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(delivery_flags_fd_.get(), &one, sizeof one);
}

// On the publishing thread, under the client list's mutex: nothing here calls into the loop.
bool UnixSocketServer::deliverLine(Client& c, const char* data, std::size_t size, bool decimated) {
  if (!c.watch.load(std::memory_order_relaxed) || c.dead.load(std::memory_order_relaxed) ||
      c.drop_requested.load(std::memory_order_relaxed) || c.send_failed.load(std::memory_order_relaxed))
    return false;
  const std::lock_guard lock(c.mutex);
  if (!c.watch || c.closing) return false;  // as the loop's thread left them under the mutex
  if (decimated) {
    if (c.countdown > 0) {
      --c.countdown;
      return false;
    }
    c.countdown = c.decimate - 1;
  }
  if (size > c.out.free()) {
    c.drop_line_bytes = size;
    c.drop_requested = true;
    return true;
  }
  // Bytes already waiting mean the socket was full: they leave on EPOLLOUT, from the loop's
  // thread, and this line after them.
  const bool socket_full = !c.out.empty();
  c.out.append(data, size);
  ++c.lines_queued;
  if (socket_full) return false;
  switch (c.sendBuffered()) {
    case SendResult::Drained: return false;
    case SendResult::Blocked: c.wants_output = true; return true;
    case SendResult::Failed: c.send_failed = true; return true;
  }
  return false;
}

void UnixSocketServer::serviceDeliveryFlags() {
  for (const auto& client : clients_) {
    Client& c = *client;
    if (c.dead) continue;
    if (c.send_failed) {
      c.dead = true;
    } else if (c.drop_requested) {
      std::size_t line_bytes = 0;
      {
        const std::lock_guard lock(c.mutex);
        line_bytes = c.drop_line_bytes;
      }
      dropSlowClient(c, line_bytes);
    } else if (c.wants_output.exchange(false)) {
      updateInterest(c);
    }
  }
  reapDeadClients();
}

ServerStatus UnixSocketServer::serverStatusFor(const Client* self) const {
  ServerStatus s;
  s.clients_total = clients_total_;
  s.clients_dropped = clients_dropped_;
  s.lines_dropped = lines_dropped_;
  s.client_buffer_bytes = options_.client_buffer_bytes;
  for (const auto& c : clients_) {
    if (c->dead) continue;
    ClientStatus cs;
    cs.id = c->id;
    cs.pid = c->pid;
    cs.uid = c->uid;
    cs.watch = c->watch;
    {
      const std::lock_guard lock(c->mutex);
      cs.decimate = c->decimate;
      cs.lines_queued = c->lines_queued;
      cs.lines_sent = c->lines_sent;
      cs.buffered_bytes = c->out.size();
    }
    cs.self = c.get() == self;
    s.client_list.push_back(cs);
  }
  s.clients = s.client_list.size();
  return s;
}

ServerStatus UnixSocketServer::serverStatus() const { return serverStatusFor(nullptr); }

}  // namespace gyrod::daemon
