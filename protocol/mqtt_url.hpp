#pragma once
// A broker's address as gyrod's configuration and gyroctl write it: mqtt://HOST[:PORT] (plain,
// port 1883 by default) or mqtts://HOST[:PORT] (TLS, 8883 by default); HOST may be a name, an
// IPv4 address or a bracketed IPv6 address ([::1]:1883). docs/protocol.md "MQTT".
#include <string>
#include <string_view>

namespace gyrod::protocol {

struct MqttBrokerAddress {
  std::string host;
  int port = 1883;
  bool tls = false;
};

inline constexpr int kMqttPort = 1883;
inline constexpr int kMqttTlsPort = 8883;

// Throws std::invalid_argument saying what is wrong (the scheme, the host or the port).
MqttBrokerAddress parseMqttUrl(std::string_view url);

}  // namespace gyrod::protocol
