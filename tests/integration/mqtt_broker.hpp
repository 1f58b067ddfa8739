#pragma once
// Debian's MQTT broker (/usr/sbin/mosquitto) for the tests, on the loopback and a free port.
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <thread>

namespace gyrod::test {

inline int freeLoopbackPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t n = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &n);
  ::close(fd);
  return ntohs(a.sin_port);
}

inline bool acceptsConnections(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  const bool up = ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  ::close(fd);
  return up;
}

// Debian's broker, on the loopback only: its default without a configuration file, or the
// configuration file given (whose listeners must include port). Its log is not the test's
// output. Ready when it accepts a connection (generous: a loaded machine, a broker reading its
// persistence file); stop() and start() restart it on the same port.
class Broker {
 public:
  explicit Broker(int port, std::filesystem::path config = {}) : port_(port), config_(std::move(config)) { start(); }
  ~Broker() { stop(); }
  Broker(const Broker&) = delete;
  Broker& operator=(const Broker&) = delete;
  void start() {
    pid_ = ::fork();
    if (pid_ == 0) {
      const int quiet = ::open("/dev/null", O_WRONLY);  // its connection log, its warnings as root
      ::dup2(quiet, 1);
      ::dup2(quiet, 2);
      const std::string p = std::to_string(port_);
      if (config_.empty())
        ::execl("/usr/sbin/mosquitto", "mosquitto", "-p", p.c_str(), static_cast<char*>(nullptr));
      else
        ::execl("/usr/sbin/mosquitto", "mosquitto", "-c", config_.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    for (int i = 0; i < 400 && !acceptsConnections(port_); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  // SIGTERM: mosquitto saves its persistence file and exits.
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  int port_;
  std::filesystem::path config_;
  pid_t pid_ = -1;
};

}  // namespace gyrod::test
