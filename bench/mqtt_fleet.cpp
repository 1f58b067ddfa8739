// A fleet on one broker, measured: N gyrod processes on the mock (real time, 50 Hz by default)
// publish every RATE line with QoS 1 to one mosquitto; one subscriber takes <root>/+/rate and
// checks that every board's seqs arrive, each once and in order, and the latency from each
// sample's data-ready edge (RATE `t`, CLOCK_MONOTONIC) to its arrival here (same clock).
// Two phases of the same length: the N gyrods without [mqtt], then with it; the difference
// of their CPU (utime + stime, /proc/PID/stat) is what publishing adds per board.
// usage: mqtt_fleet GYROD [--boards N] [--seconds S] [--rate HZ] [--qos 0|1]
// docs/fleet.md "A fleet on one machine" has the figures and the command.
#include <fcntl.h>
#include <mosquitto.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Options {
  std::string gyrod;
  int boards = 50;
  double seconds = 30.0;
  double rate_hz = 50.0;
  int qos = 1;
};

double monotonicSeconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// A loopback port nobody holds now (the kernel's choice for port 0), for the broker.
int freeLoopbackPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t n = sizeof a;
  const bool ok = ::bind(fd, reinterpret_cast<sockaddr*>(&a), n) == 0 &&
                  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &n) == 0;
  ::close(fd);
  return ok ? ntohs(a.sin_port) : 1883;
}

pid_t spawn(const std::vector<std::string>& argv, const fs::path& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int out = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, 1);
    ::dup2(out, 2);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  return pid;
}

void stop(pid_t pid) {
  ::kill(pid, SIGTERM);
  ::waitpid(pid, nullptr, 0);
}

// utime + stime of a process [s].
double cpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close = text.rfind(')');
  if (close == std::string::npos) return 0.0;
  std::istringstream fields(text.substr(close + 2));
  std::string skip;
  for (int i = 0; i < 11; ++i) fields >> skip;  // state .. cmajflt: fields 3..13
  double utime = 0, stime = 0;
  fields >> utime >> stime;
  return (utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

struct BoardSeen {
  std::uint64_t messages = 0, first_seq = 0, last_seq = 0, out_of_order = 0, duplicates = 0;
};

class RateSubscriber {
 public:
  RateSubscriber(int port, int qos) {
    mosquitto_lib_init();
    mosq_ = mosquitto_new("mqtt-fleet-bench", true, this);
    mosquitto_message_callback_set(mosq_, &RateSubscriber::onMessage);
    if (mosquitto_connect(mosq_, "127.0.0.1", port, 30) != MOSQ_ERR_SUCCESS ||
        mosquitto_subscribe(mosq_, nullptr, "bench/+/rate", qos) != MOSQ_ERR_SUCCESS ||
        mosquitto_loop_start(mosq_) != MOSQ_ERR_SUCCESS) {
      std::fprintf(stderr, "mqtt_fleet: the subscriber cannot connect to the broker on port %d\n", port);
      std::exit(1);
    }
  }
  ~RateSubscriber() {
    mosquitto_disconnect(mosq_);
    mosquitto_loop_stop(mosq_, false);
    mosquitto_destroy(mosq_);
  }
  void measure(bool on) {
    const std::lock_guard lock(mutex_);
    measuring_ = on;
  }
  std::map<std::string, BoardSeen> boards() const {
    const std::lock_guard lock(mutex_);
    return boards_;
  }
  std::vector<double> latencies() const {
    const std::lock_guard lock(mutex_);
    return latency_ms_;
  }

 private:
  static void onMessage(mosquitto*, void* self, const mosquitto_message* m) {
    const double arrived = monotonicSeconds();
    auto* s = static_cast<RateSubscriber*>(self);
    const auto j = nlohmann::json::parse(static_cast<const char*>(m->payload),
                                         static_cast<const char*>(m->payload) + m->payloadlen, nullptr, false);
    if (!j.is_object() || !j.contains("seq")) return;
    const auto seq = j["seq"].get<std::uint64_t>();
    const std::lock_guard lock(s->mutex_);
    if (!s->measuring_) return;
    BoardSeen& b = s->boards_[m->topic];
    if (b.messages == 0) {
      b.first_seq = seq;
    } else if (seq == b.last_seq) {
      ++b.duplicates;
    } else if (seq != b.last_seq + 1) {
      ++b.out_of_order;
    }
    ++b.messages;
    b.last_seq = std::max(b.last_seq, seq);
    s->latency_ms_.push_back((arrived - j["t"].get<double>()) * 1e3);
  }

  mosquitto* mosq_ = nullptr;
  mutable std::mutex mutex_;
  bool measuring_ = false;
  std::map<std::string, BoardSeen> boards_;
  std::vector<double> latency_ms_;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

std::string boardConfig(const fs::path& dir, int i, double rate_hz, int port, int qos) {
  std::string c = "[device]\nbackend = \"mock\"\nrate_hz = " + std::to_string(static_cast<int>(rate_hz)) +
                  "\n[socket]\npath = \"" + (dir / ("board-" + std::to_string(i) + ".sock")).string() +
                  "\"\n[mock]\nseed = " + std::to_string(i + 1) + "\n";
  if (port > 0)
    c += "[mqtt]\nurl = \"mqtt://127.0.0.1:" + std::to_string(port) + "\"\nprefix = \"bench/board-" +
         std::to_string(i) + "\"\nclient_id = \"bench-" + std::to_string(i) + "\"\nqos = " + std::to_string(qos) + "\n";
  return c;
}

// N gyrods for `seconds` after `settle_s`; returns their CPU seconds in the window.
double runBoards(const Options& o, const fs::path& dir, int port, RateSubscriber* sub, double settle_s) {
  std::vector<pid_t> pids;
  for (int i = 0; i < o.boards; ++i) {
    const fs::path cfg = dir / ("board-" + std::to_string(i) + (port > 0 ? "-mqtt" : "") + ".toml");
    std::ofstream(cfg) << boardConfig(dir, i, o.rate_hz, port, o.qos);
    pids.push_back(spawn({o.gyrod, "--config", cfg.string()}, dir / ("board-" + std::to_string(i) + ".log")));
  }
  std::this_thread::sleep_for(std::chrono::duration<double>(settle_s));
  double before = 0.0;
  for (const pid_t p : pids) before += cpuSeconds(p);
  if (sub) sub->measure(true);
  std::this_thread::sleep_for(std::chrono::duration<double>(o.seconds));
  if (sub) sub->measure(false);
  double after = 0.0;
  for (const pid_t p : pids) after += cpuSeconds(p);
  for (const pid_t p : pids) stop(p);
  return after - before;
}

Options parse(int argc, char** argv) {
  Options o;
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0) {
    std::printf("usage: mqtt_fleet GYROD [--boards N] [--seconds S] [--rate HZ] [--qos 0|1]\n");
    std::exit(argc < 2 ? 64 : 0);
  }
  o.gyrod = argv[1];
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    const double v = std::atof(argv[i + 1]);
    if (k == "--boards")
      o.boards = static_cast<int>(v);
    else if (k == "--seconds")
      o.seconds = v;
    else if (k == "--rate")
      o.rate_hz = v;
    else if (k == "--qos")
      o.qos = static_cast<int>(v);
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const fs::path dir = fs::temp_directory_path() / ("mqtt-fleet-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const double settle_s = 5.0;  // start-up, the still period's first window, the connections

  const double cpu_without = runBoards(o, dir, 0, nullptr, settle_s);

  const int port = freeLoopbackPort();
  const pid_t broker = spawn({"/usr/sbin/mosquitto", "-p", std::to_string(port)}, dir / "mosquitto.log");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  RateSubscriber sub(port, o.qos);
  const double broker_before = cpuSeconds(broker);
  const double cpu_with = runBoards(o, dir, port, &sub, settle_s);
  const double broker_cpu = cpuSeconds(broker) - broker_before;
  stop(broker);

  const auto boards = sub.boards();
  std::uint64_t messages = 0, missing = 0, disorder = 0, duplicates = 0;
  for (const auto& [topic, b] : boards) {
    messages += b.messages;
    missing += (b.last_seq - b.first_seq + 1) - (b.messages - b.duplicates);
    disorder += b.out_of_order;
    duplicates += b.duplicates;
  }
  const auto lat = sub.latencies();
  const double expected = o.boards * o.rate_hz * o.seconds;
  std::printf(
      "%d boards at %g Hz, QoS %d, %g s: %zu boards seen, %llu messages (%.1f %% of %g), %llu missing "
      "between each board's first and last, %llu out of order, %llu duplicates\n",
      o.boards, o.rate_hz, o.qos, o.seconds, boards.size(), static_cast<unsigned long long>(messages),
      100.0 * static_cast<double>(messages) / expected, expected, static_cast<unsigned long long>(missing),
      static_cast<unsigned long long>(disorder), static_cast<unsigned long long>(duplicates));
  std::printf("edge -> subscriber latency: p50 %.2f ms, p99 %.2f ms, max %.2f ms\n", percentile(lat, 0.5),
              percentile(lat, 0.99), lat.empty() ? 0.0 : *std::max_element(lat.begin(), lat.end()));
  std::printf("gyrod CPU per board: %.2f %% without MQTT, %.2f %% with (added %.2f %% of a CPU); mosquitto %.1f %%\n",
              100.0 * cpu_without / o.seconds / o.boards, 100.0 * cpu_with / o.seconds / o.boards,
              100.0 * (cpu_with - cpu_without) / o.seconds / o.boards, 100.0 * broker_cpu / o.seconds);
  std::error_code ec;
  fs::remove_all(dir, ec);
  return (boards.size() == static_cast<std::size_t>(o.boards) && missing == 0 && disorder == 0) ? 0 : 1;
}
