// Latency from a sample's data-ready edge to a client holding its RATE line, measured
// against a running gyrod: usage  gyrod_latency SOCKET [LINES]
// The RATE line's `t` is the driver's CLOCK_MONOTONIC estimate of the sample's edge; the
// client stamps each line with CLOCK_MONOTONIC when recv() returns it. Real-time backends
// only (with an accelerated mock, t is sensor time). Prints p50, p90, p99 and max in µs.
// Both processes wait for a CPU like any other: on a busy machine a SCHED_OTHER wake-up can
// wait for the next scheduler tick (4 ms at HZ=250), so the client also prints how long it
// itself sat runnable before each read (its run-queue delay, /proc/thread-self/schedstat).
// Run both under `chrt -f 10` to measure the daemon rather than the scheduler.
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace {

// Nanoseconds this thread has spent runnable but not running (schedstat's second field).
std::int64_t runQueueDelayNs() {
  std::FILE* f = std::fopen("/proc/thread-self/schedstat", "r");
  if (f == nullptr) return 0;
  long long on_cpu = 0, waited = 0, slices = 0;
  const int n = std::fscanf(f, "%lld %lld %lld", &on_cpu, &waited, &slices);
  std::fclose(f);
  return n == 3 ? waited : 0;
}

}  // namespace

constexpr const char* kUsage =
    "usage: gyrod_latency SOCKET [LINES]\n"
    "Watches gyrod's RATE stream on SOCKET and prints the latency from each sample's data-ready\n"
    "edge to its arrival here (p50, p90, p99, max in us) over LINES lines (default 3000), and\n"
    "this client's own run-queue delay. Real-time backends only (not an accelerated mock).\n";

int main(int argc, char** argv) {
  if (argc >= 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (argc < 2 || argc > 3) {
    std::fputs(kUsage, stderr);
    return 64;  // EX_USAGE, as gyrod and gyroctl
  }
  std::size_t wanted = 3000;
  if (argc > 2) {
    char* end = nullptr;
    const unsigned long long lines = std::strtoull(argv[2], &end, 10);
    if (end == argv[2] || *end != '\0' || lines == 0 || argv[2][0] == '-') {
      std::fprintf(stderr, "gyrod_latency: LINES must be a positive whole number (got '%s')\n", argv[2]);
      return 64;
    }
    wanted = static_cast<std::size_t>(lines);
  }
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, argv[1], sizeof(addr.sun_path) - 1);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    std::perror("connect");
    return 1;
  }
  const std::string watch = "{\"cmd\":\"watch\"}\n";
  if (::send(fd, watch.data(), watch.size(), 0) < 0) return 1;
  std::string buffer;
  std::vector<double> latency_us;
  std::vector<double> client_wait_us;  // the client's own run-queue delay before each line's read
  std::int64_t waited_before = runQueueDelayNs();
  char chunk[65536];
  while (latency_us.size() < wanted) {
    const ssize_t n = ::recv(fd, chunk, sizeof chunk, 0);
    if (n <= 0) break;
    timespec now{};
    ::clock_gettime(CLOCK_MONOTONIC, &now);
    const double now_s = static_cast<double>(now.tv_sec) + static_cast<double>(now.tv_nsec) * 1e-9;
    const std::int64_t waited = runQueueDelayNs();
    const double wait_us = static_cast<double>(waited - waited_before) * 1e-3;
    waited_before = waited;
    buffer.append(chunk, static_cast<std::size_t>(n));
    std::size_t nl;
    while ((nl = buffer.find('\n')) != std::string::npos) {
      const auto j = nlohmann::json::parse(buffer.substr(0, nl));
      buffer.erase(0, nl + 1);
      if (j.value("class", "") == "RATE") {
        latency_us.push_back((now_s - j["t"].get<double>()) * 1e6);
        client_wait_us.push_back(wait_us);
      }
    }
  }
  if (latency_us.empty()) {
    std::fprintf(stderr, "no RATE line received\n");
    return 1;
  }
  std::sort(latency_us.begin(), latency_us.end());
  std::sort(client_wait_us.begin(), client_wait_us.end());
  auto pct = [](const std::vector<double>& v, double p) { return v[static_cast<std::size_t>(p * (v.size() - 1))]; };
  std::printf("RATE lines: %zu\nlatency edge -> client [us]: p50 %.0f  p90 %.0f  p99 %.0f  max %.0f\n",
              latency_us.size(), pct(latency_us, 0.5), pct(latency_us, 0.9), pct(latency_us, 0.99), latency_us.back());
  std::printf("client's own run-queue wait per line [us]: p50 %.0f  p90 %.0f  p99 %.0f  max %.0f\n",
              pct(client_wait_us, 0.5), pct(client_wait_us, 0.9), pct(client_wait_us, 0.99), client_wait_us.back());
  return 0;
}
