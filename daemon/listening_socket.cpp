#include "daemon/unix_socket_server.hpp"

#include <fcntl.h>
#include <grp.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <systemd/sd-daemon.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <vector>

// The listening side of the socket server (declared in unix_socket_server.hpp): binding,
// socket activation, the file's mode and group.
namespace gyrod::daemon {

using protocol::errnoError;

void setNonBlockingCloseOnExec(int fd) {
  const int fl = ::fcntl(fd, F_GETFL);
  if (fl < 0 || ::fcntl(fd, F_SETFL, fl | O_NONBLOCK) != 0) throw errnoError("fcntl(O_NONBLOCK)");
  const int fdfl = ::fcntl(fd, F_GETFD);
  if (fdfl < 0 || ::fcntl(fd, F_SETFD, fdfl | FD_CLOEXEC) != 0) throw errnoError("fcntl(FD_CLOEXEC)");
}

namespace {

constexpr int kListenBacklog = 64;

std::string singleQuoted(std::string_view s) { return "'" + std::string(s) + "'"; }

sockaddr_un socketAddress(const std::string& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.empty()) throw std::invalid_argument("socket path is empty");
  if (path.size() >= sizeof addr.sun_path)
    throw std::invalid_argument("socket path " + singleQuoted(path) + " is " + std::to_string(path.size()) +
                                " bytes long; a Unix socket path must be shorter than " +
                                std::to_string(sizeof addr.sun_path));
  std::memcpy(addr.sun_path, path.data(), path.size());
  return addr;
}

gid_t groupId(const std::string& name) {
  std::vector<char> buf(16384);
  group gr{};
  group* found = nullptr;
  const int rc = ::getgrnam_r(name.c_str(), &gr, buf.data(), buf.size(), &found);
  if (rc != 0) throw std::system_error(rc, std::generic_category(), "getgrnam_r(" + singleQuoted(name) + ")");
  if (found == nullptr) throw std::invalid_argument("socket group " + singleQuoted(name) + " does not exist");
  return gr.gr_gid;
}

// Is someone accepting connections on the socket file at `path`? Only a refused
// connection proves the file stale; anything else (success, busy backlog, no permission)
// is treated as "in use" or reported.
bool socketIsLive(const std::string& path) {
  const Fd probe(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
  if (!probe) throw errnoError("socket(AF_UNIX) for probing " + singleQuoted(path));
  const sockaddr_un addr = socketAddress(path);
  if (::connect(probe.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0) return true;
  if (errno == ECONNREFUSED) return false;
  if (errno == EAGAIN || errno == EINPROGRESS) return true;  // a full backlog: alive but busy
  throw errnoError("connect(" + singleQuoted(path) + ") to check whether the socket is in use");
}

}  // namespace

// ---- listening socket --------------------------------------------------------------------

ListeningSocket bindListeningSocket(const SocketOptions& options) {
  namespace fs = std::filesystem;
  const sockaddr_un addr = socketAddress(options.path);
  if ((options.mode & ~mode_t{0777}) != 0)
    throw std::invalid_argument("socket mode " + std::to_string(options.mode) + " has bits outside 0777");
  // (gid_t)-1 tells chown() to leave the group as it is.
  const gid_t gid = options.group ? groupId(*options.group) : static_cast<gid_t>(-1);

  const fs::path parent = fs::path(options.path).parent_path();
  if (!parent.empty()) {
    std::error_code ec;
    if (!fs::exists(parent, ec)) {
      fs::create_directories(parent, ec);
      if (ec) throw std::system_error(ec, "cannot create the socket folder " + singleQuoted(parent.string()));
      fs::permissions(parent, fs::perms(0755), ec);
    }
  }

  struct stat st {};
  if (::lstat(options.path.c_str(), &st) == 0) {
    if (!S_ISSOCK(st.st_mode))
      throw std::runtime_error(options.path + " exists and is not a socket; refusing to replace it");
    if (socketIsLive(options.path))
      throw std::runtime_error(options.path + " is already in use by a running server (is gyrod already running?)");
    if (::unlink(options.path.c_str()) != 0)
      throw errnoError("unlink(" + singleQuoted(options.path) + ") of a stale socket");
    spdlog::info("removed stale socket file {}", options.path);
  } else if (errno != ENOENT) {
    throw errnoError("lstat(" + singleQuoted(options.path) + ")");
  }

  ListeningSocket ls;
  ls.fd.reset(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
  if (!ls.fd) throw errnoError("socket(AF_UNIX)");
  // The file bind() creates gets its mode from the umask: keep it owner-only until the
  // configured mode and group are in place, so nobody else can connect in between.
  const mode_t old_umask = ::umask(0177);
  const int bind_rc = ::bind(ls.fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr);
  const int bind_errno = errno;
  ::umask(old_umask);
  if (bind_rc != 0) {
    errno = bind_errno;
    throw errnoError("bind(" + singleQuoted(options.path) + ")");
  }
  ls.path = options.path;
  auto removeOnError = [&] { ::unlink(options.path.c_str()); };
  if (options.group && ::chown(options.path.c_str(), static_cast<uid_t>(-1), gid) != 0) {
    const auto err =
        errnoError("chown(" + singleQuoted(options.path) + ", group " + singleQuoted(*options.group) + ")");
    removeOnError();
    throw err;
  }
  if (::chmod(options.path.c_str(), options.mode) != 0) {
    const auto err = errnoError("chmod(" + singleQuoted(options.path) + ")");
    removeOnError();
    throw err;
  }
  if (::stat(options.path.c_str(), &st) != 0 || ::listen(ls.fd.get(), kListenBacklog) != 0) {
    const auto err = errnoError("listen(" + singleQuoted(options.path) + ")");
    removeOnError();
    throw err;
  }
  ls.device = st.st_dev;
  ls.inode = st.st_ino;
  return ls;
}

std::optional<ListeningSocket> adoptActivatedSocket(std::string_view name) {
  char** names = nullptr;
  const int n = ::sd_listen_fds_with_names(/*unset_environment=*/0, &names);
  std::vector<std::string> fd_names;
  if (names != nullptr) {
    for (char** p = names; *p != nullptr; ++p) {
      fd_names.emplace_back(*p);
      std::free(*p);
    }
    std::free(names);
  }
  if (n < 0) throw std::system_error(-n, std::generic_category(), "sd_listen_fds_with_names");
  if (n == 0) return std::nullopt;

  int chosen = -1;
  for (int i = 0; i < n && static_cast<std::size_t>(i) < fd_names.size(); ++i)
    if (fd_names[static_cast<std::size_t>(i)] == name) chosen = SD_LISTEN_FDS_START + i;
  if (chosen < 0 && n == 1) chosen = SD_LISTEN_FDS_START;
  if (chosen < 0) {
    std::string list;
    for (const auto& s : fd_names) list += (list.empty() ? "" : ", ") + s;
    throw std::runtime_error("systemd passed " + std::to_string(n) + " sockets (" + list + ") but none is named " +
                             singleQuoted(name) + " (set FileDescriptorName=" + std::string(name) +
                             " in the socket unit)");
  }
  if (::sd_is_socket_unix(chosen, SOCK_STREAM, /*listening=*/1, nullptr, 0) <= 0)
    throw std::runtime_error("fd " + std::to_string(chosen) +
                             " passed by systemd is not a listening Unix stream socket");
  ListeningSocket ls;
  ls.fd.reset(chosen);
  ls.activated = true;
  setNonBlockingCloseOnExec(chosen);
  return ls;
}

ListeningSocket openListeningSocket(const SocketOptions& options) {
  if (auto activated = adoptActivatedSocket()) {
    spdlog::info("using the socket passed by systemd (fd {})", activated->fd.get());
    return std::move(*activated);
  }
  ListeningSocket ls = bindListeningSocket(options);
  spdlog::info("listening on {}", ls.path);
  return ls;
}

}  // namespace gyrod::daemon
