// gyrod's configuration file and command line: the shipped file is the documentation of
// the defaults (it must load to exactly the compiled-in defaults and mention every key),
// and every kind of mistake is one line naming file, line and key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "daemon/command_line.hpp"
#include "daemon/config.hpp"

using namespace gyrod::daemon;
namespace fs = std::filesystem;

namespace {

const std::string kShippedConfig = std::string(GYROD_TEST_DATA_DIR) + "/../../config/gyrod.toml";

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The message of the ConfigError that parsing `text` (as "x.toml") throws; "" if none.
std::string errorOf(const std::string& text) {
  try {
    parseConfig(text, "x.toml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/gyrod-config-test-XXXXXX";
    path_ = mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string write(const std::string& name, const std::string& text) const {
    const auto p = (fs::path(path_) / name).string();
    std::ofstream(p) << text;
    return p;
  }
  std::string path(const std::string& name) const { return (fs::path(path_) / name).string(); }

 private:
  std::string path_;
};

GyrodCommandLine parseArgs(std::vector<std::string> args, const std::string& default_config) {
  args.insert(args.begin(), "gyrod");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  return parseGyrodCommandLine(static_cast<int>(argv.size()), argv.data(), default_config);
}

}  // namespace

// ---- the shipped file -------------------------------------------------------------------

TEST(ShippedConfig, LoadsToExactlyTheCompiledInDefaults) {
  const GyrodConfig loaded = loadConfigFile(kShippedConfig);
  EXPECT_TRUE(loaded == GyrodConfig{}) << "config/gyrod.toml and daemon/config.hpp disagree";
}

TEST(ShippedConfig, DefaultsAreTheDocumentedValues) {
  // The values the design fixes (the paper's filter settings, the daemon's paths),
  // written here independently of config.hpp.
  const GyrodConfig d;
  EXPECT_EQ(d.device.backend, DeviceBackend::I2c);
  EXPECT_EQ(d.device.bus, "/dev/i2c-1");
  EXPECT_EQ(d.device.address, 0x68);
  EXPECT_EQ(d.device.rate_hz, 50.0);
  EXPECT_EQ(d.device.dlpf, 4);
  EXPECT_EQ(d.device.full_scale_dps, 250);
  EXPECT_TRUE(d.gpio.chip.empty());
  EXPECT_EQ(d.filter.mean_window, 20u);
  EXPECT_EQ(d.filter.mean_threshold_dps, 0.3);
  EXPECT_EQ(d.allan.window_s, 3600.0);
  EXPECT_EQ(d.allan.refit_interval_s, 10.0);
  EXPECT_TRUE(d.allan.octave());
  EXPECT_EQ(d.socket.path, "/run/gyrod/gyrod.sock");
  EXPECT_EQ(d.socket.mode, 0660u);
  EXPECT_EQ(d.socket.client_buffer_kib, 256u);
  EXPECT_FALSE(d.record.enabled());
  EXPECT_EQ(d.record.flush_interval_s, 1.0);
  EXPECT_EQ(d.log.level, spdlog::level::info);
  EXPECT_EQ(d.mock.speed, 1.0);
  EXPECT_EQ(exitCodeForConfigError(), 78);
}

TEST(ShippedConfig, MentionsEveryKeyTheLoaderAccepts) {
  // The loader lists a section's valid keys when it meets an unknown one; every key so
  // listed must appear in the shipped file as "key =" or "# key =" inside that section
  // (or, for a sub-table, as its section header).
  const std::string shipped = readText(kShippedConfig);
  const std::vector<std::pair<std::string, std::string>> probes = {
      {"device", "[device]\nzz = 1\n"},
      {"gpio", "[gpio]\nzz = 1\n"},
      {"bias", "[bias]\nzz = 1\n"},
      {"filter", "[filter]\nzz = 1\n"},
      {"filter.kalman", "[filter.kalman]\nzz = 1\n"},
      {"allan", "[allan]\nzz = 1\n"},
      {"socket", "[socket]\nzz = 1\n"},
      {"record", "[record]\nzz = 1\n"},
      {"log", "[log]\nzz = 1\n"},
      {"mock", "[mock]\nzz = 1\n"},
      {"mock.faults", "[mock.faults]\nzz = 1\n"},
  };
  for (const auto& [section, probe] : probes) {
    const std::string err = errorOf(probe);
    const auto list_begin = err.find("(valid keys: ");
    ASSERT_NE(list_begin, std::string::npos) << err;
    const auto list_end = err.find(')', list_begin);
    ASSERT_NE(list_end, std::string::npos) << err;
    const std::string list = err.substr(list_begin + 13, list_end - list_begin - 13);
    const auto header = shipped.find("[" + section + "]\n");
    ASSERT_NE(header, std::string::npos) << section;
    const auto next_header = shipped.find("\n[", header + 1);
    const std::string body =
        shipped.substr(header, next_header == std::string::npos ? std::string::npos : next_header - header);
    std::stringstream keys(list);
    std::string key;
    int count = 0;
    while (std::getline(keys, key, ',')) {
      key.erase(0, key.find_first_not_of(' '));
      ++count;
      // A sub-table may be documented as its own section header instead.
      EXPECT_TRUE(body.find("\n" + key + " = ") != std::string::npos ||
                  body.find("\n# " + key + " = ") != std::string::npos ||
                  shipped.find("\n[" + section + "." + key + "]\n") != std::string::npos)
          << "key '" << section << "." << key << "' is not documented in config/gyrod.toml";
    }
    EXPECT_GT(count, 0) << section;
  }
  // Keys of the inline fault tables are shown in their examples.
  for (const auto* example : {"at_s = ", "count = ", "duration_s = ", "power_lost = "})
    EXPECT_NE(shipped.find(example), std::string::npos) << example;
}

TEST(ShippedConfig, ParsesAFileThatSetsEveryKey) {
  const auto c = parseConfig(R"(
[device]
backend = "mock"
bus = "/dev/i2c-3"
address = 0x69
rate_hz = 200
dlpf = 3
full_scale_dps = 500
[gpio]
chip = "gpiochip0"
line = 17
[bias]
source = "config"
still_seconds = 5.5
values = [0.1, -0.2, 3]
[filter]
mean_window = 10
mean_threshold_dps = 0.5
model = "/var/lib/gyrod/model.json"
kalman = { a = 0.9, q = 1e-4, r = 2e-3 }
[allan]
window_s = 600
refit_interval_s = 5
taus = [0.005, 0.1, 1, 300]
[socket]
path = "/tmp/g.sock"
mode = "0600"
group = "gyrod"
client_buffer_kib = 64
[record]
path = "/var/lib/gyrod/gyro.csv"
rotate_mb = 0.5
rotate_minutes = 60
flush_interval_s = 0.25
fsync_each_flush = true
keep = 3
[log]
level = "debug"
[mock]
source = "replay"
replay_file = "r.csv"
seed = 42
speed = 10
[mock.faults]
transfer_error_fraction = 0.01
error_burst = [{ at_s = 5, count = 10 }, { at_s = 7.5, count = 2 }]
vanish = { at_s = 20, duration_s = 2, power_lost = true }
silent_reset_at_s = 30
fifo_overflow_at_s = [40, 41.5]
who_am_i = 0x72
stuck_data_ready_at_s = [50]
stuck_data_ready_duration_s = 5
glitch_burst = [{ at_s = 3600, duration_s = 60, count = 30, axis = "z", bit = 9 }, { at_s = 10 }]
)",
                             "full.toml");
  EXPECT_EQ(c.device.backend, DeviceBackend::Mock);
  EXPECT_EQ(c.device.bus, "/dev/i2c-3");
  EXPECT_EQ(c.device.address, 0x69);
  EXPECT_EQ(c.device.rate_hz, 200.0);
  EXPECT_EQ(c.device.dlpf, 3);
  EXPECT_EQ(c.device.full_scale_dps, 500);
  EXPECT_EQ(c.gpio.chip, "gpiochip0");
  EXPECT_EQ(c.gpio.line, 17);
  EXPECT_EQ(c.bias.source, BiasSource::Config);
  EXPECT_EQ(c.bias.still_seconds, 5.5);
  EXPECT_EQ(c.bias.values, (std::vector<double>{0.1, -0.2, 3.0}));
  EXPECT_EQ(c.filter.mean_window, 10u);
  EXPECT_EQ(c.filter.mean_threshold_dps, 0.5);
  EXPECT_EQ(c.filter.model, "/var/lib/gyrod/model.json");
  EXPECT_EQ(c.filter.kalman.a, 0.9);
  EXPECT_EQ(c.filter.kalman.q, 1e-4);
  EXPECT_EQ(c.filter.kalman.r, 2e-3);
  EXPECT_EQ(c.allan.window_s, 600.0);
  EXPECT_EQ(c.allan.refit_interval_s, 5.0);
  EXPECT_EQ(c.allan.taus_s, (std::vector<double>{0.005, 0.1, 1.0, 300.0}));
  EXPECT_EQ(c.socket.path, "/tmp/g.sock");
  EXPECT_EQ(c.socket.mode, 0600u);
  EXPECT_EQ(c.socket.group, "gyrod");
  EXPECT_EQ(c.socket.client_buffer_kib, 64u);
  EXPECT_EQ(c.record.path, "/var/lib/gyrod/gyro.csv");
  EXPECT_EQ(c.record.rotate_mb, 0.5);
  EXPECT_EQ(c.record.rotate_minutes, 60.0);
  EXPECT_EQ(c.record.flush_interval_s, 0.25);
  EXPECT_TRUE(c.record.fsync_each_flush);
  EXPECT_EQ(c.record.keep, 3u);
  EXPECT_EQ(c.log.level, spdlog::level::debug);
  EXPECT_EQ(c.mock.source, MockSource::Replay);
  EXPECT_EQ(c.mock.replay_file, "r.csv");
  EXPECT_EQ(c.mock.seed, 42u);
  EXPECT_EQ(c.mock.speed, 10.0);
  const auto& f = c.mock.faults;
  EXPECT_EQ(f.transfer_error_fraction, 0.01);
  EXPECT_EQ(f.error_bursts, (std::vector<MockErrorBurst>{{5.0, 10}, {7.5, 2}}));
  EXPECT_EQ(f.vanish, (std::vector<MockVanish>{{20.0, 2.0, true}}));
  EXPECT_EQ(f.silent_reset_at_s, (std::vector<double>{30.0}));
  EXPECT_EQ(f.fifo_overflow_at_s, (std::vector<double>{40.0, 41.5}));
  EXPECT_EQ(f.who_am_i, 0x72);
  EXPECT_EQ(f.stuck_data_ready_at_s, (std::vector<double>{50.0}));
  EXPECT_EQ(f.stuck_data_ready_duration_s, 5.0);
  EXPECT_EQ(f.glitch_bursts, (std::vector<MockGlitchBurst>{{3600.0, 60.0, 30, 2, 9}, {10.0, 0.0, 1, 0, 8}}));
}

TEST(ConfigValues, BusNumbersAndPaths) {
  EXPECT_EQ(i2cDevicePath("1"), "/dev/i2c-1");
  EXPECT_EQ(i2cDevicePath("0"), "/dev/i2c-0");
  EXPECT_EQ(i2cDevicePath("22"), "/dev/i2c-22");
  EXPECT_EQ(i2cDevicePath("/dev/i2c-7"), "/dev/i2c-7");
  EXPECT_THROW(i2cDevicePath("i2c-1"), ConfigError);
  EXPECT_THROW(i2cDevicePath(""), ConfigError);
  EXPECT_EQ(parseConfig("[device]\nbus = 0\n", "x").device.bus, "/dev/i2c-0");
  EXPECT_EQ(parseConfig("[device]\nbus = \"3\"\n", "x").device.bus, "/dev/i2c-3");
}

TEST(ConfigValues, EveryRateTheChipCanProduceIsAcceptedAndNoOther) {
  // Register Map rev 4.2 §4.2: rate = internal / (1 + SMPLRT_DIV), SMPLRT_DIV 0..255;
  // internal = 1 kHz with DLPF_CFG 1..6, 8 kHz with 0.
  for (int dlpf : {0, 4}) {
    const double internal = dlpf == 0 ? 8000.0 : 1000.0;
    for (int n = 1; n <= 256; ++n) {
      std::ostringstream toml;
      toml.precision(17);
      // A 1 min Allan window: the default hour at 8 kHz is over the default memory budget.
      // Gyro-only frames: with the accel, rates above its 1 kHz output rate are refused (below).
      toml << "[device]\nbackend = \"mock\"\ndlpf = " << dlpf << "\naccel = false\nrate_hz = " << internal / n
           << "\n[allan]\nwindow_s = 60\n";
      EXPECT_EQ(errorOf(toml.str()), "") << toml.str();
    }
    for (double bad : {internal / 256.0 * 0.999, internal * 1.001, internal / 2.5, 47.0 * internal / 1000.0 + 0.3}) {
      std::ostringstream toml;
      toml.precision(17);
      toml << "[device]\ndlpf = " << dlpf << "\nrate_hz = " << bad << "\n";
      EXPECT_NE(errorOf(toml.str()).find("key 'device.rate_hz'"), std::string::npos) << toml.str();
    }
  }
}

TEST(ConfigValues, TheAccelIsRefusedAboveItsOutputRate) {
  // RM rev 4.2 §4.2: the accelerometer's output rate is 1 kHz. 1000 Hz with DLPF 0 (8 kHz / 8)
  // is the fastest rate with the accel; 8000/7 Hz is the next one up.
  EXPECT_EQ(errorOf("[device]\ndlpf = 0\nrate_hz = 1000\n[allan]\nwindow_s = 60\n"), "");
  for (const char* rate : {"1142.857142857143", "2000", "8000"}) {
    const std::string e = errorOf(std::string("[device]\ndlpf = 0\nrate_hz = ") + rate + "\n[allan]\nwindow_s = 60\n");
    EXPECT_EQ(e.rfind("x.toml:3: key 'device.rate_hz': must be at most 1000 Hz with device.accel = true", 0), 0u) << e;
    EXPECT_NE(e.find(std::string("(got ") + rate + ")"), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  // Gyro-only, 8 kHz is the chip's (on the mock: a real bus cannot carry it, below).
  EXPECT_EQ(errorOf("[device]\nbackend = \"mock\"\ndlpf = 0\naccel = false\nrate_hz = 8000\n[allan]\nwindow_s = 60\n"),
            "");
}

TEST(ConfigValues, ARateWhoseFramesTheI2cBusCannotCarryIsRefused) {
  // 8-byte frames x 9 clocks a byte at 8 kHz: 576 kbit/s, above the chip's 400 kHz clock.
  const std::string e = errorOf("[device]\ndlpf = 0\naccel = false\nrate_hz = 8000\n[allan]\nwindow_s = 60\n");
  EXPECT_EQ(e.rfind("x.toml:4: key 'device.rate_hz': must keep the FIFO's 8-byte frames within what the I2C bus", 0),
            0u)
      << e;
  EXPECT_NE(e.find("8000 Hz needs 576 kbit/s; the fastest rate that fits is 4000 Hz (got 8000)"), std::string::npos)
      << e;
  // 4 kHz gyro-only (288 kbit/s) and 1 kHz with the accel (126 kbit/s) fit.
  EXPECT_EQ(errorOf("[device]\ndlpf = 0\naccel = false\nrate_hz = 4000\n[allan]\nwindow_s = 60\n"), "");
  EXPECT_EQ(errorOf("[device]\ndlpf = 1\nrate_hz = 1000\n[allan]\nwindow_s = 60\n"), "");
}

// ---- error messages ---------------------------------------------------------------------

TEST(ConfigErrors, TomlSyntaxErrorNamesFileLineAndColumn) {
  const auto err = errorOf("[device]\nbackend = \"mock\"\nrate_hz = = 50\n");
  // "x.toml:3:COLUMN: description"
  ASSERT_EQ(err.rfind("x.toml:3:", 0), 0u) << err;
  const auto column_end = err.find_first_not_of("0123456789", 9);
  EXPECT_GT(column_end, 9u) << err;
  EXPECT_EQ(err.substr(column_end, 2), ": ") << err;
  EXPECT_GT(err.size(), column_end + 2) << err;
  EXPECT_EQ(err.find('\n'), std::string::npos) << err;
}

TEST(ConfigErrors, UnknownKeyNamesFileLineKeyAndTheValidKeys) {
  EXPECT_EQ(errorOf("[device]\nbackend = \"mock\"\nrat_hz = 50\n"),
            "x.toml:3: unknown key 'rat_hz' in [device] (valid keys: backend, bus, address, rate_hz, dlpf, "
            "full_scale_dps, accel, accel_range_g); did you mean 'rate_hz'?");
  // Nothing close: no suggestion.
  EXPECT_EQ(errorOf("[log]\nverbosity = 3\n"), "x.toml:2: unknown key 'verbosity' in [log] (valid keys: level)");
}

TEST(ConfigErrors, UnknownSectionAndTopLevelKey) {
  EXPECT_EQ(errorOf("[log]\nlevel = \"info\"\n\n[devise]\nbackend = \"mock\"\n"),
            "x.toml:4: unknown section [devise] (valid sections: device, gpio, bias, filter, allan, socket, record, "
            "log, mock, limits, mqtt, state, check); did you mean 'device'?");
  EXPECT_EQ(errorOf("rate_hz = 50\n"),
            "x.toml:1: unknown key 'rate_hz' at top level (keys belong in a section: device, gpio, bias, filter, "
            "allan, socket, record, log, mock, limits, mqtt, state, check)");
  EXPECT_EQ(errorOf("device = 5\n"), "x.toml:1: key 'device': must be a section [device] (got integer 5)");
}

TEST(ConfigErrors, UnknownKeysInNestedAndInlineTables) {
  EXPECT_EQ(errorOf("[mock.faults]\nvanishh = 3\n"),
            "x.toml:2: unknown key 'vanishh' in [mock.faults] (valid keys: transfer_error_fraction, error_burst, "
            "vanish, silent_reset_at_s, fifo_overflow_at_s, who_am_i, stuck_data_ready_at_s, "
            "stuck_data_ready_duration_s, glitch_burst); did you mean 'vanish'?");
  EXPECT_EQ(errorOf("[mock.faults]\nglitch_burst = [{ at_s = 1, axis = \"w\" }]\n"),
            "x.toml:2: key 'mock.faults.glitch_burst.axis': must be \"x\", \"y\" or \"z\" (got \"w\")");
  EXPECT_EQ(
      errorOf("[mock.faults]\nerror_burst = [\n  { at_s = 1, count = 2 },\n  { at_s = 3, cnt = 4 },\n]\n"),
      "x.toml:4: unknown key 'cnt' in [mock.faults.error_burst] (valid keys: at_s, count); did you mean 'count'?");
  EXPECT_EQ(errorOf("[filter]\nkalman = { a = 0.5, qq = 1 }\n"),
            "x.toml:2: unknown key 'qq' in [filter.kalman] (valid keys: a, q, r); did you mean 'q'?");
}

TEST(ConfigErrors, WrongTypeNamesKeyRequirementAndWhatWasWritten) {
  EXPECT_EQ(errorOf("[device]\n\nrate_hz = \"fifty\"\n"),
            "x.toml:3: key 'device.rate_hz': must be a number (got string \"fifty\")");
  EXPECT_EQ(errorOf("[filter]\nmean_window = 20.5\n"),
            "x.toml:2: key 'filter.mean_window': must be an integer (got float 20.5)");
  EXPECT_EQ(errorOf("[record]\nfsync_each_flush = 1\n"),
            "x.toml:2: key 'record.fsync_each_flush': must be true or false (got integer 1)");
  EXPECT_EQ(errorOf("[socket]\nmode = 660\n"),
            "x.toml:2: key 'socket.mode': must be a string of octal digits, e.g. \"0660\" (got integer 660)");
  EXPECT_EQ(errorOf("[device]\nrate_hz = nan\n"), "x.toml:2: key 'device.rate_hz': must be a finite number (got nan)");
  EXPECT_EQ(errorOf("[bias]\nvalues = [1, 2]\n"),
            "x.toml:2: key 'bias.values': must be an array of 3 numbers [x, y, z] in °/s (got an array of 2 elements)");
}

TEST(ConfigErrors, OutOfRangeNamesKeyRangeAndValue) {
  EXPECT_EQ(errorOf("[device]\nrate_hz = 47\n"),
            "x.toml:2: key 'device.rate_hz': must be 1000 Hz / N for a whole N in 1..256 (the chip's rate with dlpf "
            "4) (got 47)");
  EXPECT_EQ(errorOf("[device]\naddress = 0x70\n"),
            "x.toml:2: key 'device.address': must be 0x68 (AD0 low) or 0x69 (AD0 high) (got 0x70)");
  EXPECT_EQ(errorOf("[device]\ndlpf = 7\n"),
            "x.toml:2: key 'device.dlpf': must be a DLPF_CFG value 0..6 (7 is reserved) (got 7)");
  EXPECT_EQ(errorOf("[device]\nfull_scale_dps = 300\n"),
            "x.toml:2: key 'device.full_scale_dps': must be 250, 500, 1000 or 2000 (got 300)");
  EXPECT_EQ(errorOf("[device]\nbackend = \"spi\"\n"),
            "x.toml:2: key 'device.backend': must be one of i2c, mock (got \"spi\")");
  EXPECT_EQ(errorOf("[filter]\nmean_threshold_dps = 0\n"),
            "x.toml:2: key 'filter.mean_threshold_dps': must be > 0 °/s (got 0)");
  EXPECT_EQ(errorOf("[filter.kalman]\na = 1.5\n"),
            "x.toml:2: key 'filter.kalman.a': must be in [-1, 1] (A = φ1 of the AR(1) drift model) (got 1.5)");
  EXPECT_EQ(errorOf("[socket]\nmode = \"0999\"\n"),
            "x.toml:2: key 'socket.mode': must be octal permission bits as a string, e.g. \"0660\" (got \"0999\")");
  EXPECT_EQ(errorOf("[record]\nflush_interval_s = 0\n"),
            "x.toml:2: key 'record.flush_interval_s': must be between 0.01 and 3600 s (got 0)");
  EXPECT_EQ(
      errorOf("[log]\nlevel = \"verbose\"\n"),
      "x.toml:2: key 'log.level': must be one of trace, debug, info, warn, error, critical, off (got \"verbose\")");
  EXPECT_EQ(errorOf("[mock]\nspeed = 0\n"),
            "x.toml:2: key 'mock.speed': must be between 0.01 and 1000 (1 = real time) (got 0)");
  EXPECT_EQ(errorOf("[record]\npath = \"/tmp/\\u001b[2Jrec.csv\"\n"),
            "x.toml:2: key 'record.path': must be a path without control characters (got '/tmp/\\x1B[2Jrec.csv')");
  EXPECT_EQ(errorOf("[mock]\nspeed = 1e-320\n"),
            "x.toml:2: key 'mock.speed': must be between 0.01 and 1000 (1 = real time) (got 1e-320)");
  EXPECT_EQ(errorOf("[mock.faults]\ntransfer_error_fraction = 1.5\n"),
            "x.toml:2: key 'mock.faults.transfer_error_fraction': must be between 0 and 1 (got 1.5)");
  EXPECT_EQ(errorOf("[mock.faults]\nfifo_overflow_at_s = [1,\n -2]\n"),
            "x.toml:3: key 'mock.faults.fifo_overflow_at_s': must be a time ≥ 0 s, or an array of them (got -2)");
}

TEST(ConfigErrors, AllanTausMustBeWholeSamplePeriodsIncreasingAndWithinHalfTheWindow) {
  EXPECT_EQ(errorOf("[allan]\ntaus = [0.1, 0.03]\n"),
            "x.toml:2: key 'allan.taus': each τ must be a whole number of sample periods (τ0 = 0.02 s) (got 0.03)");
  EXPECT_EQ(errorOf("[allan]\ntaus = [1, 0.5]\n"),
            "x.toml:2: key 'allan.taus': τ values must be strictly increasing (got 0.5 after 1)");
  EXPECT_EQ(errorOf("[allan]\nwindow_s = 100\ntaus = [1, 60]\n"),
            "x.toml:3: key 'allan.taus': each τ must be ≤ allan.window_s / 2 (50 s) (got 60)");
  EXPECT_EQ(errorOf("[allan]\ntaus = \"decade\"\n"),
            "x.toml:2: key 'allan.taus': must be \"octave\" or an array of τ in seconds (got \"decade\")");
  // τ0 follows device.rate_hz: at 200 Hz, 0.005 s is one sample.
  EXPECT_EQ(errorOf("[device]\nrate_hz = 200\n[allan]\ntaus = [0.005]\n"), "");
}

TEST(ConfigErrors, SettingsThatNeedAnotherSetting) {
  EXPECT_EQ(errorOf("[bias]\nsource = \"model\"\n"),
            "x.toml:2: key 'bias.source': \"model\" needs filter.model (a model file from `gyroctl analyze "
            "--write-model`) (got \"model\")");
  EXPECT_EQ(errorOf("[gpio]\nchip = \"gpiochip0\"\n"),
            "x.toml:2: key 'gpio.chip': needs gpio.line (the offset of the line wired to the MPU-6050 INT pin) (got "
            "\"gpiochip0\")");
  EXPECT_EQ(errorOf("[mock]\nsource = \"replay\"\n"),
            "x.toml:2: key 'mock.source': \"replay\" needs mock.replay_file (a recording CSV t,gx,gy,gz,temp) (got "
            "\"replay\")");
  EXPECT_EQ(errorOf("[mock.faults]\nvanish = { at_s = 3 }\n"),
            "x.toml:2: key 'mock.faults.vanish': each outage needs at_s and duration_s (got a table)");
}

TEST(ConfigErrors, MissingOrUnreadableFile) {
  TempDir d;
  const auto missing = d.path("nope.toml");
  try {
    loadConfigFile(missing);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), missing + ": cannot open: No such file or directory");
  }
  // The file name in messages is the path as given.
  const auto f = d.write("bad.toml", "[device]\nrate_hz = 47\n");
  try {
    loadConfigFile(f);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(f + ":2: key 'device.rate_hz'", 0), 0u) << e.what();
  }
}

// ---- command line -----------------------------------------------------------------------

TEST(CommandLine, NoFileNoFlagsGivesTheDefaults) {
  TempDir d;
  const auto r = parseArgs({}, d.path("absent.toml"));
  EXPECT_FALSE(r.exit_code);
  EXPECT_TRUE(r.config_file.empty());
  EXPECT_TRUE(r.config == GyrodConfig{});
  const auto m = parseArgs({"--backend", "mock"}, d.path("absent.toml"));
  GyrodConfig expected;
  expected.device.backend = DeviceBackend::Mock;
  EXPECT_TRUE(m.config == expected);
}

TEST(CommandLine, DefaultFileIsLoadedWhenPresentAndConfigFlagReplacesIt) {
  TempDir d;
  const auto def = d.write("gyrod.toml", "[socket]\npath = \"/tmp/from-default.sock\"\n");
  const auto other = d.write("other.toml", "[socket]\npath = \"/tmp/from-other.sock\"\n");
  const auto a = parseArgs({}, def);
  EXPECT_EQ(a.config_file, def);
  EXPECT_EQ(a.config.socket.path, "/tmp/from-default.sock");
  const auto b = parseArgs({"--config", other}, def);
  EXPECT_EQ(b.config_file, other);
  EXPECT_EQ(b.config.socket.path, "/tmp/from-other.sock");
}

TEST(CommandLine, FlagsOverrideTheFile) {
  TempDir d;
  const auto f = d.write("g.toml",
                         "[device]\nbackend = \"i2c\"\n[socket]\npath = \"/tmp/file.sock\"\n[record]\npath = "
                         "\"/tmp/file.csv\"\n[mock]\nspeed = 2\n[log]\nlevel = \"warn\"\n");
  const auto r = parseArgs({"--config", f, "--backend", "mock", "--socket", "/tmp/flag.sock", "--record",
                            "/tmp/flag.csv", "--mock-speed", "50", "--log-level", "trace"},
                           d.path("absent.toml"));
  ASSERT_FALSE(r.exit_code) << r.message;
  EXPECT_EQ(r.config.device.backend, DeviceBackend::Mock);
  EXPECT_EQ(r.config.socket.path, "/tmp/flag.sock");
  EXPECT_EQ(r.config.record.path, "/tmp/flag.csv");
  EXPECT_EQ(r.config.mock.speed, 50.0);
  EXPECT_EQ(r.config.log.level, spdlog::level::trace);
  // Without flags the file's values stand.
  const auto s = parseArgs({"--config", f}, d.path("absent.toml"));
  EXPECT_EQ(s.config.device.backend, DeviceBackend::I2c);
  EXPECT_EQ(s.config.socket.path, "/tmp/file.sock");
  EXPECT_EQ(s.config.mock.speed, 2.0);
  EXPECT_EQ(s.config.log.level, spdlog::level::warn);
  // --record "" turns recording off.
  EXPECT_FALSE(parseArgs({"--config", f, "--record", ""}, d.path("absent.toml")).config.record.enabled());
}

TEST(CommandLine, BadUsageExitsWith64AndSaysWhy) {
  TempDir d;
  const auto none = d.path("absent.toml");
  const auto unknown = parseArgs({"--bakend", "mock"}, none);
  EXPECT_EQ(unknown.exit_code, 64);
  EXPECT_NE(unknown.message.find("--bakend"), std::string::npos) << unknown.message;
  const auto bad_backend = parseArgs({"--backend", "spi"}, none);
  EXPECT_EQ(bad_backend.exit_code, 64);
  EXPECT_NE(bad_backend.message.find("spi"), std::string::npos) << bad_backend.message;
  const auto bad_speed = parseArgs({"--mock-speed", "-1"}, none);
  EXPECT_EQ(bad_speed.exit_code, 64);
  EXPECT_EQ(bad_speed.message, "--mock-speed: must be between 0.01 and 1000 (got -1)\n");
  EXPECT_EQ(parseArgs({"--record", "/tmp/\x1b[2Jrec.csv"}, none).message,
            "--record: must be a path without control characters (got '/tmp/\\x1B[2Jrec.csv')\n");
  EXPECT_EQ(parseArgs({"--mock-speed", "1e-320"}, none).message,
            "--mock-speed: must be between 0.01 and 1000 (got 1e-320)\n");
  const auto bad_level = parseArgs({"--log-level", "loud"}, none);
  EXPECT_EQ(bad_level.exit_code, 64);
  const auto help = parseArgs({"--help"}, none);
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.message.find("--mock-speed"), std::string::npos) << help.message;
  const auto version = parseArgs({"--version"}, none);
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.message.find("gyrod"), std::string::npos) << version.message;
}

TEST(CommandLine, ABadConfigFileIsAConfigError) {
  TempDir d;
  const auto f = d.write("g.toml", "[device]\nrat_hz = 50\n");
  EXPECT_THROW(parseArgs({"--config", f}, d.path("absent.toml")), ConfigError);
  EXPECT_THROW(parseArgs({"--config", d.path("missing.toml")}, d.path("absent.toml")), ConfigError);
  // A broken default file is an error too, not silently skipped.
  EXPECT_THROW(parseArgs({}, f), ConfigError);
}

// A file read at start-up (and at SIGHUP) checks what the configuration refers to, with the
// key's file:line; text parsed on its own does not (it may come from another machine).
TEST(ConfigErrors, ReferencedFilesAndGroupAreCheckedWhenLoadingAFile) {
  TempDir d;
  const auto missing_model = d.path("no-model.toml");
  const auto model = d.write("model.toml", "[filter]\nmean_window = 5\nmodel = \"" + missing_model + "\"\n");
  try {
    loadConfigFile(model);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(model + ":3: key 'filter.model': " + missing_model + ": ", 0), 0u) << m;
    EXPECT_NE(m.find("No such file or directory"), std::string::npos) << m;
  }
  const auto group = d.write("group.toml", "[socket]\ngroup = \"no-such-group-gyrod-test\"\n");
  try {
    loadConfigFile(group);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), group +
                                         ":2: key 'socket.group': no such group on this system (got "
                                         "\"no-such-group-gyrod-test\")");
  }
  const auto bad_csv = d.write("bad.csv", "t,gx,gy,gz,temp\n0,1,2,x,25\n");
  const auto replay = d.write(
      "replay.toml", "[device]\nbackend = \"mock\"\n[mock]\nsource = \"replay\"\nreplay_file = \"" + bad_csv + "\"\n");
  try {
    loadConfigFile(replay);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(replay + ":5: key 'mock.replay_file': " + bad_csv + ":2: ", 0), 0u) << m;
  }
  // 30 Hz and a real record's 100.31 Hz do not divide the chip's 1 kHz internal rate (dlpf 4):
  // the mock replays them at their own rate, its clock 1 % slow and 0.31 % fast.
  const auto odd_rate = d.write("odd.csv", "t,gx\n0,1\n0.0333333333333,2\n0.0666666666667,3\n");
  const auto odd = d.write(
      "odd.toml", "[device]\nbackend = \"mock\"\n[mock]\nsource = \"replay\"\nreplay_file = \"" + odd_rate + "\"\n");
  EXPECT_NO_THROW(loadConfigFile(odd));
  const std::string real =
      std::string(GYROD_TEST_DATA_DIR) + "/mpu6050-sensor-fusion-set1/unmoved-x-pointing-forward.csv";
  const auto real_toml = d.write(
      "real.toml", "[device]\nbackend = \"mock\"\n[mock]\nsource = \"replay\"\nreplay_file = \"" + real + "\"\n");
  EXPECT_NO_THROW(loadConfigFile(real_toml));
  // 400 Hz: 2.5 ticks of 1 kHz; 2 or 3 would need the clock 20 % off, beyond the mock's 10 %.
  const auto fast_rate = d.write("fast.csv", "t,gx\n0,1\n0.0025,2\n0.005,3\n");
  const auto fast = d.write(
      "fast.toml", "[device]\nbackend = \"mock\"\n[mock]\nsource = \"replay\"\nreplay_file = \"" + fast_rate + "\"\n");
  try {
    loadConfigFile(fast);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(fast + ":5: key 'mock.replay_file': a recording at 400", 0), 0u) << m;
    EXPECT_NE(m.find("cannot be replayed at the chip's internal rate of 1000 Hz"), std::string::npos) << m;
  }
  const auto good_rate = d.write("good.csv", "t,gx\n0,1\n0.02,2\n0.04,3\n");
  const auto good = d.write(
      "good.toml", "[device]\nbackend = \"mock\"\n[mock]\nsource = \"replay\"\nreplay_file = \"" + good_rate + "\"\n");
  EXPECT_NO_THROW(loadConfigFile(good));
  EXPECT_NO_THROW(parseConfig(readText(model), "x.toml"));
  EXPECT_NO_THROW(parseConfig(readText(group), "x.toml"));
}

// bias.still_seconds out of range, or too short for what the still period must do at the
// configured rate, is a configuration error naming the file, the line and the key (exit 78)
// rather than a failure after start.
TEST(ConfigErrors, StillSecondsOutOfRangeOrTooShortNamesFileLineAndKey) {
  EXPECT_EQ(errorOf("[bias]\nstill_seconds = 0\n"),
            "x.toml:2: key 'bias.still_seconds': must be > 0 and ≤ 3600 s (got 0)");
  EXPECT_EQ(errorOf("[bias]\nstill_seconds = 4000\n"),
            "x.toml:2: key 'bias.still_seconds': must be > 0 and ≤ 3600 s (got 4000)");
  EXPECT_EQ(errorOf("[bias]\nstill_seconds = 1\n"),
            "x.toml:2: key 'bias.still_seconds': must give at least 100 samples at device.rate_hz = 50 Hz (2 s) to "
            "identify the Kalman filter, unless filter.kalman gives a, q and r (got 1)");
  // With a, q and r given the still period only averages the bias: one sample is enough.
  EXPECT_EQ(errorOf("[bias]\nstill_seconds = 1\n[filter.kalman]\na = 0.5\nq = 0.01\nr = 0.02\n"), "");
  EXPECT_EQ(errorOf("[bias]\nstill_seconds = 0.001\n[filter.kalman]\na = 0.5\nq = 0.01\nr = 0.02\n"),
            "x.toml:2: key 'bias.still_seconds': must give at least 1 sample at device.rate_hz = 50 Hz (0.02 s) "
            "(got 0.001)");
  // Nothing to estimate or identify: no still period, no requirement.
  EXPECT_EQ(errorOf("[bias]\nsource = \"config\"\nstill_seconds = 0.001\n[filter.kalman]\na = 0.5\nq = 0.01\n"
                    "r = 0.02\n"),
            "");
  EXPECT_EQ(exitCodeForConfigError(), 78);
}

TEST(ConfigValues, TheDefaultStillPeriodGrowsToTheSamplesItNeedsBelowTenHertz) {
  EXPECT_EQ(parseConfig("[device]\nrate_hz = 50\n", "x.toml").bias.still_seconds, 10.0);
  // 1000 / 256 Hz: 100 samples take 25.6 s.
  EXPECT_EQ(parseConfig("[device]\nrate_hz = 3.90625\n", "x.toml").bias.still_seconds, 26.0);
}

TEST(ConfigMqtt, ValuesAreReadAndBadOnesNameFileLineAndKey) {
  const GyrodConfig c = parseConfig(
      "[mqtt]\nurl = \"mqtt://broker.lan:1884\"\nprefix = \"lab/bench-3\"\nqos = 1\nclient_id = \"b3\"\n"
      "rate_every = 50\nusername = \"gyrod\"\npassword_file = \"/run/credentials/p\"\n",
      "x.toml");
  EXPECT_TRUE(c.mqtt.enabled());
  EXPECT_EQ(c.mqtt.prefix, "lab/bench-3");
  EXPECT_EQ(c.mqtt.qos, 1);
  EXPECT_EQ(c.mqtt.rate_every, 50u);
  const MqttEndpoint e = parseMqttUrl(c.mqtt.url);
  EXPECT_EQ(e.host, "broker.lan");
  EXPECT_EQ(e.port, 1884);
  EXPECT_EQ(parseMqttUrl("mqtt://[::1]:1885").host, "::1");
  EXPECT_EQ(parseMqttUrl("mqtt://10.0.0.2").port, 1883);
  EXPECT_FALSE(parseConfig("[log]\nlevel = \"info\"\n", "x.toml").mqtt.enabled());

  const auto error = [](const std::string& line) { return errorOf("[mqtt]\n" + line + "\n"); };
  EXPECT_NE(error("url = \"mqtts:/b:8883\"").find("x.toml:2: key 'mqtt.url'"), std::string::npos)
      << error("url = \"mqtts:/b:8883\"");
  EXPECT_NE(error("url = \"http://b\"").find("mqtts://HOST[:PORT] (TLS)"), std::string::npos);
  EXPECT_NE(error("url = \"mqtt://b:0\"").find("port must be 1..65535"), std::string::npos);
  EXPECT_NE(error("url = \"mqtt://\"").find("must name a host"), std::string::npos);
  EXPECT_NE(error("qos = 2").find("x.toml:2: key 'mqtt.qos'"), std::string::npos);
  EXPECT_NE(error("prefix = \"a/#\"").find("key 'mqtt.prefix'"), std::string::npos);
  EXPECT_NE(error("prefix = \"/a\"").find("key 'mqtt.prefix'"), std::string::npos);
  EXPECT_NE(error("rate_every = 0").find("key 'mqtt.rate_every'"), std::string::npos);
  EXPECT_NE(error("password_file = \"/p\"").find("needs mqtt.username"), std::string::npos);
  EXPECT_NE(error("colour = 1").find("unknown key"), std::string::npos);
}

TEST(ConfigMqtt, BufferAndTlsKeysAreReadAndBadOnesNameFileLineAndKey) {
  EXPECT_EQ(parseConfig("[mqtt]\nurl = \"mqtt://b\"\n", "x.toml").mqtt.buffer_messages, 60000u);
  const GyrodConfig c = parseConfig(
      "[mqtt]\nurl = \"mqtts://broker.lan\"\nqos = 1\nbuffer_messages = 500\nca_file = \"/etc/gyrod/ca.pem\"\n"
      "cert_file = \"/etc/gyrod/board.pem\"\nkey_file = \"/etc/gyrod/board.key\"\n",
      "x.toml");
  EXPECT_EQ(c.mqtt.buffer_messages, 500u);
  EXPECT_EQ(c.mqtt.ca_file, "/etc/gyrod/ca.pem");
  EXPECT_EQ(c.mqtt.cert_file, "/etc/gyrod/board.pem");
  EXPECT_EQ(c.mqtt.key_file, "/etc/gyrod/board.key");
  const MqttEndpoint tls = parseMqttUrl(c.mqtt.url);
  EXPECT_TRUE(tls.tls);
  EXPECT_EQ(tls.port, 8883);
  EXPECT_EQ(parseMqttUrl("mqtts://b:9999").port, 9999);
  EXPECT_FALSE(parseMqttUrl("mqtt://b").tls);

  const auto error = [](const std::string& lines) { return errorOf("[mqtt]\nurl = \"mqtts://b\"\n" + lines + "\n"); };
  EXPECT_EQ(error("buffer_messages = -1"),
            "x.toml:3: key 'mqtt.buffer_messages': must be 0..100000000 messages (0: none kept while the broker is "
            "away) (got -1)");
  EXPECT_NE(error("buffer_messages = \"many\"").find("x.toml:3: key 'mqtt.buffer_messages'"), std::string::npos);
  EXPECT_NE(error("ca_file = \"\"").find("x.toml:3: key 'mqtt.ca_file': must be a path"), std::string::npos);
  EXPECT_NE(error("cert_file = \"/c.pem\"").find("x.toml:3: key 'mqtt.cert_file': needs mqtt.key_file"),
            std::string::npos);
  EXPECT_NE(error("key_file = \"/k.pem\"").find("x.toml:3: key 'mqtt.key_file': needs mqtt.cert_file"),
            std::string::npos);
  const std::string plain = errorOf("[mqtt]\nurl = \"mqtt://b\"\nca_file = \"/ca.pem\"\n");
  EXPECT_NE(plain.find("x.toml:3: key 'mqtt.ca_file': needs an mqtts:// url (TLS)"), std::string::npos) << plain;
}

// The TLS files are read as every file gyrod reads: a regular file, within a size limit.
TEST(ConfigMqtt, TlsFilesMustBeRegularFilesWhenLoadingAFile) {
  TempDir d;
  const auto ca = d.write("ca.pem", "-----BEGIN CERTIFICATE-----\n");
  const auto good = d.write("good.toml", "[mqtt]\nurl = \"mqtts://b\"\nca_file = \"" + ca + "\"\n");
  EXPECT_EQ(loadConfigFile(good).mqtt.ca_file, ca);
  const auto cases = {std::pair{"ca_file", d.path("")}, std::pair{"cert_file", d.path("missing.pem")},
                      std::pair{"key_file", std::string("/dev/zero")}};
  for (const auto& [key, path] : cases) {
    const std::string other = std::string(key) == "ca_file"     ? ""
                              : std::string(key) == "cert_file" ? "key_file = \"" + ca + "\"\n"
                                                                : "cert_file = \"" + ca + "\"\n";
    const auto f = d.write("tls.toml", "[mqtt]\nurl = \"mqtts://b\"\n" + other + key + " = \"" + path + "\"\n");
    try {
      loadConfigFile(f);
      ADD_FAILURE() << key << " = " << path << ": no error";
    } catch (const ConfigError& e) {
      const std::string line = other.empty() ? ":3: " : ":4: ";
      EXPECT_EQ(std::string(e.what()).rfind(f + line + "key 'mqtt." + key + "': " + path, 0), 0u) << e.what();
    }
  }
}

TEST(ConfigValues, TheStateDirectoryAndItsSaveInterval) {
  const GyrodConfig defaults = parseConfig("", "x.toml");
  EXPECT_EQ(defaults.state.directory, "");  // systemd's $STATE_DIRECTORY, if any, at start
  EXPECT_EQ(defaults.state.save_interval_s, 600.0);
  const GyrodConfig c = parseConfig("[state]\ndirectory = \"/var/lib/gyrod\"\nsave_interval_s = 60\n", "x.toml");
  EXPECT_EQ(c.state.directory, "/var/lib/gyrod");
  EXPECT_EQ(c.state.save_interval_s, 60.0);
  EXPECT_EQ(errorOf("[state]\nsave_interval_s = 0.5\n"),
            "x.toml:2: key 'state.save_interval_s': must be between 1 and 86400 s (got 0.5)");
  EXPECT_EQ(errorOf("[state]\ndirectory = 3\n"), "x.toml:2: key 'state.directory': must be a string (got integer 3)");
  EXPECT_EQ(errorOf("[state]\ndir = \"/tmp\"\n").rfind("x.toml:2: unknown key 'dir' in [state]", 0), 0u);
}

TEST(ConfigValues, TheLiveCheck) {
  const GyrodConfig defaults = parseConfig("", "x.toml");
  EXPECT_TRUE(defaults.check.enabled);
  EXPECT_EQ(defaults.check.interval_s, 300.0);
  EXPECT_EQ(defaults.check.baseline_s, 1800.0);
  EXPECT_EQ(defaults.check.false_alarms_per_week, 0.25);
  const GyrodConfig c = parseConfig(
      "[check]\nenabled = false\ninterval_s = 120\nbaseline_s = 600\nfalse_alarms_per_week = 1\n", "x.toml");
  EXPECT_FALSE(c.check.enabled);
  EXPECT_EQ(c.check.interval_s, 120.0);
  EXPECT_EQ(c.check.baseline_s, 600.0);
  EXPECT_EQ(c.check.false_alarms_per_week, 1.0);
  // A long interval with the default baseline: the baseline becomes one interval.
  EXPECT_EQ(parseConfig("[check]\ninterval_s = 3600\n", "x.toml").check.baseline_s, 3600.0);
  EXPECT_EQ(errorOf("[check]\ninterval_s = 10\n"),
            "x.toml:2: key 'check.interval_s': must be between 60 and 86400 s (got 10)");
  EXPECT_EQ(errorOf("[device]\nrate_hz = 4\n[check]\ninterval_s = 60\n"),
            "x.toml:4: key 'check.interval_s': must hold at least 512 samples at 4 Hz (got 60)");
  EXPECT_EQ(
      errorOf("[check]\ninterval_s = 600\nbaseline_s = 300\n"),
      "x.toml:3: key 'check.baseline_s': must be at least check.interval_s (600 s) and at most 604800 s (got 300)");
  EXPECT_EQ(errorOf("[check]\nfalse_alarms_per_week = 0\n"),
            "x.toml:2: key 'check.false_alarms_per_week': must be > 0 and at most 100 (got 0)");
}
