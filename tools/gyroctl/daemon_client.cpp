#include "tools/gyroctl/daemon_client.hpp"

#include <grp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace gyrod::gyroctl {
namespace {

// Server lines are short except ALLAN; anything this long is not gyrod talking.
constexpr std::size_t kMaxServerLineBytes = 16 * 1024 * 1024;

std::string socketGroupName(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return {};
  if (const group* g = ::getgrgid(st.st_gid)) return g->gr_name;
  return std::to_string(st.st_gid);
}

[[noreturn]] void throwConnectError(const std::string& path, int err) {
  switch (err) {
    case ENOENT: throw DaemonConnectionError(path + ": no such socket (is gyrod running?)");
    case EACCES:
    case EPERM: {
      const std::string group = socketGroupName(path);
      throw DaemonConnectionError(path + ": permission denied (the socket is for members of group '" +
                                  (group.empty() ? std::string("gyrod") : group) +
                                  "': add your user to it and log in again, or use sudo)");
    }
    case ECONNREFUSED:
      throw DaemonConnectionError(
          path + ": connection refused (the socket file exists but nothing listens on it: is gyrod running?)");
    case ENOTDIR:
      throw DaemonConnectionError(path + ": no such socket (a part of the path is not a folder; is gyrod running?)");
    default: throw DaemonConnectionError(path + ": cannot connect: " + std::strerror(err));
  }
}

}  // namespace

protocol::ServerMessage parseServerLine(const std::string& line) {
  try {
    return protocol::parseServerLine(line);
  } catch (const protocol::MalformedLine& e) {
    throw DaemonConnectionError("gyrod sent a line that is not a protocol object (" + std::string(e.what()) +
                                "): " + line.substr(0, 200));
  }
}

void throwIfError(const protocol::ServerMessage& message) {
  if (const auto* error = std::get_if<protocol::ErrorReply>(&message))
    throw DaemonConnectionError("gyrod: " + error->message.value_or("error"));
}

DaemonConnection DaemonConnection::open(const std::string& path, std::chrono::milliseconds timeout) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof addr.sun_path)
    throw DaemonConnectionError("'" + path + "' cannot be a Unix socket path (1.." +
                                std::to_string(sizeof addr.sun_path - 1) + " bytes)");
  std::memcpy(addr.sun_path, path.data(), path.size());
  protocol::Fd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd) throw DaemonConnectionError(std::string("socket(AF_UNIX): ") + std::strerror(errno));
  if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) throwConnectError(path, errno);
  DaemonConnection c(std::move(fd), path);
  c.version_line_ = c.readLine(timeout);
  const protocol::ServerMessage first = parseServerLine(c.version_line_);
  if (const auto* error = std::get_if<protocol::ErrorReply>(&first))
    throw DaemonConnectionError("gyrod: " + error->message.value_or("refused the connection"));
  const auto* version = std::get_if<protocol::VersionReply>(&first);
  if (version == nullptr) throw DaemonConnectionError("gyrod did not start with a VERSION line: " + c.version_line_);
  c.version_ = *version;
  const std::int64_t major = c.version_.proto_major.value_or(-1);
  if (major != protocol::kProtocolMajor)
    throw DaemonConnectionError("gyrod speaks protocol " + std::to_string(major) + ".x; this gyroctl speaks " +
                                std::to_string(protocol::kProtocolMajor) + ".x (update gyroctl or gyrod)");
  return c;
}

void DaemonConnection::sendLine(std::string_view json_line) {
  std::string line(json_line);
  line += '\n';
  std::size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::send(fd_.get(), line.data() + done, line.size() - done, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw DaemonConnectionError(path_ + ": sending the request failed: " + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
}

std::string DaemonConnection::readLine(std::optional<std::chrono::milliseconds> timeout) {
  using clock = std::chrono::steady_clock;
  const auto deadline = timeout ? clock::now() + *timeout : clock::time_point::max();
  while (true) {
    if (const auto nl = pending_.find('\n'); nl != std::string::npos) {
      std::string line = pending_.substr(0, nl);
      pending_.erase(0, nl + 1);
      return line;
    }
    if (pending_.size() > kMaxServerLineBytes) throw DaemonConnectionError("gyrod sent a line longer than 16 MiB");
    int wait_ms = -1;
    if (timeout) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - clock::now()).count();
      if (left <= 0) {
        char secs[32];
        std::snprintf(secs, sizeof secs, "%g", static_cast<double>(timeout->count()) / 1000.0);
        throw DaemonConnectionError(path_ + ": no reply from gyrod within " + secs + " s");
      }
      wait_ms = static_cast<int>(left);
    }
    pollfd p{fd_.get(), POLLIN, 0};
    const int rc = ::poll(&p, 1, wait_ms);
    if (rc < 0 && errno == EINTR) continue;
    if (rc < 0) throw DaemonConnectionError(std::string("poll: ") + std::strerror(errno));
    if (rc == 0) continue;  // the deadline check above reports it
    char buf[65536];
    const ssize_t n = ::recv(fd_.get(), buf, sizeof buf, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw DaemonConnectionError(path_ + ": reading from gyrod failed: " + std::strerror(errno));
    if (n == 0) throw DaemonConnectionError("gyrod closed the connection");
    pending_.append(buf, static_cast<std::size_t>(n));
  }
}

}  // namespace gyrod::gyroctl
