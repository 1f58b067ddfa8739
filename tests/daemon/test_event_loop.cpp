// The event loop: fds, timers and signals behind one interface, and sources that remove
// each other (or themselves) while a batch is being dispatched.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "daemon/event_loop.hpp"
#include "protocol/fd.hpp"

using namespace gyrod::daemon;
using namespace std::chrono_literals;

namespace {

struct Pipe {
  Fd read_end, write_end;
  Pipe() {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC | O_NONBLOCK) != 0) throw errnoError("pipe2");
    read_end.reset(fds[0]);
    write_end.reset(fds[1]);
  }
  void put(char c) { ASSERT_EQ(::write(write_end.get(), &c, 1), 1); }
};

// Runs the loop until it stops, with a one-shot guard that fails the test if it hangs.
void runGuarded(EventLoop& loop) {
  bool guard_fired = false;
  const auto guard = loop.addOneShotTimer(5s, [&](std::uint64_t) {
    guard_fired = true;
    loop.stop();
  });
  loop.run();
  loop.removeSource(guard);
  EXPECT_FALSE(guard_fired) << "the loop did not stop by itself";
}

}  // namespace

TEST(Fd, ClosesOnceAndMovesOwnership) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  {
    Fd a(fds[0]);
    Fd b(std::move(a));
    EXPECT_FALSE(a.valid());
    EXPECT_EQ(b.get(), fds[0]);
    Fd c;
    c = std::move(b);
    EXPECT_EQ(c.get(), fds[0]);
  }
  EXPECT_EQ(::fcntl(fds[0], F_GETFD), -1);  // closed by c
  EXPECT_EQ(errno, EBADF);
  Fd w(fds[1]);
  const int raw = w.release();
  EXPECT_FALSE(w.valid());
  EXPECT_EQ(::close(raw), 0);  // release() did not close it
}

TEST(EventLoop, FdCallbackSeesReadableData) {
  EventLoop loop;
  Pipe p;
  int calls = 0;
  loop.addFd(p.read_end.get(), EPOLLIN, [&](std::uint32_t events) {
    EXPECT_TRUE(events & EPOLLIN);
    char c = 0;
    ASSERT_EQ(::read(p.read_end.get(), &c, 1), 1);
    EXPECT_EQ(c, 'x');
    ++calls;
    loop.stop();
  });
  p.put('x');
  runGuarded(loop);
  EXPECT_EQ(calls, 1);
  EXPECT_TRUE(loop.watches(p.read_end.get()));
  loop.removeFd(p.read_end.get());
  EXPECT_FALSE(loop.watches(p.read_end.get()));
}

TEST(EventLoop, RejectsBadFds) {
  EventLoop loop;
  Pipe p;
  EXPECT_THROW(loop.addFd(-1, EPOLLIN, [](std::uint32_t) {}), std::invalid_argument);
  loop.addFd(p.read_end.get(), EPOLLIN, [](std::uint32_t) {});
  EXPECT_THROW(loop.addFd(p.read_end.get(), EPOLLIN, [](std::uint32_t) {}), std::invalid_argument);
  EXPECT_THROW(loop.modifyFd(p.write_end.get(), EPOLLOUT), std::invalid_argument);
  EXPECT_THROW(loop.addPeriodicTimer(0ns, [](std::uint64_t) {}), std::invalid_argument);
  EXPECT_THROW(loop.addOneShotTimer(-1ms, [](std::uint64_t) {}), std::invalid_argument);
}

TEST(EventLoop, PeriodicTimerKeepsFiringUntilRemoved) {
  EventLoop loop;
  std::uint64_t expirations = 0;
  int callbacks = 0;
  EventLoop::SourceId id = 0;
  id = loop.addPeriodicTimer(1ms, [&](std::uint64_t n) {
    EXPECT_GE(n, 1u);
    expirations += n;
    if (++callbacks == 5) {
      loop.removeSource(id);  // removing itself from inside its own callback is safe
      loop.stop();
    }
  });
  runGuarded(loop);
  EXPECT_EQ(callbacks, 5);
  EXPECT_GE(expirations, 5u);
  // Removed: nothing fires any more.
  EXPECT_EQ(loop.runOnce(20ms), 0u);
}

TEST(EventLoop, OneShotTimerFiresOnce) {
  EventLoop loop;
  int shots = 0;
  loop.addOneShotTimer(1ms, [&](std::uint64_t n) {
    EXPECT_EQ(n, 1u);
    ++shots;
  });
  loop.addOneShotTimer(30ms, [&](std::uint64_t) { loop.stop(); });
  runGuarded(loop);
  EXPECT_EQ(shots, 1);
}

TEST(EventLoop, SourceRemovedEarlierInTheBatchIsNotDispatched) {
  EventLoop loop;
  Pipe a, b;
  int calls = 0;
  // Whichever callback runs first removes the other, although both are ready in the same
  // epoll batch: the second must not run (its owner may already be destroyed).
  loop.addFd(a.read_end.get(), EPOLLIN, [&](std::uint32_t) {
    ++calls;
    loop.removeFd(b.read_end.get());
  });
  loop.addFd(b.read_end.get(), EPOLLIN, [&](std::uint32_t) {
    ++calls;
    loop.removeFd(a.read_end.get());
  });
  a.put('1');
  b.put('2');
  EXPECT_EQ(loop.runOnce(1s), 2u);  // both were in the batch
  EXPECT_EQ(calls, 1);
}

TEST(EventLoop, SignalsArriveThroughTheSignalfd) {
  EventLoop loop;
  std::vector<int> received;
  loop.addSignals({SIGUSR1, SIGUSR2}, [&](int signo) {
    received.push_back(signo);
    if (received.size() == 2) loop.stop();
  });
  // Blocked now, so raise() leaves them pending for the signalfd instead of killing us.
  ASSERT_EQ(::raise(SIGUSR2), 0);
  ASSERT_EQ(::raise(SIGUSR1), 0);
  runGuarded(loop);
  ASSERT_EQ(received.size(), 2u);
  EXPECT_NE(std::find(received.begin(), received.end(), SIGUSR1), received.end());
  EXPECT_NE(std::find(received.begin(), received.end(), SIGUSR2), received.end());
  sigset_t mask;
  ASSERT_EQ(::pthread_sigmask(SIG_BLOCK, nullptr, &mask), 0);
  EXPECT_EQ(sigismember(&mask, SIGUSR1), 1);
}

TEST(EventLoop, CallbackExceptionsReachTheCaller) {
  EventLoop loop;
  loop.addOneShotTimer(1ms, [](std::uint64_t) { throw std::runtime_error("sensor failed"); });
  EXPECT_THROW(
      {
        for (int i = 0; i < 100; ++i) loop.runOnce(100ms);
      },
      std::runtime_error);
}

TEST(EventLoop, DeferredWorkRunsAfterTheNextTurnsEventsWithoutWaiting) {
  EventLoop loop;
  std::vector<int> order;
  loop.defer([&] {
    order.push_back(1);
    loop.defer([&] { order.push_back(2); });  // deferred during a turn: the next turn
  });
  const auto start = std::chrono::steady_clock::now();
  loop.runOnce(10s);  // does not wait: work is deferred
  EXPECT_EQ(order, std::vector<int>({1}));
  loop.runOnce(10s);
  EXPECT_EQ(order, std::vector<int>({1, 2}));
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
  EXPECT_GT(loop.longestTurn().count(), 0);
}
