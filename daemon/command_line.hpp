#pragma once
// gyrod's command line: the configuration file (daemon/config.hpp) with a few flags on top.
#include <optional>
#include <string>
#include <string_view>

#include "daemon/config.hpp"

namespace gyrod::daemon {

// sysexits.h EX_USAGE: the command line itself is wrong (unknown flag, bad flag value).
inline constexpr int kExitUsageError = 64;

inline constexpr std::string_view kDefaultConfigPath = "/etc/gyrod/gyrod.toml";

// Values a flag may set, on top of the file. Each is validated as the same key would be.
struct CommandLineOverrides {
  std::optional<DeviceBackend> backend;
  std::optional<std::string> socket_path;
  std::optional<std::string> record_path;
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
//   [--record PATH] [--mock-speed X] [--log-level L] [--help] [--version]
// Loads --config FILE, or else default_config_path when that file exists, or else the
// compiled-in defaults, then applies the flags. Throws ConfigError for a bad config file.
GyrodCommandLine parseGyrodCommandLine(int argc, const char* const* argv,
                                       const std::string& default_config_path = std::string(kDefaultConfigPath));

}  // namespace gyrod::daemon
