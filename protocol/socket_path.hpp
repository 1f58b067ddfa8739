#pragma once
// Where gyrod listens and gyroctl connects unless told otherwise (docs/protocol.md "The
// socket"). The one place this path is written in code.
namespace gyrod::protocol {

inline constexpr const char* kDefaultSocketPath = "/run/gyrod/gyrod.sock";

}  // namespace gyrod::protocol
