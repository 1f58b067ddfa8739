#pragma once
// gyroctl's exit statuses, one scheme for every subcommand: the BSD sysexits(3) values that
// gyrod uses too (README "Exit statuses", man/gyroctl.1 EXIT STATUS). A new error fits in
// by throwing ExitError with the status that says what went wrong; main() maps the library
// exceptions (bad recording, output refused, gyrod unreachable) onto the same table.
#include <stdexcept>
#include <string>

namespace gyrod::gyroctl {

enum class ExitCode : int {
  Ok = 0,
  Failure = 1,       // anything not below (an internal error, a failed write)
  Usage = 64,        // EX_USAGE: unknown command or option, bad option value
  DataError = 65,    // EX_DATAERR: an input file is malformed or unusable (also --strict-timing)
  NoInput = 66,      // EX_NOINPUT: an input file does not exist or cannot be read
  Unavailable = 69,  // EX_UNAVAILABLE: gyrod cannot be reached, refuses, or does not answer
  CantCreate = 73,   // EX_CANTCREAT: the output file cannot be created where asked
};

constexpr int toInt(ExitCode code) { return static_cast<int>(code); }

// An error that ends gyroctl with a given status; main() prints "gyroctl: <what>".
class ExitError : public std::runtime_error {
 public:
  ExitError(ExitCode code, const std::string& what) : std::runtime_error(what), code_(code) {}
  ExitCode code() const noexcept { return code_; }

 private:
  ExitCode code_;
};

}  // namespace gyrod::gyroctl
