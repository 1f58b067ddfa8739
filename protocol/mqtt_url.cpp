#include "protocol/mqtt_url.hpp"

#include <algorithm>
#include <charconv>
#include <stdexcept>

#include "protocol/control_characters.hpp"

namespace gyrod::protocol {

MqttBrokerAddress parseMqttUrl(std::string_view url) {
  MqttBrokerAddress a;
  std::string_view rest;
  if (url.rfind("mqtt://", 0) == 0) {
    rest = url.substr(7);
  } else if (url.rfind("mqtts://", 0) == 0) {
    rest = url.substr(8);
    a.tls = true;
    a.port = kMqttTlsPort;
  } else {
    throw std::invalid_argument("must be mqtt://HOST[:PORT] or mqtts://HOST[:PORT] (TLS)");
  }
  if (!rest.empty() && rest.back() == '/') rest.remove_suffix(1);
  const auto colon = rest.rfind(':');
  const bool bracketed = !rest.empty() && rest.front() == '[';  // [IPv6]:port
  if (colon != std::string_view::npos && (!bracketed || rest.find(']') < colon)) {
    const std::string_view port = rest.substr(colon + 1);
    int value = 0;
    const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
    if (port.empty() || ec != std::errc() || end != port.data() + port.size() || value < 1 || value > 65535)
      throw std::invalid_argument("the port must be 1..65535");
    a.port = value;
    rest = rest.substr(0, colon);
  }
  if (bracketed && rest.size() >= 2 && rest.back() == ']') rest = rest.substr(1, rest.size() - 2);
  if (rest.empty() || hasControlCharacter(rest) || rest.find_first_of("/@ ") != std::string_view::npos)
    throw std::invalid_argument("must name a host: mqtt://HOST[:PORT] or mqtts://HOST[:PORT]");
  a.host = std::string(rest);
  return a;
}

}  // namespace gyrod::protocol
