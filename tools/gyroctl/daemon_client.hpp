#pragma once
// gyroctl's side of the gyrod socket: connect with errors a person can act on, send one
// request line, read reply lines (blocking, with an optional timeout) and parse them with
// the protocol's own parser (protocol/protocol.hpp), the inverse of what gyrod formats with.
#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>

#include "protocol/fd.hpp"
#include "protocol/protocol.hpp"

namespace gyrod::gyroctl {

// Could not talk to gyrod (no socket, permission, refused, closed, timed out, protocol).
class DaemonConnectionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// protocol::parseServerLine, with a line that does not follow the protocol thrown as
// DaemonConnectionError.
protocol::ServerMessage parseServerLine(const std::string& line);
// Throws DaemonConnectionError with gyrod's message when `message` is an ERROR line.
void throwIfError(const protocol::ServerMessage& message);

class DaemonConnection {
 public:
  // Connects to the socket at `path` and reads the VERSION line. Throws
  // DaemonConnectionError: "no such socket (is gyrod running?)", "permission denied
  // (... group ...)", "connection refused", or a protocol major version we do not speak.
  static DaemonConnection open(const std::string& path, std::chrono::milliseconds timeout);

  void sendLine(std::string_view json_without_newline);
  // The next line (without '\n'). No timeout when `timeout` is empty. Throws
  // DaemonConnectionError when gyrod closes the connection or the timeout passes.
  std::string readLine(std::optional<std::chrono::milliseconds> timeout);
  // The next reply of type Reply (e.g. protocol::StatusReply); an ERROR line is thrown as
  // DaemonConnectionError with gyrod's message; lines of other classes are skipped.
  template <class Reply>
  Reply readReply(std::chrono::milliseconds timeout, std::string* raw_line = nullptr) {
    while (true) {
      std::string line = readLine(timeout);
      protocol::ServerMessage message = parseServerLine(line);
      throwIfError(message);
      if (auto* reply = std::get_if<Reply>(&message)) {
        if (raw_line) *raw_line = std::move(line);
        return std::move(*reply);
      }
    }
  }

  const protocol::VersionReply& version() const { return version_; }
  const std::string& versionLine() const { return version_line_; }
  const std::string& path() const { return path_; }

 private:
  DaemonConnection(protocol::Fd fd, std::string path) : fd_(std::move(fd)), path_(std::move(path)) {}
  protocol::Fd fd_;
  std::string path_;
  std::string pending_;  // received bytes not yet returned as a line
  protocol::VersionReply version_;
  std::string version_line_;
};

}  // namespace gyrod::gyroctl
