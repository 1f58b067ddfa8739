#pragma once
// gyrod's command line: the configuration file (daemon/config.hpp) with a few flags on top.
#include <optional>
#include <string>
#include <string_view>

#include "daemon/config.hpp"

namespace gyrod::daemon {

// sysexits.h EX_USAGE: the command line itself is wrong (unknown flag, bad flag value).
inline constexpr int kExitUsageError = 64;
// sysexits.h EX_OSERR: an allocation failed (std::bad_alloc), whatever allocated. The
// configuration's memory check (daemon/memory_budget.hpp) stops what it can foresee with 78.
inline constexpr int kExitOutOfMemory = 71;
// gyrod's exit statuses: 0 after SIGTERM/SIGINT (or --help, --version), kExitUsageError,
// kExitConfigError (config.hpp), kExitOutOfMemory, and 1 for any other failure at start-up
// (e.g. the socket cannot be bound).

// The one line gyrod prints when an allocation failed; a literal, since printing must not
// allocate then.
inline constexpr const char* kOutOfMemoryMessage =
    "gyrod: out of memory: an allocation failed (std::bad_alloc); the configuration's [limits] memory_mb "
    "budget does not cover it, or the machine is short of memory";

inline constexpr std::string_view kDefaultConfigPath = "/etc/gyrod/gyrod.toml";

// Values a flag may set, on top of the file. Each is validated as the same key would be.
struct CommandLineOverrides {
  std::optional<DeviceBackend> backend;
  std::optional<std::string> socket_path;
  std::optional<std::string> record_path;
  std::optional<std::string> mqtt_url;
  std::optional<double> mock_speed;
  std::optional<spdlog::level::level_enum> log_level;
};
// Throws ConfigError naming the flag for a value out of range.
void applyOverrides(GyrodConfig& config, const CommandLineOverrides& overrides);

struct GyrodCommandLine {
  GyrodConfig config;
  std::string config_file;       // the file loaded; empty = compiled-in defaults
  std::optional<int> exit_code;  // set: exit now (0 after --help/--version, 64 for bad usage)
  std::string message;           // print before exiting: stdout if exit_code == 0, else stderr
};

// gyrod's command line:  gyrod [--config FILE] [--backend mock|i2c] [--socket PATH]
//   [--record PATH] [--mock-speed X] [--mqtt URL] [--log-level L] [--help] [--version]
// Loads --config FILE, or else default_config_path when that file exists, or else the
// compiled-in defaults, then applies the flags. Throws ConfigError for a bad config file.
GyrodCommandLine parseGyrodCommandLine(int argc, const char* const* argv,
                                       const std::string& default_config_path = std::string(kDefaultConfigPath));

}  // namespace gyrod::daemon
