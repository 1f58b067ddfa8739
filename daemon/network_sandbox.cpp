#include "daemon/network_sandbox.hpp"

#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace gyrod::daemon {
namespace {

bool onLoopback(const std::string& host) { return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0; }

// Interfaces other than "lo": none in a network namespace of one's own (PrivateNetwork=yes).
bool hasNonLoopbackInterface() {
  struct if_nameindex* names = ::if_nameindex();
  if (names == nullptr) return true;  // cannot tell: assume a network
  bool found = false;
  for (const struct if_nameindex* i = names; i->if_index != 0 && i->if_name != nullptr; ++i)
    if (std::strcmp(i->if_name, "lo") != 0) found = true;
  ::if_freenameindex(names);
  return found;
}

}  // namespace

std::string networkSandboxObstacle(const std::string& broker_host) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    const int error = errno;
    if (error == EAFNOSUPPORT || error == EPERM || error == EACCES)
      return std::string("this gyrod may not open IP sockets (") + std::strerror(error) + ")";
    return {};
  }
  ::close(fd);
  if (!onLoopback(broker_host) && !hasNonLoopbackInterface())
    return "this gyrod's network has only a loopback interface (a network namespace of its own)";
  return {};
}

}  // namespace gyrod::daemon
