// libFuzzer target: the protocol's request parser (protocol/protocol.hpp's parseRequest),
// the one parser that reads what any local client sends to gyrod.
#include "fuzz/fuzz_check.hpp"
#include "protocol/protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace protocol = gyrod::protocol;
  // The server refuses a longer line before parsing it.
  if (size > protocol::kMaxRequestLineBytes) return 0;
  const std::string line = gyrod::fuzz::inputText(data, size);
  protocol::Request request;
  try {
    request = protocol::parseRequest(line);
  } catch (const protocol::ProtocolError&) {
    return 0;
  }
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
