#pragma once
// gyroctl's side of the gyrod socket: connect with errors a person can act on, send one
// request line, read reply lines (blocking, with an optional timeout).
#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "daemon/fd.hpp"

namespace gyrod::gyroctl {

// Could not talk to gyrod (no socket, permission, refused, closed, timed out, protocol).
class DaemonConnectionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

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
  // The next line that is a JSON object of class `wanted`; an ERROR line is thrown as
  // DaemonConnectionError with gyrod's message; lines of other classes are skipped.
  nlohmann::json readObjectOfClass(std::string_view wanted, std::chrono::milliseconds timeout, std::string* raw_line = nullptr);

  const nlohmann::json& version() const { return version_; }
  const std::string& versionLine() const { return version_line_; }
  const std::string& path() const { return path_; }

 private:
  DaemonConnection(daemon::Fd fd, std::string path) : fd_(std::move(fd)), path_(std::move(path)) {}
  daemon::Fd fd_;
  std::string path_;
  std::string pending_;  // received bytes not yet returned as a line
  nlohmann::json version_;
  std::string version_line_;
};

// Parses a server line; throws DaemonConnectionError when it is not a JSON object with a
// string "class".
nlohmann::json parseServerLine(const std::string& line);

}  // namespace gyrod::gyroctl
