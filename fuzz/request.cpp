// libFuzzer target: the protocol's request parser (protocol/protocol.hpp's parseRequest),
// the one parser that reads what any local client sends to gyrod.
#include <algorithm>

#include "fuzz/fuzz_check.hpp"
#include "protocol/protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace protocol = gyrod::protocol;
  // The server refuses a longer line before parsing it.
  if (size > protocol::kMaxRequestLineBytes) return 0;
  const std::string line = gyrod::fuzz::inputText(data, size);
  // A control byte anywhere (NUL, ESC, ...; tab and CR are JSON whitespace) refuses the whole
  // line as bad_request: no part of it may be taken for a request.
  const bool control_byte = std::any_of(line.begin(), line.end(), [](char c) {
    const auto byte = static_cast<unsigned char>(c);
    return (byte < 0x20 && byte != '\t' && byte != '\r') || byte == 0x7f;
  });
  protocol::Request request;
  try {
    request = protocol::parseRequest(line);
  } catch (const protocol::ProtocolError& e) {
    if (control_byte)
      gyrod::fuzz::fuzzCheck(e.code() == protocol::ErrorCode::BadRequest,
                             "a line with a control byte is refused as bad_request");
    return 0;
  }
  gyrod::fuzz::fuzzCheck(!control_byte, "a line with a control byte is never accepted");
  const std::string canonical = protocol::requestLine(request);
  try {
    gyrod::fuzz::fuzzCheck(protocol::requestLine(protocol::parseRequest(canonical)) == canonical,
                           "a request written by requestLine parses back to itself");
  } catch (const protocol::ProtocolError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    gyrod::fuzz::fuzzCheck(false, "parseRequest accepts what requestLine writes");
  }
  return 0;
}
