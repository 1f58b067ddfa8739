#pragma once
// Text that may reach a terminal: gyrod's log names files, users and brokers from the
// configuration, and a control character in one (an escape sequence) would act on the terminal
// of whoever reads that log.
#include <algorithm>
#include <string_view>

namespace gyrod::protocol {

// A C0 control character or DEL in `text`.
inline bool hasControlCharacter(std::string_view text) {
  return std::any_of(text.begin(), text.end(), [](char c) {
    const auto byte = static_cast<unsigned char>(c);
    return byte < 0x20 || byte == 0x7f;
  });
}

}  // namespace gyrod::protocol
