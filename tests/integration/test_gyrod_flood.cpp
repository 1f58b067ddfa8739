// The samples never wait on a client. gyrod on the real-time mock while clients flood it:
// ALLAN and STATUS requests in batches of 50 per write, a client pipelining 10,000 requests per
// write, one that never reads its replies and one that watches but never reads.
//  - 1 kHz with a 1 h Allan window (3.6 M samples per stream) and a refit every second: the
//    chip's FIFO lasts ~73 ms (1024 bytes of 14-byte accel + gyro frames);
//  - 8 kHz (DLPF 0), gyro only, with a 60 s window: the FIFO lasts ~16 ms (1024 bytes of 8-byte
//    temperature + gyro frames; with the accel gyrod refuses rates above its 1 kHz output rate).
// Any sample-loop turn longer than that loses samples, which a watching client sees as a GAP
// line. Asserts none, contiguous sequence numbers, a loop turn far inside the FIFO, and the
// watcher's edge → line latency. A loss is gyrod's unless one CPU of the machine itself stood
// still for half a FIFO or more in the two FIFOs' time before it, in one stop or in many, or
// a stop of half a FIFO ended in the 0.5 s before it:
// probes above gyrod's priority time each CPU (machine_stall_probe.hpp), and on a virtual
// machine with both CPUs busy the host stops a CPU for 5-15 ms now and then, or, on a crowded
// host, for 2-7 ms a hundred times a second (docs/driver.md "Under a flood of requests").
//
// Real time (mock speed 1), because the accelerated mock slows its virtual clock down when
// the loop is late instead of overflowing the FIFO. The window cannot fill in the test's
// time, so what it measures at 3.6 M samples is what does not depend on the fill: the copy
// of a raw stream for the refit worker (the whole ring, every refit) and the per-request
// costs; the refit's own O(fill) work runs on the worker thread.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <ctime>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <thread>

#include "binary_command.hpp"
#include "gyrod_process.hpp"
#include "machine_stall_probe.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

constexpr auto kFloodTime = 12s;

struct FloodSetup {
  int rate_hz = 1000;
  int dlpf = 1;
  int window_s = 3600;
  bool accel = true;

  double fifoMs() const { return 1024.0 / (accel ? 14.0 : 8.0) / rate_hz * 1e3; }
};

std::string floodConfig(const std::filesystem::path& dir, const FloodSetup& setup) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = " << setup.rate_hz << "\ndlpf = " << setup.dlpf << "\n"
    << "accel = " << (setup.accel ? "true" : "false") << "\n"
    << "[bias]\nsource = \"config\"\nvalues = [-3.34, 1.09, -0.5]\n"
    << "[filter]\nmean_window = 20\nmean_threshold_dps = 0.3\n"
    << "[filter.kalman]\na = 0.9\nq = 0.0001\nr = 0.01\n"
    << "[allan]\nwindow_s = " << setup.window_s << "\nrefit_interval_s = 1\n"
    << "[socket]\npath = \"" << (dir / "gyrod.sock").string() << "\"\n"
    << "[mock]\nspeed = 1\nseed = 5\n";
  return c.str();
}

// gyrod's log lines for a FIFO overflow ("2026-11-28 20:13:06.403 warning FIFO overflow on ...")
// that the machine does not explain. The overflow happened in the two FIFOs' time before the
// line; it is the machine's when one CPU stood still for half a FIFO or more of that time, in
// one stop or in many short ones (MachineStallProbe::stolenMsBefore), or when a stop of half a
// FIFO or more ended in the 0.5 s before the line (a long stop leaves the threads behind: the
// delivery thread's backlog, a client thread stopped while it held the state lock); gyrod's
// otherwise. The stamp is local wall-clock time to the millisecond, as gyrod's log writes it.
std::string overflowsTheMachineDoesNotExplain(const std::string& log_text, const MachineStallProbe& machine,
                                              double fifo_ms) {
  static const std::regex kOverflow(R"(^(\d{4})-(\d{2})-(\d{2}) (\d{2}):(\d{2}):(\d{2})\.(\d{3}) \S+ FIFO overflow)");
  std::string unexplained;
  std::istringstream lines(log_text);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, kOverflow)) continue;
    std::tm tm{};
    tm.tm_year = std::stoi(m[1]) - 1900;
    tm.tm_mon = std::stoi(m[2]) - 1;
    tm.tm_mday = std::stoi(m[3]);
    tm.tm_hour = std::stoi(m[4]);
    tm.tm_min = std::stoi(m[5]);
    tm.tm_sec = std::stoi(m[6]);
    tm.tm_isdst = -1;
    const double logged_s = static_cast<double>(std::mktime(&tm)) + std::stoi(m[7]) * 1e-3;
    const double at_s = machine.monotonicFromRealtime(logged_s) + 0.002;  // the stamp's truncation, and rounding
    const double stolen_ms = machine.stolenMsBefore(at_s, 2 * fifo_ms * 1e-3);
    if (stolen_ms < fifo_ms / 2 && !machine.stalledBefore(at_s, 0.5, fifo_ms / 2))
      unexplained += line + " (one CPU stood still " + std::to_string(stolen_ms) + " ms before it, no stop of " +
                     std::to_string(fifo_ms / 2) + " ms in the 0.5 s before)\n";
  }
  return unexplained;
}

std::string repeated(const std::string& line, std::size_t times) {
  std::string all;
  for (std::size_t i = 0; i < times; ++i) all += line;
  return all;
}

// Sends `batch` copies of `request` (one or more lines) per write and reads every reply, until `stop`.
void requestInBatches(const std::string& socket, const std::string& request, std::size_t batch,
                      const std::atomic<bool>& stop, std::atomic<std::uint64_t>& replies) {
  LineClient c(socket);
  if (!c.connected() || !c.readLine()) return;  // VERSION
  const std::string write = repeated(request, batch);
  const auto lines = static_cast<std::size_t>(std::count(write.begin(), write.end(), '\n'));
  while (!stop) {
    if (!c.send(write)) return;
    for (std::size_t i = 0; i < lines; ++i) {
      if (!c.readLine(20s)) return;
      ++replies;
    }
  }
}

// The 1, 5 and 15 minute load averages (/proc/loadavg): what else the machine ran meanwhile.
std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

// The tests that run gyrod SCHED_FIFO take turns: ctest runs them alone (RUN_SERIAL,
// tests/CMakeLists.txt), and this lock keeps two of them apart when they are run otherwise
// (two test binaries, gtest filters by hand): each measures one real-time gyrod on the machine,
// not two of them and their real-time watchers competing for 2 CPUs. Released when the test
// ends (the lock goes with the descriptor).
class RealTimeTurn {
 public:
  RealTimeTurn() : fd_(::open("/tmp/gyrod-tests-real-time.lock", O_CREAT | O_RDWR | O_CLOEXEC, 0666)) {
    if (fd_ >= 0) ::flock(fd_, LOCK_EX);
  }
  ~RealTimeTurn() {
    if (fd_ >= 0) ::close(fd_);
  }
  RealTimeTurn(const RealTimeTurn&) = delete;
  RealTimeTurn& operator=(const RealTimeTurn&) = delete;

 private:
  int fd_;
};

double monotonicSeconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

void floodAndCheck(const FloodSetup& setup) {
  const RealTimeTurn turn_of_this_test;
  const double fifo_ms = setup.fifoMs();
  const MachineStallProbe machine;
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", floodConfig(d.path(), setup));
  const auto log = d.path() / "log.txt";
  // gyrod runs SCHED_FIFO as its systemd unit runs it (CPUSchedulingPolicy=fifo): what is
  // measured is then the loop's own turns, not how long a loaded test machine leaves it
  // unscheduled (SCHED_OTHER at load 6: one 235 ms turn, 235 samples lost). Its delivery thread
  // runs SCHED_FIFO one step below and only moves the lines to the clients; its client thread
  // is never real-time and its requests take at most half a CPU, so however hard it is flooded
  // the real-time threads stay light and far from the kernel's real-time throttling.
  // Where real-time scheduling is refused (no CAP_SYS_NICE, no RLIMIT_RTPRIO) it runs as it
  // can, and the test says so.
  GyrodProcess gyrod({"--config", cfg.string()}, log, [] {
    sched_param fifo{};
    fifo.sched_priority = 10;
    ::sched_setscheduler(0, SCHED_FIFO, &fifo);
  });
  const std::string socket = (d.path() / "gyrod.sock").string();
  LineClient watcher(socket);
  ASSERT_TRUE(watcher.connected()) << readWholeFile(log);
  ASSERT_TRUE(watcher.readLine());  // VERSION
  ASSERT_TRUE(watcher.send("{\"cmd\":\"watch\",\"enable\":true}\n"));

  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> allan_replies{0}, status_replies{0}, pipelined_replies{0};
  std::vector<std::thread> clients;
  for (int i = 0; i < 4; ++i)
    clients.emplace_back([&] { requestInBatches(socket, "{\"cmd\":\"allan\"}\n", 50, stop, allan_replies); });
  for (int i = 0; i < 2; ++i)
    clients.emplace_back([&] { requestInBatches(socket, "{\"cmd\":\"status\"}\n", 50, stop, status_replies); });
  clients.emplace_back(
      [&] { requestInBatches(socket, "{\"cmd\":\"status\"}\n{\"cmd\":\"allan\"}\n", 5'000, stop, pipelined_replies); });
  // Never reads: its requests are answered until its buffer is full, then it waits (and is
  // dropped after 10 s without reading). Never reads its RATE lines: dropped when full.
  LineClient deaf(socket), deaf_watcher(socket);
  std::thread deaf_sender([&] { deaf.send(repeated("{\"cmd\":\"allan\"}\n", 10'000)); });
  deaf_watcher.send("{\"cmd\":\"watch\",\"enable\":true}\n");
  // The watcher itself real-time too (after the flooders are started: they must not inherit
  // it), as a latency-sensitive client runs: its lateness is then gyrod's, not its own.
  sched_param watcher_priority{};
  watcher_priority.sched_priority = 9;  // below gyrod's sample thread: it never holds a CPU from it
  const bool watcher_real_time = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &watcher_priority) == 0;

  std::uint64_t rates = 0, gaps = 0;
  std::optional<std::uint64_t> first_seq, last_seq;
  std::string first_problem;  // a silent break in the sequence, or silence
  bool after_gap = false;
  std::vector<double> latency_ms;
  latency_ms.reserve(static_cast<std::size_t>(setup.rate_hz) * 13);
  const std::string load_before = loadAverage();
  const auto until = std::chrono::steady_clock::now() + kFloodTime;
  while (std::chrono::steady_clock::now() < until) {
    const auto line = watcher.readLine(2s);
    const double arrived_s = monotonicSeconds();
    if (!line) {
      first_problem = first_problem.empty() ? "the watcher got no line for 2 s" : first_problem;
      break;
    }
    const json j = json::parse(*line);
    if (j["class"] == "GAP") {
      after_gap = true;
      ++gaps;
    } else if (j["class"] == "RATE") {
      const auto seq = j["seq"].get<std::uint64_t>();
      if (last_seq && seq != *last_seq + 1 && !after_gap && first_problem.empty())
        first_problem = "seq " + std::to_string(seq) + " after " + std::to_string(*last_seq) + " with no GAP line";
      after_gap = false;
      if (!first_seq) first_seq = seq;
      last_seq = seq;
      latency_ms.push_back((arrived_s - j["t"].get<double>()) * 1e3);
      ++rates;
    }
  }
  const sched_param normal{};
  ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &normal);
  stop = true;
  gyrod.signal(SIGTERM);
  for (auto& t : clients) t.join();
  ::shutdown(deaf.fd(), SHUT_RDWR);
  deaf_sender.join();
  const auto status = gyrod.waitExit(10s);
  ASSERT_TRUE(status.has_value()) << "gyrod did not exit within 10 s of SIGTERM";
  EXPECT_EQ(*status, 0);

  const std::string text = readWholeFile(log);
  // The shutdown line: "stopped after N samples, G gaps (L samples lost)...; longest loop turn T us".
  std::smatch m, turn;
  ASSERT_TRUE(std::regex_search(text, m, std::regex(R"(stopped after (\d+) samples, (\d+) gaps \((\d+) samples lost)")))
      << text;
  ASSERT_TRUE(std::regex_search(text, turn, std::regex(R"(longest loop turn (\d+) us)"))) << text;
  const bool real_time = text.find("event loop scheduling: SCHED_FIFO") != std::string::npos;
  const bool delivery_real_time = text.find("delivery thread scheduling: SCHED_FIFO") != std::string::npos;
  const double p50 = percentile(latency_ms, 0.5), p99 = percentile(latency_ms, 0.99);
  const std::string gyrods_gaps = overflowsTheMachineDoesNotExplain(text, machine, fifo_ms);
  const auto stalls = machine.stalls();
  std::cout << setup.rate_hz << " Hz flood, " << std::chrono::duration_cast<std::chrono::seconds>(kFloodTime).count()
            << " s: watcher got " << rates << " RATE lines, " << gaps << " GAP lines, edge -> watcher p50 " << p50
            << " ms, p99 " << p99 << " ms; gyrod published " << m[1] << " samples, " << m[2] << " gaps, " << m[3]
            << " samples lost, longest loop turn " << turn[1] << " us; " << allan_replies << " ALLAN, "
            << status_replies << " STATUS, " << pipelined_replies << " pipelined replies; gyrod "
            << (real_time ? "SCHED_FIFO" : "not real-time (refused)") << ", its delivery thread "
            << (delivery_real_time ? "SCHED_FIFO" : "not real-time") << ", watcher "
            << (watcher_real_time ? "SCHED_FIFO" : "not real-time") << "; load average before " << load_before
            << ", after " << loadAverage() << "; the machine stopped "
            << (machine.running() ? std::to_string(stalls.size()) + " times for 2 ms or more, at most " +
                                        std::to_string(machine.longestMs()) + " ms"
                                  : "(not timed: the probes could not run real-time)")
            << "\n";
  ::testing::Test::RecordProperty("machine_longest_stall_ms", std::to_string(machine.longestMs()));
  ::testing::Test::RecordProperty("samples_published", m[1].str());
  ::testing::Test::RecordProperty("samples_lost", m[3].str());
  ::testing::Test::RecordProperty("longest_loop_turn_us", turn[1].str());
  ::testing::Test::RecordProperty("latency_p99_ms", std::to_string(p99));
#if defined(__SANITIZE_ADDRESS__)
  // Under ASan + UBSan every instruction of gyrod is instrumented (2 to 5 times slower): CI's
  // sanitized run saw an 89 ms loop turn while flooded at 1 kHz (1664 samples lost in 9 gaps,
  // each reported). Like the emulator, that measures the instrumentation: losses and counts are
  // checked in the optimised build.
  constexpr bool kSlowedDown = true;
#else
  constexpr bool kSlowedDown = false;
#endif
  if (gyrod::test::underEmulator() || kSlowedDown) {
    // Under qemu-user gyrod and the seven clients run every instruction emulated (5 to 20 times
    // slower, docs/testing.md): whether the rate keeps up while flooded, and how many replies fit
    // in 12 real seconds, measure the emulator and the host's load, not the target. Under the
    // emulator gyrod must still survive the flood, stop cleanly and account for what it lost
    // (above); losses and counts are checked natively.
    GTEST_SKIP() << (kSlowedDown ? "sanitizer speed" : "emulator speed") << ": at " << setup.rate_hz
                 << " Hz gyrod lost " << m[3] << " samples in " << m[2]
                 << " gaps (first seen: " << (first_problem.empty() ? "none" : first_problem) << "); the watcher got "
                 << rates << " RATE lines; " << allan_replies << " ALLAN, " << status_replies << " STATUS, "
                 << pipelined_replies << " pipelined in 12 s";
  }
  EXPECT_TRUE(first_problem.empty()) << first_problem << "\n" << text;
  // No gap came without the machine stopping, and each one gyrod counted reached the watcher.
  EXPECT_TRUE(gyrods_gaps.empty()) << "lost while no CPU stood still for " << fifo_ms / 2
                                   << " ms in the two FIFOs' time before:\n"
                                   << gyrods_gaps << text;
  EXPECT_EQ(m[2].str(), std::to_string(gaps)) << text;
  if (gaps == 0) {
    EXPECT_EQ(m[3].str(), "0") << text;
  }
  EXPECT_GT(rates, static_cast<std::uint64_t>(setup.rate_hz) * 8);  // the watcher was served: 8 of the 12 s
  EXPECT_GT(allan_replies.load(), 1000u);
  EXPECT_GT(status_replies.load(), 1000u);
  EXPECT_GE(pipelined_replies.load(), 10'000u);  // one whole pipelined write at least
  if (real_time && watcher_real_time) {
    // The targets are a 10 ms turn and a 2 ms p99 (measured by hand: docs/driver.md "Latency");
    // the test shares its machine with other tests, hence the margin. What the FIFO holds is the
    // limit that matters: past it a turn loses samples.
    // A turn the machine's own stall explains (the CPU stopped mid-turn) is not gyrod's.
    EXPECT_LT(std::stod(turn[1].str()) * 1e-3, std::max(std::min(20.0, fifo_ms), machine.longestMs() + 2.0)) << text;
    // The edge -> watcher p99 is reported, not asserted: it depends on the machine's load and
    // on the watcher's own wake-ups (docs/driver.md "Under a flood of requests").
    ::testing::Test::RecordProperty("latency_p50_ms", std::to_string(p50));
  }
}

}  // namespace

TEST(GyrodFlood, NoSampleLostAt1kHzWithAOneHourWindowWhileClientsFloodIt) { floodAndCheck({1000, 4, 3600}); }

TEST(GyrodFlood, NoSampleLostAt8kHzWhileClientsFloodIt) { floodAndCheck({8000, 0, 60, false}); }

// The start-up at 8 kHz (DLPF 0), no clients, SCHED_FIFO: the end of the still window (motion
// check, bias, the filter's identification over 80,000 samples per axis, tens of milliseconds)
// runs off the sample loop, whose longest turn stays under 10 ms (the FIFO holds 16 ms of
// gyro-only frames; a turn the machine's own stop explains aside, as above; turns of 6-8 ms
// come with a compiler running beside the test, where the machine's longest stop was 3.2 ms,
// and the work on the loop would take tens), and no sample is lost beyond what the machine's
// stops explain; the mock at rest passes the still check (its DLPF-correlated noise is read at
// the low-pass's correlation time, processing/motion/still_period_check.hpp).
TEST(GyrodStartUp, At8kHzTheStillWindowEndsOffTheLoopAndTheMockAtRestIsStill) {
  const RealTimeTurn turn_of_this_test;
  const MachineStallProbe machine;
  ScratchDir d;
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 8000\ndlpf = 0\naccel = false\n"
    << "[bias]\nsource = \"estimate\"\n"
    << "[allan]\nwindow_s = 60\nrefit_interval_s = 1\n"
    << "[socket]\npath = \"" << (d.path() / "gyrod.sock").string() << "\"\n"
    << "[mock]\nspeed = 1\nseed = 11\n";
  const auto cfg = d.write("gyrod.toml", c.str());
  const auto log = d.path() / "log.txt";
  GyrodProcess gyrod({"--config", cfg.string()}, log, [] {
    sched_param fifo{};
    fifo.sched_priority = 10;
    ::sched_setscheduler(0, SCHED_FIFO, &fifo);
  });
  const auto until = std::chrono::steady_clock::now() + 30s;
  std::string text;
  while (std::chrono::steady_clock::now() < until) {
    text = readWholeFile(log);
    if (text.find("start-up still period:") != std::string::npos) break;
    std::this_thread::sleep_for(100ms);
  }
  std::this_thread::sleep_for(1s);  // the held samples released and a second of filtering
  gyrod.signal(SIGTERM);
  const auto status = gyrod.waitExit(10s);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(*status, 0);
  text = readWholeFile(log);
  std::smatch m, turn;
  ASSERT_TRUE(std::regex_search(text, m, std::regex(R"(stopped after (\d+) samples, (\d+) gaps \((\d+) samples lost)")))
      << text;
  ASSERT_TRUE(std::regex_search(text, turn, std::regex(R"(longest loop turn (\d+) us)"))) << text;
  std::cout << "8 kHz start-up: " << m[1] << " samples, " << m[3] << " lost, longest loop turn " << turn[1]
            << " us; the machine's longest stop " << machine.longestMs() << " ms\n";
  EXPECT_NE(text.find("start-up still period: at rest (window 1 of"), std::string::npos) << text;
  EXPECT_EQ(text.find("moved"), std::string::npos) << text;
  EXPECT_GT(std::stoull(m[1].str()), 80'000u);  // the still window and more
#if defined(__SANITIZE_ADDRESS__)
  constexpr bool kSlowedDown = true;  // instrumented: losses measure the sanitizer (see above)
#else
  constexpr bool kSlowedDown = false;
#endif
  if (gyrod::test::underEmulator() || kSlowedDown) GTEST_SKIP() << "at 8 kHz: " << m[3] << " samples lost";
  // No sample lost that the machine's own stops do not explain (as above).
  EXPECT_EQ(overflowsTheMachineDoesNotExplain(text, machine, 1024.0 / 8.0 / 8000 * 1e3), "") << text;
  const auto count = [&text](const char* pattern) {
    const std::regex re(pattern);
    return std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator());
  };
  EXPECT_EQ(count(R"(lost \d+ samples \(seq)"), count("FIFO overflow on the")) << text;  // every loss an overflow
  if (text.find("event loop scheduling: SCHED_FIFO") != std::string::npos) {
    EXPECT_LT(std::stod(turn[1].str()) * 1e-3, std::max(10.0, machine.longestMs() + 2.0)) << text;
  }
}
