#pragma once
// Test support for the socket server: a scratch folder, an in-process server on a real
// Unix socket, raw test clients, synthetic samples. The server runs in the test's own
// thread, so every wait pumps the event loop; deadlines only guard against hangs (a test
// that reaches one fails), they assert nothing about speed.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "daemon/event_loop.hpp"
#include "daemon/unix_socket_server.hpp"
#include "protocol/fd.hpp"
#include "protocol/protocol.hpp"
#include "tools/run_command.hpp"

namespace gyrod::test {

using namespace std::chrono_literals;
using daemon::EventLoop;
using nlohmann::json;

inline constexpr auto kHangGuard = 5s;

// A synthetic sample whose every field is a plain function of k, with values chosen to
// need all 17 significant digits (thirds, sevenths, tiny and huge magnitudes, negatives).
inline protocol::RateSample syntheticSample(std::uint64_t k) {
  const double x = static_cast<double>(k);
  protocol::RateSample s;
  s.seq = 1000 + k;
  s.t_s = 12345.678 + x / 50.0;
  s.temp_c = 25.0 + x / 3.0;
  s.raw_dps = {x / 7.0 - 1.0, -x * 1e-7 / 3.0, 250.0 / (x + 3.0)};
  s.mean_dps = {1.0 / (x + 1.0), -std::sqrt(x + 2.0), x * 1e300 / 7.0};
  s.kalman_dps = {std::ldexp(1.0, -1070) * (x + 1.0), 0.1 * x, -2.0 / 3.0};
  return s;
}

// Raw client socket. Reads are non-blocking and pump the loop while they wait.
class TestClient {
 public:
  explicit TestClient(const std::string& path) : fd_(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0)) {
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::memcpy(addr.sun_path, path.data(), path.size());
    if (::connect(fd_.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0)
      throw protocol::errnoError("test client connect(" + path + ")");
  }
  int fd() const { return fd_.get(); }
  void close() { fd_.reset(); }

  void send(const std::string& text) {
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::send(fd_.get(), text.data() + done, text.size() - done, MSG_NOSIGNAL);
      if (n < 0) throw protocol::errnoError("test client send");
      done += static_cast<std::size_t>(n);
    }
  }

  // Takes what the socket has now without waiting. Returns false once the server has
  // closed the connection (EOF or reset).
  bool drain() {
    char buf[65536];
    while (true) {
      const ssize_t n = ::recv(fd_.get(), buf, sizeof buf, MSG_DONTWAIT);
      if (n > 0) {
        pending_.append(buf, static_cast<std::size_t>(n));
        continue;
      }
      if (n == 0) {
        closed_ = true;
        return false;
      }
      if (errno == EAGAIN || errno == EWOULDBLOCK) return true;
      closed_ = true;  // ECONNRESET: closed with our request bytes unread
      return false;
    }
  }
  bool closedByServer() const { return closed_; }

  // Complete lines received so far (removed from the pending bytes).
  std::vector<std::string> takeLines() {
    std::vector<std::string> lines;
    std::size_t start = 0;
    for (std::size_t nl; (nl = pending_.find('\n', start)) != std::string::npos; start = nl + 1)
      lines.push_back(pending_.substr(start, nl - start));
    pending_.erase(0, start);
    return lines;
  }
  const std::string& partial() const { return pending_; }

  // Moves what has arrived into the received lines; false once closed by the server.
  bool collect() {
    const bool open = drain();
    for (auto& l : takeLines()) got_.push_back(std::move(l));
    return open;
  }
  std::size_t received() const { return got_.size(); }

  // Pumps `loop` until this client has `n` more lines (or the guard passes).
  std::vector<std::string> readLines(EventLoop& loop, std::size_t n) {
    const auto deadline = std::chrono::steady_clock::now() + kHangGuard;
    while (got_.size() < n && std::chrono::steady_clock::now() < deadline) {
      loop.runOnce(1ms);
      if (!collect()) break;
    }
    const std::size_t k = std::min(n, got_.size());
    std::vector<std::string> out(got_.begin(), got_.begin() + static_cast<std::ptrdiff_t>(k));
    got_.erase(got_.begin(), got_.begin() + static_cast<std::ptrdiff_t>(k));
    return out;
  }
  json readObject(EventLoop& loop) {
    const auto lines = readLines(loop, 1);
    if (lines.empty()) {
      ADD_FAILURE() << "no line from the server";
      return json();
    }
    return json::parse(lines[0]);
  }
  // Pumps until the server closes the connection; returns the lines received before.
  std::vector<std::string> readUntilClosed(EventLoop& loop) {
    const auto deadline = std::chrono::steady_clock::now() + kHangGuard;
    std::vector<std::string> lines = std::move(got_);
    got_.clear();
    while (!closed_ && std::chrono::steady_clock::now() < deadline) {
      loop.runOnce(1ms);
      drain();
      for (auto& l : takeLines()) lines.push_back(std::move(l));
    }
    return lines;
  }

 private:
  protocol::Fd fd_;
  std::string pending_;
  std::vector<std::string> got_;
  bool closed_ = false;
};

// Pumps `loop` and reads all `clients` side by side (as independent processes would)
// until each has received its count of lines.
inline void collectConcurrently(EventLoop& loop, const std::vector<TestClient*>& clients,
                                const std::vector<std::size_t>& counts) {
  const auto deadline = std::chrono::steady_clock::now() + kHangGuard;
  auto done = [&] {
    for (std::size_t i = 0; i < clients.size(); ++i)
      if (clients[i]->received() < counts[i] && !clients[i]->closedByServer()) return false;
    return true;
  };
  while (!done() && std::chrono::steady_clock::now() < deadline) {
    loop.runOnce(1ms);
    for (TestClient* c : clients) c->collect();
  }
}

// ALLAN/STATUS content with values set by the test.
struct FakeContent : daemon::ServerContent {
  protocol::AllanReport allan;
  protocol::StatusReport status;
  bool fail = false;
  protocol::AllanReport allanReport() override {
    if (fail) throw std::runtime_error("statistics not available");
    return allan;
  }
  protocol::StatusReport statusReport() override {
    if (fail) throw std::runtime_error("status not available");
    return status;
  }
};

// Pumps `loop` until `done()` or the guard passes; returns done().
inline bool pumpUntil(EventLoop& loop, const std::function<bool()>& done) {
  const auto deadline = std::chrono::steady_clock::now() + kHangGuard;
  while (!done() && std::chrono::steady_clock::now() < deadline) loop.runOnce(1ms);
  return done();
}

class ServerFixture : public ::testing::Test {
 protected:
  void startServer(daemon::ServerOptions options = {}) {
    daemon::SocketOptions so;
    so.path = socketPath();
    server_ = std::make_unique<daemon::UnixSocketServer>(loop_, daemon::bindListeningSocket(so), content_,
                                                         std::move(options));
  }
  std::string socketPath() const { return (dir_.path() / "gyrod.sock").string(); }

  // Connects and consumes the VERSION line.
  std::unique_ptr<TestClient> connect() {
    auto c = std::make_unique<TestClient>(socketPath());
    const json v = c->readObject(loop_);
    EXPECT_EQ(v.value("class", ""), "VERSION");
    return c;
  }
  // Connects, asks to watch and waits for the WATCH reply.
  std::unique_ptr<TestClient> watcher(std::uint32_t decimate = 1) {
    auto c = connect();
    c->send(json({{"cmd", "watch"}, {"enable", true}, {"decimate", decimate}}).dump() + "\n");
    const json w = c->readObject(loop_);
    EXPECT_EQ(w.value("class", ""), "WATCH");
    return c;
  }
  // Publishes samples first..first+count−1 from a periodic timer, `per_tick` per expiry,
  // as the daemon's data-ready handler would.
  // `after_each(k)` runs after sample k is published.
  void publishFromTimer(std::uint64_t first, std::uint64_t count, std::uint64_t per_tick = 1,
                        std::function<void(std::uint64_t)> after_each = {}) {
    auto next = std::make_shared<std::uint64_t>(first);
    const std::uint64_t end = first + count;
    auto id = std::make_shared<EventLoop::SourceId>(0);
    *id = loop_.addPeriodicTimer(200us, [this, next, end, per_tick, id, after_each](std::uint64_t) {
      for (std::uint64_t i = 0; i < per_tick && *next < end; ++i) {
        const std::uint64_t k = (*next)++;
        server_->publishRate(syntheticSample(k));
        if (after_each) after_each(k);
      }
      if (*next == end) loop_.removeSource(*id);
    });
  }

  ScratchDir dir_;
  EventLoop loop_;
  FakeContent content_;
  std::unique_ptr<daemon::UnixSocketServer> server_;
};

// Checks a RATE line against the sample it must carry, value by value, exactly.
inline void expectRateLineCarries(const std::string& line, const protocol::RateSample& s) {
  const json j = json::parse(line);
  ASSERT_EQ(j.value("class", ""), "RATE") << line;
  EXPECT_EQ(j["seq"].get<std::uint64_t>(), s.seq);
  EXPECT_EQ(j["t"].get<double>(), s.t_s) << line;
  EXPECT_EQ(j["temp"].get<double>(), s.temp_c) << line;
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(j["raw"][i].get<double>(), s.raw_dps[i]) << line;
    EXPECT_EQ(j["mean"][i].get<double>(), s.mean_dps[i]) << line;
    EXPECT_EQ(j["kalman"][i].get<double>(), s.kalman_dps[i]) << line;
  }
}

}  // namespace gyrod::test
