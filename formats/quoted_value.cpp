#include "formats/quoted_value.hpp"

#include <cstdint>
#include <cstdio>

namespace gyrod::formats {
namespace {

// The length of the well-formed UTF-8 sequence at the start of `s` and its code point;
// 0 when the bytes there are not one (a stray continuation byte, a truncated or overlong
// sequence, a surrogate).
std::size_t utf8Sequence(std::string_view s, char32_t& code_point) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
  const unsigned char lead = byte(0);
  std::size_t length = 0;
  char32_t value = 0;
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
    value = lead & 0x1Fu;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    value = lead & 0x0Fu;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    value = lead & 0x07u;
  } else {
    return 0;
  }
  if (s.size() < length) return 0;
  for (std::size_t i = 1; i < length; ++i) {
    if ((byte(i) & 0xC0u) != 0x80u) return 0;
    value = (value << 6) | (byte(i) & 0x3Fu);
  }
  const char32_t smallest[] = {0, 0, 0x80, 0x800, 0x10000};
  if (value < smallest[length] || value > 0x10FFFF || (value >= 0xD800 && value <= 0xDFFF)) return 0;
  code_point = value;
  return length;
}

bool isEscapedCodePoint(char32_t c) {
  return (c >= 0x80 && c <= 0x9F) || (c >= 0x202A && c <= 0x202E) || (c >= 0x2066 && c <= 0x2069);
}

void appendHex(std::string& out, const char* format, unsigned value) {
  char buf[16];
  std::snprintf(buf, sizeof buf, format, value);
  out += buf;
}

}  // namespace

std::string quotedValue(std::string_view raw) {
  std::string out = "'";
  std::size_t shown = 0, i = 0;
  while (i < raw.size() && shown < kQuotedValueMaxChars) {
    const auto byte = static_cast<unsigned char>(raw[i]);
    ++shown;
    char32_t c = 0;
    std::size_t length = 0;
    if (byte == '\\') {
      out += "\\\\";
      ++i;
    } else if (byte >= 0x20 && byte < 0x7F) {
      out += static_cast<char>(byte);
      ++i;
    } else if (byte >= 0x80 && (length = utf8Sequence(raw.substr(i), c)) != 0) {
      if (isEscapedCodePoint(c))
        appendHex(out, "\\u{%04X}", static_cast<unsigned>(c));
      else
        out.append(raw.substr(i, length));
      i += length;
    } else {  // a control byte, DEL, or a byte that starts no UTF-8 sequence
      appendHex(out, "\\x%02X", byte);
      ++i;
    }
  }
  if (i < raw.size()) return out + "…' (" + std::to_string(raw.size()) + " bytes)";
  return out + "'";
}

}  // namespace gyrod::formats
