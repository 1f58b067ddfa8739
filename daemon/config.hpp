#pragma once
// gyrod's configuration: one TOML file (config/gyrod.toml documents every key and its
// default) plus a few command-line flags on top (daemon/command_line.hpp). Every problem
// is a ConfigError whose message is one line naming the file, the line and the key; the
// daemon prints it and exits with EX_CONFIG (78). A key the loader does not know is an
// error, never ignored. The TOML reading itself is formats/toml_document.hpp's.
#include <spdlog/common.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/control_characters.hpp"
#include "protocol/mqtt_url.hpp"
#include "protocol/socket_path.hpp"

namespace gyrod::daemon {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// sysexits.h EX_CONFIG: "something was found in an unconfigured or misconfigured state".
inline constexpr int kExitConfigError = 78;
inline constexpr int exitCodeForConfigError() { return kExitConfigError; }

enum class DeviceBackend { I2c, Mock };
enum class BiasSource { Estimate, Model, Config };
enum class MockSource { Simulator, Replay };

struct DeviceConfig {
  DeviceBackend backend = DeviceBackend::I2c;
  std::string bus = "/dev/i2c-1";  // resolved: `bus = 1` and `bus = "1"` both give /dev/i2c-1
  int address = 0x68;              // 0x68 (AD0 low) or 0x69 (AD0 high)
  double rate_hz = 50.0;           // internal rate / (1 + SMPLRT_DIV), checked to be reachable
  int dlpf = 4;                    // DLPF_CFG 0..6; 4 = 20 Hz gyro bandwidth (the paper's)
  int full_scale_dps = 250;        // FS_SEL: 250, 500, 1000 or 2000 °/s
  bool accel = true;               // accel in the FIFO (14-byte frames); false: the 8-byte gyro frame
  int accel_range_g = 2;           // AFS_SEL: 2, 4, 8 or 16 g
  bool operator==(const DeviceConfig&) const = default;
};

struct GpioConfig {
  std::string chip;         // "gpiochip0", "/dev/gpiochip0", ...; empty = no data-ready line (FIFO polling)
  std::optional<int> line;  // line offset on the chip; required when chip is set
  bool operator==(const GpioConfig&) const = default;
};

struct BiasConfig {
  BiasSource source = BiasSource::Estimate;
  double still_seconds = 10.0;                // length of the still period averaged at start (estimate)
  std::vector<double> values{0.0, 0.0, 0.0};  // x, y, z in °/s (source = config)
  bool operator==(const BiasConfig&) const = default;
};

struct KalmanOverrideConfig {
  std::optional<double> a, q, r;  // A = φ1, Q = σa², R; empty = from the model / identification
  bool operator==(const KalmanOverrideConfig&) const = default;
};

struct FilterConfig {
  std::size_t mean_window = 20;     // L (paper: 20)
  double mean_threshold_dps = 0.3;  // r (paper: 0.3 °/s)
  std::string model;                // model file from `gyroctl analyze --write-model`; empty = none
  // The rate stream's first-order low-pass, −3 dB in Hz, over the model file's [filter]
  // low_pass_hz; 0 = off; unset = the model's (none there: off).
  std::optional<double> rate_low_pass_hz;
  KalmanOverrideConfig kalman;
  bool operator==(const FilterConfig&) const = default;
};

struct AllanConfig {
  double window_s = 3600.0;        // rolling window of the statistics
  double refit_interval_s = 10.0;  // how often the noise terms are refitted
  std::vector<double> taus_s;      // empty = octave spacing (τ0·2^k); else explicit τ in s
  bool octave() const { return taus_s.empty(); }
  bool operator==(const AllanConfig&) const = default;
};

struct SocketConfig {
  std::string path = protocol::kDefaultSocketPath;
  unsigned mode = 0660;                 // permission bits of the socket file
  std::string group;                    // group of the socket file; empty = the daemon's group
  std::size_t client_buffer_kib = 256;  // per-client output queue before dropping
  bool operator==(const SocketConfig&) const = default;
};

// [mqtt]: publishing to a broker (docs/protocol.md "MQTT"); off unless url is set.
struct MqttConfig {
  std::string url;             // mqtt://host[:port] (port 1883) or mqtts://host[:port] (TLS, port 8883)
  std::string prefix;          // topics' prefix; empty: gyrod/<hostname>
  int qos = 0;                 // 0 or 1, for rate and gap (status is always QoS 1, retained)
  std::string client_id;       // empty: gyrod-<hostname>
  std::size_t rate_every = 1;  // publish every N-th RATE line
  std::string username;        // empty: no credentials
  std::string password_file;   // the password, read at start (systemd: LoadCredential=)
  // qos 1: messages kept on the publisher's thread while the broker is away, oldest dropped
  // past this (60 s at 1 kHz); 0: none kept.
  std::size_t buffer_messages = 60000;
  std::string ca_file;          // mqtts: the CA certificates the broker's is checked against; empty: /etc/ssl/certs
  std::string cert_file;        // mqtts: a client certificate (PEM), with key_file
  std::string key_file;         // mqtts: its private key (PEM, not encrypted)
  bool home_assistant = false;  // Home Assistant's MQTT discovery configs, retained
  std::string home_assistant_prefix = "homeassistant";
  bool enabled() const { return !url.empty(); }
  bool operator==(const MqttConfig&) const = default;
};

// The host, port and TLS of an mqtt:// or mqtts:// URL (protocol/mqtt_url.hpp, which gyroctl
// fleet reads its --broker with). Throws std::invalid_argument saying what is wrong.
using MqttEndpoint = protocol::MqttBrokerAddress;
using protocol::parseMqttUrl;

struct RecordConfig {
  std::string path;               // base file name, e.g. /var/lib/gyrod/gyro.csv; empty = off
  double rotate_mb = 64.0;        // start a new file past this size (10^6 bytes); 0 = never
  double rotate_minutes = 0.0;    // start a new file after this long; 0 = never
  double flush_interval_s = 1.0;  // how often buffered lines are written (bounds crash loss)
  bool fsync_each_flush = false;  // also fdatasync() at every flush (power-loss safety, SD wear)
  std::size_t keep = 10;          // recording files kept (oldest deleted); 0 = keep all
  bool enabled() const { return !path.empty(); }
  bool operator==(const RecordConfig&) const = default;
};

// The base file name that a record.path value or --record names, one rule for both: a value
// ending in '/' is a folder, recorded into as FOLDER/gyro.csv (an existing folder named
// without the '/' is recorded into too: the recorder finds it is one). "" stays "" (off).
std::string recordingBaseName(const std::string& setting);

// Resources the configuration may claim; checked at load, before anything is allocated
// (daemon/memory_budget.hpp computes the figure).
struct LimitsConfig {
  double memory_mb = 1024.0;  // 10^6 bytes; the Allan window at 1 kHz x 1 h needs ~650
  bool operator==(const LimitsConfig&) const = default;
};

struct LogConfig {
  spdlog::level::level_enum level = spdlog::level::info;
  bool operator==(const LogConfig&) const = default;
};

// Mock device faults (all optional). Times are seconds since the mock device started.
struct MockErrorBurst {
  double at_s = 0.0;
  std::uint32_t count = 1;  // consecutive failing transfers
  bool operator==(const MockErrorBurst&) const = default;
};
// `count` samples spread over [at_s, at_s + duration_s) with bit `bit` of one axis's gyro word
// flipped (outliers the chip reports as data).
struct MockGlitchBurst {
  double at_s = 0.0;
  double duration_s = 0.0;
  std::uint32_t count = 1;
  int axis = 0;  // 0..2: "x", "y", "z"
  int bit = 8;   // 256 LSB: 1.95 °/s at ±250 °/s
  bool operator==(const MockGlitchBurst&) const = default;
};
struct MockVanish {
  double at_s = 0.0;
  double duration_s = 0.0;
  bool power_lost = false;  // also loses power: comes back in its power-on state
  bool operator==(const MockVanish&) const = default;
};
struct MockFaults {
  double transfer_error_fraction = 0.0;  // each transfer fails with this probability
  std::vector<MockErrorBurst> error_bursts;
  std::vector<MockVanish> vanish;
  std::vector<double> silent_reset_at_s;   // brown-out: registers reset, no bus error
  std::vector<double> fifo_overflow_at_s;  // FIFO forced to overflow
  std::optional<int> who_am_i;             // WHO_AM_I answer instead of 0x68 (clones)
  std::vector<double> stuck_data_ready_at_s;
  std::optional<double> stuck_data_ready_duration_s;  // empty = stuck until the end
  std::vector<MockGlitchBurst> glitch_bursts;
  bool operator==(const MockFaults&) const = default;
};

// Paths, names and URLs with a control character are refused (protocol/control_characters.hpp).
using protocol::hasControlCharacter;

// mock.speed's range. Below the minimum the mock's virtual clock hardly moves: at 0.01 its
// start-up (a few hundred ms of the chip's time) already takes most of a minute.
inline constexpr double kMinMockSpeed = 0.01;
inline constexpr double kMaxMockSpeed = 1000.0;

struct MockConfig {
  MockSource source = MockSource::Simulator;
  std::string replay_file;  // recording CSV (t,gx,gy,gz,temp) when source = replay
  std::uint64_t seed = 1;
  double speed = 1.0;  // 1 = real time; 10 = ten times faster (kMinMockSpeed .. kMaxMockSpeed)
  // The board's true rotation as a motion spec (formats/motion_spec.hpp: profiles such as
  // "constant:axis=z,rate=30,start=10", or a CSV t,wx,wy,wz); empty = at rest. Simulator only.
  std::string motion;
  // A warm-up "DELTA_C,TAU_S" (formats/motion_spec.hpp parseWarmUpSpec): the die temperature rises
  // by DELTA_C from the model's start; empty = the model's curve. Simulator only.
  std::string warm_up;
  // The bias's temperature coupling per axis [°/s per °C] (3 values); empty = the model's.
  std::vector<double> temperature_coefficient_dps_per_c;
  MockFaults faults;
  bool operator==(const MockConfig&) const = default;
};

// Where gyrod keeps what it learns across restarts (daemon/calibration_keeper.hpp).
struct StateConfig {
  std::string directory;           // empty: systemd's $STATE_DIRECTORY when set, else none
  double save_interval_s = 600.0;  // data time between writes of the calibration state
  bool operator==(const StateConfig&) const = default;
};

// The live check averages the device's samples down to at most this rate (lines up to half of
// it), which bounds its memory at any device rate.
inline constexpr double kLiveCheckMaxRateHz = 200.0;

// The live check on the board's still data (docs/live-check.md, daemon/live_checker.hpp); gyrod
// runs it when it has the still detector of filter.model.
struct CheckConfig {
  bool enabled = true;
  double interval_s = 300.0;   // still data per examination
  double baseline_s = 1800.0;  // the first still data: the board's baseline
  double false_alarms_per_week = 0.25;
  bool operator==(const CheckConfig&) const = default;
};

struct GyrodConfig {
  DeviceConfig device;
  GpioConfig gpio;
  BiasConfig bias;
  FilterConfig filter;
  AllanConfig allan;
  SocketConfig socket;
  RecordConfig record;
  LogConfig log;
  MockConfig mock;
  LimitsConfig limits;
  MqttConfig mqtt;
  StateConfig state;
  CheckConfig check;
  bool operator==(const GyrodConfig&) const = default;
};

// Whether the files and names a configuration refers to (filter.model, socket.group,
// mock.replay_file when replaying) are checked as well, and the memory the configuration
// needs against what the kernel would grant (RLIMIT_AS, RAM and swap): both need the system
// the daemon runs on, so text parsed on its own does not by default. limits.memory_mb is
// checked either way.
enum class ReferenceChecks { Off, On };

// Parses and validates TOML text; `source_name` is the file name used in messages.
// Keys absent from the text keep their defaults. Throws ConfigError.
GyrodConfig parseConfig(std::string_view toml_text, const std::string& source_name,
                        ReferenceChecks checks = ReferenceChecks::Off);
// Reads the file and parses it with the reference checks on (start-up and SIGHUP).
// Throws ConfigError ("FILE: cannot open: ..." if unreadable, else FILE:LINE and the key).
GyrodConfig loadConfigFile(const std::string& path);

// Names as written in the file.
std::string_view toString(DeviceBackend b);
std::string_view toString(BiasSource s);
std::string_view toString(MockSource s);

// The I2C device node for a `bus` value: a bus number N (≥ 0) → /dev/i2c-N, a path
// starting with '/' → itself. Throws ConfigError for anything else.
std::string i2cDevicePath(std::string_view bus);

// Names the file and the command line accept, as written.
inline const std::vector<std::string_view> kBackendNames = {"i2c", "mock"};
inline const std::vector<std::string_view> kLogLevelNames = {"trace", "debug",    "info", "warn",
                                                             "error", "critical", "off"};
inline constexpr std::array<spdlog::level::level_enum, 7> kLogLevels = {
    spdlog::level::trace, spdlog::level::debug,    spdlog::level::info, spdlog::level::warn,
    spdlog::level::err,   spdlog::level::critical, spdlog::level::off};

}  // namespace gyrod::daemon
