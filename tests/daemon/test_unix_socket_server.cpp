// The socket server against real Unix sockets in a scratch folder: what clients receive,
// what bad clients get, and that no client can hurt another or the daemon.
#include <fcntl.h>
#include <grp.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <systemd/sd-daemon.h>

#include <atomic>
#include <fstream>
#include <thread>

#include "server_fixture.hpp"

using namespace gyrod;
using namespace gyrod::test;
using protocol::ErrorCode;

namespace {

using ServerTest = ServerFixture;

json parse(const std::string& line) { return json::parse(line); }

// Leaves a socket file that nobody listens on, as a crashed daemon would.
void makeStaleSocketFile(const std::string& path) {
  daemon::SocketOptions so;
  so.path = path;
  daemon::ListeningSocket ls = daemon::bindListeningSocket(so);
  // Closing without removing the file: connect() to it is now refused.
}

}  // namespace

TEST_F(ServerTest, VersionOnConnect) {
  startServer();
  TestClient c(socketPath());
  const json v = c.readObject(loop_);
  EXPECT_EQ(v, json::parse(std::string(R"({"class":"VERSION","release":")") + GYROD_RELEASE +
                           R"(","proto_major":1,"proto_minor":9})"));
  EXPECT_EQ(server_->clientCount(), 1u);
}

TEST_F(ServerTest, WatchDeliversEveryRateLineInOrderWithExactValues) {
  startServer();
  auto c = watcher();
  publishFromTimer(0, 300, 3);
  const auto lines = c->readLines(loop_, 300);
  ASSERT_EQ(lines.size(), 300u);
  for (std::size_t k = 0; k < lines.size(); ++k) expectRateLineCarries(lines[k], syntheticSample(k));
}

TEST_F(ServerTest, NoRateLinesBeforeWatchOrAfterWatchIsDisabled) {
  startServer();
  auto quiet = connect();
  auto c = watcher();
  publishFromTimer(0, 5);
  ASSERT_EQ(c->readLines(loop_, 5).size(), 5u);
  c->send("{\"cmd\":\"watch\",\"enable\":false}\n");
  EXPECT_EQ(c->readObject(loop_), json::parse(R"({"class":"WATCH","enable":false,"decimate":1})"));
  publishFromTimer(5, 5);
  ASSERT_TRUE(pumpUntil(loop_, [&] { return loop_.runOnce(0ms) == 0; }));
  for (int i = 0; i < 5; ++i) server_->publishRate(syntheticSample(100 + static_cast<std::uint64_t>(i)));
  // The next line each client gets is the STATUS it asks for: nothing was sent in between.
  c->send("{\"cmd\":\"status\"}\n");
  quiet->send("{\"cmd\":\"status\"}\n");
  EXPECT_EQ(c->readObject(loop_).value("class", ""), "STATUS");
  EXPECT_EQ(quiet->readObject(loop_).value("class", ""), "STATUS");
}

TEST_F(ServerTest, DecimateSendsEveryNthSampleStartingWithTheNext) {
  startServer();
  auto every3 = watcher(3);
  auto all = watcher(1);
  publishFromTimer(0, 30);
  collectConcurrently(loop_, {every3.get(), all.get()}, {10, 30});
  const auto all_lines = all->readLines(loop_, 30);
  ASSERT_EQ(all_lines.size(), 30u);
  const auto some = every3->readLines(loop_, 10);
  ASSERT_EQ(some.size(), 10u);
  for (std::size_t i = 0; i < some.size(); ++i) expectRateLineCarries(some[i], syntheticSample(3 * i));
  // And nothing more: the next line is the reply to a request.
  every3->send("{\"cmd\":\"status\"}\n");
  EXPECT_EQ(every3->readObject(loop_).value("class", ""), "STATUS");
}

TEST_F(ServerTest, GapLinesReachEveryWatcherWhateverItsDecimation) {
  startServer();
  auto decimated = watcher(1000);
  auto plain = watcher();
  server_->publishRate(syntheticSample(0));
  server_->publishGap({1001, 4, "fifo_overflow"});
  server_->publishRate(syntheticSample(5));
  const auto d = decimated->readLines(loop_, 2);
  ASSERT_EQ(d.size(), 2u);
  expectRateLineCarries(d[0], syntheticSample(0));
  EXPECT_EQ(parse(d[1]), json::parse(R"({"class":"GAP","seq":1001,"count":4,"reason":"fifo_overflow"})"));
  const auto p = plain->readLines(loop_, 3);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(parse(p[1])["class"], "GAP");
  expectRateLineCarries(p[2], syntheticSample(5));
}

TEST_F(ServerTest, AllanAndStatusReplies) {
  content_.allan.window_s = 600.0;
  content_.allan.samples = 30000;
  content_.allan.tau0_s = 0.02;
  content_.allan.tau_s = {0.02, 0.04};
  content_.allan.curves[1][2].adev_dps = {0.125, 1.0 / 3.0};
  content_.status.device_state = "streaming";
  content_.status.samples = 1234;
  content_.status.uptime_s = 24.68;
  content_.status.bias_source = "calibration";
  startServer();
  auto other = watcher(4);
  auto c = connect();
  c->send("{\"cmd\":\"allan\"}\n");
  const json a = c->readObject(loop_);
  EXPECT_EQ(a, json::parse(R"({"class":"ALLAN","samples":30000,"window":600.0,"tau0":0.02,"tau":[0.02,0.04],
                                "adev":{"y":{"kalman":[0.125,0.3333333333333333]}}})"));
  EXPECT_EQ(a["adev"]["y"]["kalman"][1].get<double>(), 1.0 / 3.0);
  c->send("{\"cmd\":\"status\"}\n");
  const json s = c->readObject(loop_);
  EXPECT_EQ(s["class"], "STATUS");
  EXPECT_EQ(s["device_state"], "streaming");
  EXPECT_EQ(s["samples"], 1234);
  EXPECT_EQ(s["uptime"].get<double>(), 24.68);
  EXPECT_EQ(s["bias_source"], "calibration");
  EXPECT_FALSE(s.contains("temp"));
  EXPECT_FALSE(s.contains("rate"));
  EXPECT_EQ(s["clients"], 2);
  EXPECT_EQ(s["clients_total"], 2);
  EXPECT_EQ(s["clients_dropped"], 0);
  EXPECT_EQ(s["client_buffer"], 256 * 1024);
  ASSERT_EQ(s["client_list"].size(), 2u);
  const json& first = s["client_list"][0];
  const json& me = s["client_list"][1];
  EXPECT_EQ(first["watch"], true);
  EXPECT_EQ(first["decimate"], 4);
  EXPECT_EQ(first["lines_sent"], 2);  // VERSION, WATCH
  EXPECT_FALSE(first.contains("self"));
  EXPECT_EQ(me["self"], true);
  EXPECT_EQ(me["pid"], ::getpid());  // SO_PEERCRED: the test process itself
  EXPECT_EQ(me["lines_sent"], 2);    // VERSION, ALLAN (STATUS is being built)
}

TEST_F(ServerTest, ContentFailureBecomesAnErrorAndTheClientStays) {
  startServer();
  auto c = connect();
  content_.fail = true;
  c->send("{\"cmd\":\"allan\"}\n{\"cmd\":\"status\"}\n{\"cmd\":\"effects\"}\n");
  const json e1 = c->readObject(loop_);
  const json e2 = c->readObject(loop_);
  const json e3 = c->readObject(loop_);
  EXPECT_EQ(e1["code"], "internal");
  EXPECT_NE(e1["message"].get<std::string>().find("statistics not available"), std::string::npos);
  EXPECT_EQ(e2["code"], "internal");
  EXPECT_EQ(e3["code"], "internal");
  EXPECT_NE(e3["message"].get<std::string>().find("could not produce EFFECTS"), std::string::npos);
  content_.fail = false;
  c->send("{\"cmd\":\"status\"}\n{\"cmd\":\"effects\"}\n");
  EXPECT_EQ(c->readObject(loop_)["class"], "STATUS");
  EXPECT_EQ(c->readObject(loop_)["class"], "EFFECTS");
}

TEST_F(ServerTest, BadRequestsGetNamedErrorsAndTheClientStays) {
  startServer();
  auto c = connect();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"not json at all", "not_json"},
      {"[1,2,3]", "not_object"},
      {R"({"cmd":"launch"})", "unknown_cmd"},
      {R"({"cmd":42})", "bad_type"},
      {R"({"cmd":"watch","enable":"yes"})", "bad_type"},
      {R"({"cmd":"watch","decimate":0})", "out_of_range"},
      {R"({"cmd":"watch","decimate":1.5})", "bad_type"},
      {R"({"cmd":"status","extra":1})", "unknown_field"},
      {R"({"nocmd":true})", "missing_field"},
  };
  std::string all;
  for (const auto& [line, code] : cases) all += line + "\r\n";  // CRLF works too
  all += "\n   \n";                                             // blank lines are ignored
  c->send(all);
  const auto replies = c->readLines(loop_, cases.size());
  ASSERT_EQ(replies.size(), cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const json e = parse(replies[i]);
    EXPECT_EQ(e["class"], "ERROR") << cases[i].first;
    EXPECT_EQ(e["code"], cases[i].second) << cases[i].first;
    EXPECT_FALSE(e["message"].get<std::string>().empty());
  }
  // Still connected and served; a failed watch changed nothing.
  c->send("{\"cmd\":\"status\"}\n");
  const json s = c->readObject(loop_);
  EXPECT_EQ(s["class"], "STATUS");
  EXPECT_EQ(s["client_list"][0]["watch"], false);
  EXPECT_EQ(server_->clientCount(), 1u);
}

// The rest of a line after a NUL is never read as another request: the whole line is one
// bad_request error, and the watch it held is not turned on.
TEST_F(ServerTest, ALineWithANulIsOneBadRequestAndNothingElse) {
  using namespace std::string_literals;
  startServer();
  auto c = connect();
  c->send("{\"cmd\":\"status\"}\0garbage\n"s + "{\"cmd\":\"watch\",\"enable\":false}\0{\"cmd\":\"watch\"}\n"s);
  const auto replies = c->readLines(loop_, 2);
  ASSERT_EQ(replies.size(), 2u);
  for (const auto& reply : replies) {
    const json e = parse(reply);
    EXPECT_EQ(e["class"], "ERROR") << reply;
    EXPECT_EQ(e["code"], "bad_request") << reply;
  }
  c->send("{\"cmd\":\"status\"}\n");
  const json s = c->readObject(loop_);
  EXPECT_EQ(s["class"], "STATUS");
  EXPECT_EQ(s["client_list"][0]["watch"], false);
}

TEST_F(ServerTest, LineOfExactlyTheLimitIsServed) {
  startServer();
  auto c = connect();
  std::string line = "{\"cmd\":\"status\"}";
  line += std::string(protocol::kMaxRequestLineBytes - line.size(), ' ');
  ASSERT_EQ(line.size(), protocol::kMaxRequestLineBytes);
  c->send(line + "\r\n");
  EXPECT_EQ(c->readObject(loop_)["class"], "STATUS");
}

TEST_F(ServerTest, OverlongLineGetsAnErrorThenDisconnectAndTheServerLivesOn) {
  startServer();
  auto bystander = watcher();
  auto c = connect();
  c->send(std::string(5 * 1024, 'a') + "\n");
  const auto lines = c->readUntilClosed(loop_);
  EXPECT_TRUE(c->closedByServer());
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(parse(lines[0])["code"], "line_too_long");
  EXPECT_TRUE(pumpUntil(loop_, [&] { return server_->clientCount() == 1; }));
  // One byte over the limit without any newline is refused the same way.
  auto c2 = connect();
  c2->send(std::string(protocol::kMaxRequestLineBytes + 3, '{'));
  const auto lines2 = c2->readUntilClosed(loop_);
  ASSERT_EQ(lines2.size(), 1u);
  EXPECT_EQ(parse(lines2[0])["code"], "line_too_long");
  // The others never noticed.
  server_->publishRate(syntheticSample(0));
  const auto got = bystander->readLines(loop_, 1);
  ASSERT_EQ(got.size(), 1u);
  expectRateLineCarries(got[0], syntheticSample(0));
  auto fresh = connect();
  EXPECT_EQ(server_->clientCount(), 2u);
}

TEST_F(ServerTest, TwentyClientsAllReceiveEverything) {
  startServer();
  std::vector<std::unique_ptr<TestClient>> clients;
  for (int i = 0; i < 20; ++i) clients.push_back(watcher());
  publishFromTimer(0, 200, 10);
  std::vector<TestClient*> all;
  for (auto& c : clients) all.push_back(c.get());
  collectConcurrently(loop_, all, std::vector<std::size_t>(all.size(), 200));
  for (auto& c : clients) {
    const auto lines = c->readLines(loop_, 200);
    ASSERT_EQ(lines.size(), 200u);
    for (std::size_t k = 0; k < lines.size(); ++k) expectRateLineCarries(lines[k], syntheticSample(k));
  }
}

TEST_F(ServerTest, StalledClientIsDroppedWhileTheOthersReceiveEveryLine) {
  daemon::ServerOptions options;
  options.client_buffer_bytes = 8192;
  startServer(options);
  auto a = watcher();
  auto stalled = watcher();
  auto b = watcher(2);
  // Enough lines to fill the kernel's socket buffer and then the 8 KiB one of the
  // stalled client. The kernel charges each write with its overhead (~1 KiB), so its
  // default ~208 KiB holds a few hundred one-line writes; 1500 lines leave a wide margin
  // (the test checks that the drop happened).
  const std::uint64_t n = 1500;
  std::optional<std::uint64_t> dropped_at;  // the sample that did not fit
  publishFromTimer(0, n, 40, [&](std::uint64_t k) {
    if (!dropped_at && server_->clientCount() == 2) dropped_at = k;
  });
  collectConcurrently(loop_, {a.get(), b.get()}, {n, n / 2});
  const auto la = a->readLines(loop_, n);
  const auto lb = b->readLines(loop_, n / 2);
  ASSERT_EQ(la.size(), n);
  ASSERT_EQ(lb.size(), n / 2);
  for (std::size_t k = 0; k < n; ++k) expectRateLineCarries(la[k], syntheticSample(k));
  for (std::size_t k = 0; k < n / 2; ++k) expectRateLineCarries(lb[k], syntheticSample(2 * k));
  EXPECT_EQ(server_->clientCount(), 2u);
  const protocol::ServerStatus st = server_->serverStatus();
  EXPECT_EQ(st.clients_dropped, 1u);
  EXPECT_GT(st.lines_dropped, 0u);

  // What the stalled client did get is the stream from its start, in order, then EOF; at
  // most the beginning of one more line (the kernel may have taken part of it).
  const auto got = stalled->readUntilClosed(loop_);
  EXPECT_TRUE(stalled->closedByServer());
  ASSERT_FALSE(got.empty());
  ASSERT_TRUE(dropped_at.has_value());
  ASSERT_LE(got.size(), *dropped_at);
  for (std::size_t k = 0; k < got.size(); ++k) expectRateLineCarries(got[k], syntheticSample(k));
  std::array<char, protocol::kMaxRateLineBytes> next_line;
  const std::size_t next_size = protocol::formatRateLine(syntheticSample(got.size()), next_line);
  EXPECT_EQ(std::string(next_line.data(), next_size).substr(0, stalled->partial().size()), stalled->partial());
  // Counted exactly what it missed up to and including the sample that did not fit.
  EXPECT_EQ(got.size() + st.lines_dropped, *dropped_at + 1);
}

// gyrod's arrangement: the lines published from another thread (its delivery thread) while
// the loop's thread serves requests, switches a watch on and off and drops a client that
// never reads. Every line reaches each reading watcher once and in order, none comes before
// the reply to WATCH true or after the reply to WATCH false, and only the deaf client is
// dropped and counted.
TEST_F(ServerTest, PublishingFromAnotherThreadLosesNothingAndDropsOnlyTheClientThatDoesNotRead) {
  daemon::ServerOptions options;
  options.client_buffer_bytes = 64 * 1024;
  options.publish_off_loop = true;
  startServer(options);
  auto reader = watcher();
  auto decimated = watcher(3);
  auto deaf = watcher();  // never reads: its buffer fills, and it is dropped
  auto requester = connect();
  auto toggler = connect();

  const std::uint64_t n = 6000;
  const std::uint64_t gap_every = 500;
  struct Expected {
    bool gap;
    std::uint64_t k;
  };
  std::vector<Expected> expected, expected_decimated;
  for (std::uint64_t k = 0; k < n; ++k) {
    expected.push_back({false, k});
    if (k % 3 == 0) expected_decimated.push_back({false, k});
    if (k % gap_every == gap_every - 1) {
      expected.push_back({true, k});
      expected_decimated.push_back({true, k});
    }
  }
  auto gapFor = [](std::uint64_t k) { return protocol::GapEvent{5'000'000 + k, 2, "fifo_overflow"}; };

  std::atomic<std::uint64_t> reader_lines{0};
  std::atomic<bool> publishing{true};
  std::thread publisher([&] {
    std::uint64_t published_lines = 0;
    const auto guard = std::chrono::steady_clock::now() + 4 * kHangGuard;
    for (std::uint64_t k = 0; k < n; ++k) {
      // At most 100 lines (25 KB) ahead of the reader, so that only the deaf client fills its
      // buffer.
      while (published_lines > reader_lines.load() + 100 && std::chrono::steady_clock::now() < guard)
        std::this_thread::sleep_for(100us);
      server_->publishRate(syntheticSample(k));
      ++published_lines;
      if (k % gap_every == gap_every - 1) {
        server_->publishGap(gapFor(k));
        ++published_lines;
      }
    }
    publishing = false;
  });

  std::vector<std::string> reader_got, decimated_got;
  std::size_t status_sent = 0, status_got = 0, watch_cycles = 0;
  enum class Toggle { Off, On, AwaitOff } toggle = Toggle::Off;
  std::uint64_t toggler_seq = 0;  // the last RATE seq the toggler got, after toggler_rates > 0
  std::size_t toggler_rates = 0;
  std::string toggler_problem;
  toggler->send("{\"cmd\":\"watch\",\"enable\":true}\n");
  const auto deadline = std::chrono::steady_clock::now() + 4 * kHangGuard;
  while (std::chrono::steady_clock::now() < deadline) {
    loop_.runOnce(1ms);
    reader->drain();
    for (auto& l : reader->takeLines()) reader_got.push_back(std::move(l));
    reader_lines = reader_got.size();
    decimated->drain();
    for (auto& l : decimated->takeLines()) decimated_got.push_back(std::move(l));
    requester->drain();
    for (const auto& l : requester->takeLines()) {
      EXPECT_EQ(parse(l).value("class", ""), "STATUS") << l;
      ++status_got;
    }
    if (status_got == status_sent && publishing) {
      std::string batch;
      for (int i = 0; i < 20; ++i) batch += "{\"cmd\":\"status\"}\n";
      requester->send(batch);
      status_sent += 20;
    }
    toggler->drain();
    for (const auto& l : toggler->takeLines()) {
      const json j = parse(l);
      const std::string cls = j.value("class", "");
      if (toggle == Toggle::Off) {  // the reply to WATCH true comes first, nothing before it
        if (cls != "WATCH" || !j.value("enable", false)) {
          if (toggler_problem.empty()) toggler_problem = "before the reply to WATCH true: " + l;
          continue;
        }
        toggle = Toggle::On;
        toggler_rates = 0;
        continue;
      }
      if (cls == "WATCH") {
        if (toggle != Toggle::AwaitOff || j.value("enable", true)) {
          if (toggler_problem.empty()) toggler_problem = "unexpected " + l;
          continue;
        }
        toggle = Toggle::Off;  // nothing more until the next WATCH true is answered
        ++watch_cycles;
        if (publishing) toggler->send("{\"cmd\":\"watch\",\"enable\":true}\n");
        continue;
      }
      if (cls != "RATE") continue;
      const auto seq = j["seq"].get<std::uint64_t>();
      if (toggler_rates > 0 && seq != toggler_seq + 1 && toggler_problem.empty())
        toggler_problem = "seq " + std::to_string(seq) + " after " + std::to_string(toggler_seq);
      toggler_seq = seq;
      if (++toggler_rates == 50 && toggle == Toggle::On) {
        toggler->send("{\"cmd\":\"watch\",\"enable\":false}\n");
        toggle = Toggle::AwaitOff;
      }
    }
    if (!publishing && reader_got.size() >= expected.size() && decimated_got.size() >= expected_decimated.size() &&
        status_got == status_sent && server_->clientCount() == 4)
      break;
  }
  publisher.join();

  auto check = [](const std::vector<std::string>& got, const std::vector<Expected>& want, const char* who) {
    ASSERT_EQ(got.size(), want.size()) << who;
    for (std::size_t i = 0; i < got.size(); ++i) {
      if (want[i].gap) {
        const json j = json::parse(got[i]);
        ASSERT_EQ(j.value("class", ""), "GAP") << who << " line " << i << ": " << got[i];
        EXPECT_EQ(j["seq"].get<std::uint64_t>(), 5'000'000 + want[i].k) << who;
      } else {
        expectRateLineCarries(got[i], syntheticSample(want[i].k));
      }
    }
  };
  check(reader_got, expected, "reader");
  check(decimated_got, expected_decimated, "decimated watcher");
  EXPECT_EQ(status_got, status_sent);
  EXPECT_GT(status_sent, 0u);
  EXPECT_TRUE(toggler_problem.empty()) << toggler_problem;
  EXPECT_GE(watch_cycles, 2u);
  EXPECT_EQ(server_->clientCount(), 4u);
  const protocol::ServerStatus st = server_->serverStatus();
  EXPECT_EQ(st.clients_dropped, 1u);
  EXPECT_GT(st.lines_dropped, 0u);
  // The deaf client got the start of the stream, in order, then EOF; what it missed is counted.
  const auto deaf_got = deaf->readUntilClosed(loop_);
  EXPECT_TRUE(deaf->closedByServer());
  ASSERT_FALSE(deaf_got.empty());
  ASSERT_LT(deaf_got.size(), expected.size());
  check(deaf_got,
        std::vector<Expected>(expected.begin(), expected.begin() + static_cast<std::ptrdiff_t>(deaf_got.size())),
        "deaf client");
  EXPECT_LE(deaf_got.size() + st.lines_dropped, expected.size());
}

TEST_F(ServerTest, ClientLeavingMidStreamHurtsNobody) {
  startServer();
  auto a = watcher();
  auto leaver = watcher();
  auto b = watcher();
  publishFromTimer(0, 100, 2);
  ASSERT_EQ(leaver->readLines(loop_, 10).size(), 10u);
  leaver->close();  // mid-stream, with lines still queued for it (no SIGPIPE either)
  collectConcurrently(loop_, {a.get(), b.get()}, {100, 100});
  const auto la = a->readLines(loop_, 100);
  const auto lb = b->readLines(loop_, 100);
  ASSERT_EQ(la.size(), 100u);
  ASSERT_EQ(lb.size(), 100u);
  for (std::size_t k = 0; k < 100; ++k) {
    expectRateLineCarries(la[k], syntheticSample(k));
    expectRateLineCarries(lb[k], syntheticSample(k));
  }
  EXPECT_TRUE(pumpUntil(loop_, [&] { return server_->clientCount() == 2; }));
  EXPECT_EQ(server_->serverStatus().clients_dropped, 0u);  // leaving is not being dropped
}

TEST_F(ServerTest, ClientThatHalfClosesStillGetsItsReply) {
  startServer();
  auto c = connect();
  c->send("{\"cmd\":\"status\"}\n");
  ASSERT_EQ(::shutdown(c->fd(), SHUT_WR), 0);
  const auto lines = c->readUntilClosed(loop_);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(parse(lines[0])["class"], "STATUS");
  EXPECT_TRUE(pumpUntil(loop_, [&] { return server_->clientCount() == 0; }));
}

TEST_F(ServerTest, TooManyClientsAreRefusedWithAnError) {
  daemon::ServerOptions options;
  options.max_clients = 2;
  startServer(options);
  auto a = connect();
  auto b = connect();
  TestClient third(socketPath());
  const auto lines = third.readUntilClosed(loop_);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(parse(lines[0])["code"], "too_many_clients");
  EXPECT_EQ(server_->clientCount(), 2u);
}

TEST_F(ServerTest, SocketFileIsRemovedAtShutdownButNotAReplacement) {
  startServer();
  ASSERT_TRUE(std::filesystem::exists(socketPath()));
  server_.reset();
  EXPECT_FALSE(std::filesystem::exists(socketPath()));

  startServer();
  // Another process replaced the file meanwhile: the old server must leave it alone.
  std::filesystem::remove(socketPath());
  makeStaleSocketFile(socketPath());
  struct stat before {};
  ASSERT_EQ(::stat(socketPath().c_str(), &before), 0);
  server_.reset();
  struct stat after {};
  ASSERT_EQ(::stat(socketPath().c_str(), &after), 0);
  EXPECT_EQ(before.st_ino, after.st_ino);
}

// ---- the listening socket ----------------------------------------------------------------

TEST(ListeningSocket, StaleSocketFileIsReplaced) {
  ScratchDir dir;
  const std::string path = (dir.path() / "gyrod.sock").string();
  makeStaleSocketFile(path);
  ASSERT_TRUE(std::filesystem::is_socket(path));
  daemon::SocketOptions so;
  so.path = path;
  daemon::EventLoop loop;
  FakeContent content;
  daemon::UnixSocketServer server(loop, daemon::bindListeningSocket(so), content);
  TestClient c(path);
  EXPECT_EQ(c.readObject(loop)["class"], "VERSION");
}

TEST(ListeningSocket, LiveSocketIsNotStolen) {
  ScratchDir dir;
  const std::string path = (dir.path() / "gyrod.sock").string();
  daemon::SocketOptions so;
  so.path = path;
  daemon::EventLoop loop;
  FakeContent content;
  daemon::UnixSocketServer first(loop, daemon::bindListeningSocket(so), content);
  try {
    daemon::bindListeningSocket(so);
    ADD_FAILURE() << "a second server took over a live socket";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("already in use"), std::string::npos) << e.what();
  }
  TestClient c(path);  // the first one still serves
  EXPECT_EQ(c.readObject(loop)["class"], "VERSION");
}

TEST(ListeningSocket, OtherFilesAreNeverReplaced) {
  ScratchDir dir;
  const auto path = dir.write("gyrod.sock", "precious");
  daemon::SocketOptions so;
  so.path = path.string();
  try {
    daemon::bindListeningSocket(so);
    ADD_FAILURE() << "replaced a regular file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("is not a socket"), std::string::npos) << e.what();
  }
  EXPECT_EQ(readWholeFile(path), "precious");
}

TEST(ListeningSocket, ModeGroupAndParentFolderAreApplied) {
  ScratchDir dir;
  const std::string path = (dir.path() / "run" / "gyrod" / "gyrod.sock").string();
  const group* g = ::getgrgid(::getegid());
  ASSERT_NE(g, nullptr);
  daemon::SocketOptions so;
  so.path = path;
  so.mode = 0640;
  so.group = std::string(g->gr_name);
  const daemon::ListeningSocket ls = daemon::bindListeningSocket(so);
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_TRUE(S_ISSOCK(st.st_mode));
  EXPECT_EQ(st.st_mode & 0777, 0640u);
  EXPECT_EQ(st.st_gid, ::getegid());
  ASSERT_EQ(::stat((dir.path() / "run" / "gyrod").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0755u);

  so.path = (dir.path() / "other.sock").string();
  so.mode = 0600;
  so.group.reset();
  const daemon::ListeningSocket ls2 = daemon::bindListeningSocket(so);
  ASSERT_EQ(::stat(so.path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
}

TEST(ListeningSocket, BadOptionsAreNamed) {
  ScratchDir dir;
  daemon::SocketOptions so;
  so.path = (dir.path() / "g.sock").string();
  so.group = "no-such-group-gyrod-test";
  try {
    daemon::bindListeningSocket(so);
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'no-such-group-gyrod-test' does not exist"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(so.path));
  so.group.reset();
  so.mode = 01777;
  EXPECT_THROW(daemon::bindListeningSocket(so), std::invalid_argument);
  so.mode = 0660;
  so.path = "/tmp/" + std::string(200, 'x') + ".sock";
  try {
    daemon::bindListeningSocket(so);
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("must be shorter than 108"), std::string::npos) << e.what();
  }
}

TEST(ListeningSocket, NoActivationWithoutSystemd) {
  ::unsetenv("LISTEN_FDS");
  ::unsetenv("LISTEN_PID");
  EXPECT_FALSE(daemon::adoptActivatedSocket().has_value());
}

// systemd passes sockets as fds 3, 4, ... with LISTEN_PID, LISTEN_FDS and LISTEN_FDNAMES.
// The child process stands in for gyrod started by systemd: "other" at fd 3, "gyrod" at 4.
TEST(ListeningSocket, SocketActivationTakesTheFdNamedGyrod) {
  ScratchDir dir;
  const std::string path = (dir.path() / "activated.sock").string();
  daemon::SocketOptions so;
  so.path = path;
  daemon::ListeningSocket ls = daemon::bindListeningSocket(so);
  const protocol::Fd other(::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0));
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    // Child: only async-signal-safe work until the checks; report through the exit code.
    // Move both out of the way first: either may itself be fd 3 or 4.
    const int other_high = ::fcntl(other.get(), F_DUPFD, 100);
    const int listen_high = ::fcntl(ls.fd.get(), F_DUPFD, 100);
    if (other_high < 0 || listen_high < 0) ::_exit(10);
    if (::dup2(other_high, SD_LISTEN_FDS_START) < 0 || ::dup2(listen_high, SD_LISTEN_FDS_START + 1) < 0) ::_exit(10);
    const std::string my_pid = std::to_string(::getpid());
    ::setenv("LISTEN_PID", my_pid.c_str(), 1);
    ::setenv("LISTEN_FDS", "2", 1);
    ::setenv("LISTEN_FDNAMES", "other:gyrod", 1);
    try {
      const auto adopted = daemon::adoptActivatedSocket("gyrod");
      if (!adopted) ::_exit(11);
      if (adopted->fd.get() != SD_LISTEN_FDS_START + 1 || !adopted->activated || !adopted->path.empty()) ::_exit(12);
      if (::sd_is_socket_unix(adopted->fd.get(), SOCK_STREAM, 1, path.c_str(), 0) <= 0) ::_exit(13);
      if (!(::fcntl(adopted->fd.get(), F_GETFL) & O_NONBLOCK)) ::_exit(14);
      // Asking for a name nobody passed is an error naming what was passed.
      try {
        daemon::adoptActivatedSocket("missing");
        ::_exit(15);
      } catch (const std::runtime_error& e) {
        if (std::string(e.what()).find("(other, gyrod)") == std::string::npos) ::_exit(16);
      }
      // A non-listening fd under the wanted name is refused.
      try {
        daemon::adoptActivatedSocket("other");
        ::_exit(17);
      } catch (const std::runtime_error& e) {
        if (std::string(e.what()).find("not a listening Unix stream socket") == std::string::npos) ::_exit(18);
      }
      std::fflush(nullptr);
      ::_exit(0);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "child: %s\n", e.what());
      ::_exit(19);
    }
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "child check " << WEXITSTATUS(status) << " failed";
}
