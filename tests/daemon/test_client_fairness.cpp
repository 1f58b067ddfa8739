// The event loop never waits on a client (issue 16): a client pipelining thousands of
// requests is served a bounded share per loop turn and slowed down while it does not read,
// never dropped for it; only a client that stops reading its output is dropped. ALLAN
// replies come from a cache between refits.
#include <sys/socket.h>

#include "daemon/allan_reply_cache.hpp"
#include "server_fixture.hpp"

using namespace gyrod;
using namespace gyrod::test;

namespace {

using ClientFairnessTest = ServerFixture;

constexpr auto kLongGuard = 30s;

std::string repeated(const std::string& line, std::size_t times) {
  std::string all;
  all.reserve(line.size() * times);
  for (std::size_t i = 0; i < times; ++i) all += line;
  return all;
}

// Sends `text` without blocking the test's thread (the server runs in it), pumping the loop
// while the socket is full; when `read` the client also collects its replies meanwhile.
// Returns false when the server closed the connection before all was sent.
bool sendPumping(EventLoop& loop, TestClient& c, const std::string& text, bool read) {
  const auto deadline = std::chrono::steady_clock::now() + kLongGuard;
  std::size_t done = 0;
  while (done < text.size() && std::chrono::steady_clock::now() < deadline) {
    const ssize_t n = ::send(c.fd(), text.data() + done, text.size() - done, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) return false;  // EPIPE, ECONNRESET: dropped
    loop.runOnce(1ms);
    if (read && !c.collect()) return false;
  }
  return done == text.size();
}

}  // namespace

TEST_F(ClientFairnessTest, TenThousandPipelinedStatusRequestsGetTenThousandReplies) {
  content_.status.device_state = "streaming";
  startServer();
  auto bystander = watcher();
  auto c = connect();
  constexpr std::size_t kRequests = 10'000;
  ASSERT_TRUE(sendPumping(loop_, *c, repeated("{\"cmd\":\"status\"}\n", kRequests), /*read=*/true));
  const auto deadline = std::chrono::steady_clock::now() + kLongGuard;
  std::uint64_t published = 0;
  while (c->received() < kRequests && std::chrono::steady_clock::now() < deadline) {
    server_->publishRate(syntheticSample(published++));  // samples keep flowing meanwhile
    loop_.runOnce(1ms);
    ASSERT_TRUE(c->collect()) << "the pipelining client was dropped after " << c->received() << " replies";
    bystander->collect();
  }
  const auto replies = c->readLines(loop_, kRequests);
  ASSERT_EQ(replies.size(), kRequests);
  for (const auto& line : replies) ASSERT_EQ(json::parse(line)["class"], "STATUS") << line;
  EXPECT_EQ(server_->serverStatus().clients_dropped, 0u);
  // The watcher was served throughout: every sample, in order.
  const auto rates = bystander->readLines(loop_, published);
  ASSERT_EQ(rates.size(), published);
  for (std::uint64_t k = 0; k < published; ++k) expectRateLineCarries(rates[k], syntheticSample(k));
}

TEST_F(ClientFairnessTest, EachLoopTurnAnswersAtMostTheBudgetOfOneClient) {
  daemon::ServerOptions options;
  options.max_requests_per_turn = 4;
  startServer(options);
  auto c = connect();
  c->send(repeated("{\"cmd\":\"status\"}\n", 10));
  std::vector<std::size_t> after_turn;
  for (int turn = 0; turn < 3; ++turn) {
    loop_.runOnce(1s);
    c->collect();
    after_turn.push_back(c->received());
  }
  EXPECT_EQ(after_turn, std::vector<std::size_t>({4, 8, 10}));
}

TEST_F(ClientFairnessTest, ClientThatNeverReadsItsRepliesIsDroppedAndTheOthersAreServed) {
  daemon::ServerOptions options;
  options.client_buffer_bytes = 16 * 1024;
  options.stalled_reply_timeout = 300ms;
  startServer(options);
  auto bystander = watcher();
  auto deaf = connect();
  // Never reads: its replies fill the kernel's buffer and its own, its input is no longer
  // read, and after the timeout it is dropped (the send then fails).
  EXPECT_FALSE(sendPumping(loop_, *deaf, repeated("{\"cmd\":\"status\"}\n", 100'000), /*read=*/false));
  EXPECT_TRUE(pumpUntil(loop_, [&] { return server_->clientCount() == 1; }));
  const auto st = server_->serverStatus();
  EXPECT_EQ(st.clients_dropped, 1u);
  EXPECT_GT(st.lines_dropped, 0u);
  server_->publishRate(syntheticSample(7));
  const auto got = bystander->readLines(loop_, 1);
  ASSERT_EQ(got.size(), 1u);
  expectRateLineCarries(got[0], syntheticSample(7));
}

TEST_F(ClientFairnessTest, SlowReaderIsSlowedDownNotDropped) {
  daemon::ServerOptions options;
  options.client_buffer_bytes = 8 * 1024;
  options.stalled_reply_timeout = 2s;
  startServer(options);
  auto c = connect();
  constexpr std::size_t kRequests = 3'000;
  ASSERT_TRUE(sendPumping(loop_, *c, repeated("{\"cmd\":\"status\"}\n", kRequests), /*read=*/false));
  // Reads in small sips, with pauses shorter than the timeout.
  const auto deadline = std::chrono::steady_clock::now() + kLongGuard;
  while (c->received() < kRequests && std::chrono::steady_clock::now() < deadline) {
    for (int i = 0; i < 20; ++i) loop_.runOnce(1ms);
    char sip[4096];
    const ssize_t n = ::recv(c->fd(), sip, sizeof sip, MSG_DONTWAIT | MSG_PEEK);
    ASSERT_NE(n, 0) << "dropped after " << c->received() << " replies";
    c->collect();
  }
  EXPECT_EQ(c->received(), kRequests);
  EXPECT_EQ(server_->serverStatus().clients_dropped, 0u);
}

TEST_F(ClientFairnessTest, ContentWithoutACacheIsAskedForEveryAllanRequest) {
  content_.allan.tau0_s = 0.02;
  startServer();
  auto c = connect();
  c->send("{\"cmd\":\"allan\"}\n");
  EXPECT_EQ(c->readObject(loop_)["samples"], 0);
  content_.allan.samples = 5;
  c->send("{\"cmd\":\"allan\"}\n");
  EXPECT_EQ(c->readObject(loop_)["samples"], 5);
}

TEST(AllanReplyCache, ServesOneLineUntilInvalidatedThenANewOne) {
  std::uint64_t samples = 100;
  daemon::AllanReplyCache cache([&] {
    protocol::AllanReport r;
    r.tau0_s = 0.001;
    r.window_s = 3600.0;
    r.samples = samples++;
    return r;
  });
  const std::string first = cache.line();
  EXPECT_EQ(cache.line(), first);
  EXPECT_EQ(cache.line(), first);
  EXPECT_EQ(cache.builds(), 1u);
  EXPECT_EQ(json::parse(first)["samples"], 100);
  cache.invalidate();
  const std::string second = cache.line();
  EXPECT_NE(second, first);
  EXPECT_EQ(json::parse(second)["samples"], 101);
  EXPECT_EQ(cache.line(), second);
  EXPECT_EQ(cache.builds(), 2u);
}

TEST(AllanReplyCache, AFailedBuildCachesNothing) {
  bool fail = true;
  daemon::AllanReplyCache cache([&] {
    if (fail) throw std::runtime_error("statistics not available");
    return protocol::AllanReport{};
  });
  EXPECT_THROW(cache.line(), std::runtime_error);
  fail = false;
  EXPECT_EQ(json::parse(cache.line())["class"], "ALLAN");
  EXPECT_EQ(cache.builds(), 1u);
}
