#include "daemon/command_line.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <vector>

#include "daemon/recorder.hpp"
#include "formats/quoted_value.hpp"
#include "formats/toml_document.hpp"

#ifndef GYROD_VERSION
#define GYROD_VERSION "unknown"
#endif

namespace gyrod::daemon {

using formats::shortest;

void applyOverrides(GyrodConfig& config, const CommandLineOverrides& o) {
  if (o.backend) config.device.backend = *o.backend;
  if (o.socket_path) {
    if (o.socket_path->empty() || o.socket_path->size() > 107)
      throw ConfigError("--socket: must be a path of 1..107 bytes (got \"" + *o.socket_path + "\")");
    config.socket.path = *o.socket_path;
  }
  if (o.record_path) {
    if (hasControlCharacter(*o.record_path))
      throw ConfigError("--record: must be a path without control characters (got " +
                        formats::quotedValue(*o.record_path) + ")");
    // A folder (DIR/ or an existing DIR) is recorded into, as DIR/gyro-<time>-<index>.csv.
    config.record.path = recordingBaseName(*o.record_path);
  }
  if (o.mock_speed) {
    if (!(*o.mock_speed >= kMinMockSpeed && *o.mock_speed <= kMaxMockSpeed))
      throw ConfigError("--mock-speed: must be between " + shortest(kMinMockSpeed) + " and " + shortest(kMaxMockSpeed) +
                        " (got " + shortest(*o.mock_speed) + ")");
    config.mock.speed = *o.mock_speed;
  }
  if (o.log_level) config.log.level = *o.log_level;
  if (o.mqtt_url) {
    if (!o.mqtt_url->empty()) {
      try {
        parseMqttUrl(*o.mqtt_url);
      } catch (const std::invalid_argument& e) {
        throw ConfigError("--mqtt: " + std::string(e.what()) + " (got " + formats::quotedValue(*o.mqtt_url) + ")");
      }
    }
    config.mqtt.url = *o.mqtt_url;
  }
}

GyrodCommandLine parseGyrodCommandLine(int argc, const char* const* argv, const std::string& default_config_path) {
  CLI::App app{"gyrod: MPU-6050 gyroscope daemon (mean filter + Kalman, rolling Allan statistics)", "gyrod"};
  std::string config_file, backend, socket_path, record_path, log_level, mqtt_url;
  double mock_speed = 0.0;
  app.add_option("--config", config_file, "Configuration file (default: " + default_config_path + " if it exists)");
  const auto strings = [](const std::vector<std::string_view>& v) {
    return std::vector<std::string>(v.begin(), v.end());
  };
  app.add_option("--backend", backend, "Device backend")->check(CLI::IsMember(strings(kBackendNames)));
  app.add_option("--socket", socket_path, "Unix socket path (socket.path)");
  app.add_option("--record", record_path,
                 "Record raw samples to this file (record.path), or into this folder; \"\" = off");
  app.add_option("--mock-speed", mock_speed, "Mock device speed, 1 = real time (mock.speed)");
  app.add_option("--mqtt", mqtt_url, "Publish to this MQTT broker, mqtt://HOST[:PORT] (mqtt.url); \"\" = off");
  app.add_option("--log-level", log_level, "Log level")->check(CLI::IsMember(strings(kLogLevelNames)));
  app.set_version_flag("--version", std::string("gyrod ") + GYROD_VERSION);

  GyrodCommandLine result;
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::ostringstream out, err;
    result.exit_code = app.exit(e, out, err) == 0 ? 0 : kExitUsageError;
    result.message = *result.exit_code == 0 ? out.str() : err.str();
    return result;
  }

  if (app.count("--config")) {
    result.config_file = config_file;
  } else if (std::error_code ec; std::filesystem::exists(default_config_path, ec)) {
    result.config_file = default_config_path;
  }
  if (!result.config_file.empty()) result.config = loadConfigFile(result.config_file);

  CommandLineOverrides o;
  if (app.count("--backend")) o.backend = backend == "mock" ? DeviceBackend::Mock : DeviceBackend::I2c;
  if (app.count("--socket")) o.socket_path = socket_path;
  if (app.count("--record")) o.record_path = record_path;
  if (app.count("--mock-speed")) o.mock_speed = mock_speed;
  if (app.count("--mqtt")) o.mqtt_url = mqtt_url;
  if (app.count("--log-level")) {
    const auto it = std::find(kLogLevelNames.begin(), kLogLevelNames.end(), log_level);
    o.log_level = kLogLevels[static_cast<std::size_t>(it - kLogLevelNames.begin())];
  }
  try {
    applyOverrides(result.config, o);
  } catch (const ConfigError& e) {
    // A flag's value is a usage problem, not the configuration file's.
    result.exit_code = kExitUsageError;
    result.message = std::string(e.what()) + "\n";
  }
  return result;
}

}  // namespace gyrod::daemon
