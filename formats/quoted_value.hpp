#pragma once
// A value from an input file, quoted for an error message. The file may be hostile or just
// broken: a value can be megabytes long, or hold bytes that a terminal acts on (ESC
// sequences, bidirectional overrides that reorder what the user reads, a NUL that cuts the
// message short). So the quote is bounded and every such character is escaped.
#include <cstddef>
#include <string>
#include <string_view>

namespace gyrod::formats {

// Characters of a value shown before it is cut.
inline constexpr std::size_t kQuotedValueMaxChars = 80;

// `raw` in single quotes. Control characters (NUL included), DEL and bytes that are not
// UTF-8 become \xNN; C1 controls and the bidirectional controls U+202A..U+202E and
// U+2066..U+2069 become \u{NNNN}; a backslash becomes \\ so that the escapes stay
// unambiguous. Past kQuotedValueMaxChars characters the quote ends with "…" and the
// value's full length follows: 'abc…' (1048576 bytes).
std::string quotedValue(std::string_view raw);

}  // namespace gyrod::formats
