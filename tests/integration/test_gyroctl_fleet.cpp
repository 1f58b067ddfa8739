// gyroctl fleet against a real broker (Debian's mosquitto) and real gyrods on the mock: every
// board that publishes is a row, with its state, rate messages and counts; a board killed
// without a clean stop turns "offline" through its last will; an unreachable broker or a bad
// URL is one line and a sysexits status.
#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "gyrod_process.hpp"
#include "mqtt_broker.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using namespace std::chrono_literals;
using nlohmann::json;

namespace {

std::string boardConfig(const ScratchDir& d, int port, const std::string& board) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[bias]\nsource = \"config\"\nvalues = [-3.34, 1.09, -0.5]\n"
    << "[socket]\npath = \"" << (d.path() / (board + ".sock")).string() << "\"\n"
    << "[mqtt]\nurl = \"mqtt://127.0.0.1:" << port << "\"\nprefix = \"fleet-test/" << board << "\"\nclient_id = \""
    << board << "\"\nrate_every = 5\n";
  return c.str();
}

// `gyroctl fleet --once --json` until `pred` holds for its boards (or 30 s): the last reading.
template <typename Pred>
json fleetUntil(const ScratchDir& d, int port, Pred pred) {
  json boards;
  const auto until = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < until) {
    const auto r = runGyroctl(
        "fleet --broker mqtt://127.0.0.1:" + std::to_string(port) + " --root fleet-test --once --json --wait 1",
        d.path());
    if (r.exit_status != 0) return json{{"error", r.err}};
    boards = json::parse(r.out)["boards"];
    if (pred(boards)) return boards;
  }
  return boards;
}

const json* board(const json& boards, const std::string& name) {
  for (const auto& b : boards)
    if (b["board"] == name) return &b;
  return nullptr;
}

bool streaming(const json& boards, const std::string& name) {
  const json* b = board(boards, name);
  return b != nullptr && (*b)["state"] == "online" && (*b)["rate_messages"].get<int>() > 0;
}

}  // namespace

TEST(GyroctlFleet, ShowsEveryBoardOnTheBrokerAndTheOneThatDied) {
  const int port = freeLoopbackPort();
  Broker broker(port);
  ScratchDir d;
  GyrodProcess one({"--config", d.write("one.toml", boardConfig(d, port, "board-1")).string()}, d.path() / "1.log");
  GyrodProcess two({"--config", d.write("two.toml", boardConfig(d, port, "board-2")).string()}, d.path() / "2.log");
  json boards = fleetUntil(d, port, [](const json& b) { return streaming(b, "board-1") && streaming(b, "board-2"); });
  ASSERT_TRUE(streaming(boards, "board-1") && streaming(boards, "board-2"))
      << boards.dump() << "\n"
      << readWholeFile(d.path() / "1.log") << readWholeFile(d.path() / "2.log");
  for (const char* name : {"board-1", "board-2"}) {
    const json& b = *board(boards, name);
    EXPECT_EQ(b["rate_hz"], 50.0);
    EXPECT_EQ(b["samples_lost"], 0);
    EXPECT_GT(b["seq"].get<std::uint64_t>(), 0u);
    EXPECT_TRUE(b.contains("rate") || b.contains("raw")) << b.dump();
    // 50 Hz, every 5th line: about 10 messages a second.
    EXPECT_GT(b["messages_per_s"].get<double>(), 5.0) << b.dump();
    EXPECT_LT(b["messages_per_s"].get<double>(), 20.0) << b.dump();
  }

  two.signal(SIGKILL);  // no clean stop: the broker publishes its last will
  two.waitExit(5s);
  boards = fleetUntil(d, port, [](const json& b) {
    const json* two = board(b, "board-2");
    return two != nullptr && (*two)["state"] == "offline" && streaming(b, "board-1");
  });
  ASSERT_NE(board(boards, "board-2"), nullptr) << boards.dump();
  EXPECT_EQ((*board(boards, "board-2"))["state"], "offline") << boards.dump();
  EXPECT_TRUE(streaming(boards, "board-1")) << boards.dump();

  // The table a person reads: a header and a row per board.
  const auto r =
      runGyroctl("fleet --broker mqtt://127.0.0.1:" + std::to_string(port) + " --root fleet-test --once", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("board ", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("board-1              online"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("board-2              offline"), std::string::npos) << r.out;
}

TEST(GyroctlFleet, AnUnreachableBrokerOrABadUrlIsOneLineAndASysexitsStatus) {
  ScratchDir d;
  const int port = freeLoopbackPort();  // nobody listens there
  auto r = runGyroctl("fleet --broker mqtt://127.0.0.1:" + std::to_string(port) + " --once", d.path());
  EXPECT_EQ(r.exit_status, 69) << r.err;
  EXPECT_EQ(r.err,
            "gyroctl: fleet: cannot read the broker at 127.0.0.1:" + std::to_string(port) + ": Connection refused\n");
  r = runGyroctl("fleet --broker http://example.org --once", d.path());
  EXPECT_EQ(r.exit_status, 64) << r.err;
  EXPECT_EQ(r.err, "gyroctl: --broker 'http://example.org': must be mqtt://HOST[:PORT] or mqtts://HOST[:PORT] (TLS)\n");
  EXPECT_TRUE(r.out.empty());
}
