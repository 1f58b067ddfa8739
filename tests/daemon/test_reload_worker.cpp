// SIGHUP's reload off the loop (daemon/reload_worker.hpp): the loop keeps turning while a
// load runs, applies only a finished result, and gives up on a load past its time limit.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "daemon/event_loop.hpp"
#include "daemon/reload_worker.hpp"

using gyrod::daemon::EventLoop;
using gyrod::daemon::ReloadWorker;
using namespace std::chrono_literals;

namespace {

// Turns `loop` until `done` or `limit`; returns how long that took.
std::chrono::steady_clock::duration turnReloadLoopUntil(EventLoop& loop, const std::function<bool()>& done,
                                                        std::chrono::milliseconds limit) {
  const auto start = std::chrono::steady_clock::now();
  while (!done() && std::chrono::steady_clock::now() - start < limit) loop.runOnce(5ms);
  return std::chrono::steady_clock::now() - start;
}

}  // namespace

TEST(ReloadWorker, AFinishedLoadIsAppliedOnTheLoopThread) {
  EventLoop loop;
  std::optional<int> applied;
  std::string failure;
  std::thread::id applied_on;
  ReloadWorker<int> worker(
      loop, 2000ms, [] { return 42; },
      [&](int&& v) {
        applied = v;
        applied_on = std::this_thread::get_id();
      },
      [&](const std::string& why) { failure = why; });
  worker.request();
  EXPECT_TRUE(worker.running());
  turnReloadLoopUntil(
      loop, [&] { return applied.has_value(); }, 5000ms);
  EXPECT_EQ(applied, std::optional<int>(42));
  EXPECT_EQ(applied_on, std::this_thread::get_id());
  EXPECT_TRUE(failure.empty()) << failure;
  EXPECT_FALSE(worker.running());
}

TEST(ReloadWorker, AFailedLoadIsReportedAndNothingApplied) {
  EventLoop loop;
  bool applied = false;
  std::string failure;
  ReloadWorker<int> worker(
      loop, 2000ms, []() -> int { throw std::runtime_error("x.toml:3: key 'filter.model': no such file"); },
      [&](int&&) { applied = true; }, [&](const std::string& why) { failure = why; });
  worker.request();
  turnReloadLoopUntil(
      loop, [&] { return !failure.empty(); }, 5000ms);
  EXPECT_EQ(failure, "x.toml:3: key 'filter.model': no such file");
  EXPECT_FALSE(applied);
}

// A load that hangs (a file on a stuck network mount) is abandoned at its limit; the loop was
// never held, and the result that comes later is dropped.
TEST(ReloadWorker, ALoadPastItsLimitIsAbandonedWithoutHoldingTheLoop) {
  EventLoop loop;
  std::atomic<bool> release{false};
  bool applied = false;
  std::string failure;
  int ticks = 0;
  loop.addPeriodicTimer(10ms, [&](std::uint64_t) { ++ticks; });
  ReloadWorker<int> worker(
      loop, 200ms,
      [&release] {
        while (!release) std::this_thread::sleep_for(1ms);
        return 1;
      },
      [&](int&&) { applied = true; }, [&](const std::string& why) { failure = why; });
  worker.request();
  const auto took = turnReloadLoopUntil(
      loop, [&] { return !failure.empty(); }, 5000ms);
  EXPECT_GE(took, 190ms);
  EXPECT_LT(took, 1000ms);
  EXPECT_NE(failure.find("took longer than 200 ms"), std::string::npos) << failure;
  EXPECT_GE(ticks, 10);  // the loop went on turning meanwhile
  EXPECT_FALSE(worker.running());
  release = true;
  turnReloadLoopUntil(
      loop, [] { return false; }, 100ms);
  EXPECT_FALSE(applied);
}

// A SIGHUP during a reload is not lost: one more reload runs after it, reading the last edit.
TEST(ReloadWorker, ARequestDuringALoadRunsOneMoreAfterIt) {
  EventLoop loop;
  std::atomic<int> loads{0};
  std::atomic<bool> release{false};
  std::vector<int> applied;
  ReloadWorker<int> worker(
      loop, 5000ms,
      [&] {
        const int n = ++loads;
        while (n == 1 && !release) std::this_thread::sleep_for(1ms);
        return n;
      },
      [&](int&& v) { applied.push_back(v); }, [](const std::string&) {});
  worker.request();
  worker.request();
  worker.request();  // still one more, not two
  release = true;
  turnReloadLoopUntil(
      loop, [&] { return applied.size() >= 2; }, 5000ms);
  turnReloadLoopUntil(
      loop, [] { return false; }, 100ms);
  EXPECT_EQ(applied, (std::vector<int>{1, 2}));
  EXPECT_EQ(loads.load(), 2);
}
