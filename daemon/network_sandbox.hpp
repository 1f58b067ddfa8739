#pragma once
// Whether gyrod can reach a broker at all from where it runs. gyrod's systemd unit gives it no
// network (Unix sockets only, an empty network namespace of its own): there [mqtt] would only
// ever log "cannot reach the broker". Said once at start, with the way out
// (systemd/gyrod-mqtt.conf, docs/fleet.md).
#include <string>

namespace gyrod::daemon {

// Empty when IP sockets can be made and an interface other than the loopback exists (or the
// broker is on the loopback); otherwise what stands in the way.
std::string networkSandboxObstacle(const std::string& broker_host);

}  // namespace gyrod::daemon
