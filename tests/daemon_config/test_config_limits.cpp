// [limits] memory_mb: the memory a configuration needs is computed before anything is
// allocated, and a configuration above the budget is an error naming the key that sizes it.
#include <gtest/gtest.h>

#include <string>

#include "daemon/command_line.hpp"
#include "daemon/config.hpp"
#include "daemon/memory_budget.hpp"

using namespace gyrod::daemon;

namespace {

std::string limitsErrorOf(const std::string& text) {
  try {
    parseConfig(text, "x.toml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST(ConfigLimits, DefaultBudgetHoldsTheDefaultsAndAnHourAtOneKilohertz) {
  const GyrodConfig defaults;
  EXPECT_EQ(defaults.limits.memory_mb, 1024.0);
  const double default_need = memoryNeeded(defaults).total_bytes;
  EXPECT_LT(default_need, 64e6);
  // 9 streams x 180000 samples x 16 B, at least.
  EXPECT_GT(default_need, 9.0 * 180000 * 16);
  const GyrodConfig khz = parseConfig("[device]\nrate_hz = 1000\n[allan]\nwindow_s = 3600\n", "x.toml");
  const double need = memoryNeeded(khz).total_bytes;
  EXPECT_GT(need, 9.0 * 3.6e6 * 16 + 3.6e6 * 32);
  EXPECT_LT(need, 1024e6);
}

TEST(ConfigLimits, AWindowOfATrillionSecondsNamesTheKeyTheFigureAndTheBudget) {
  const std::string e = limitsErrorOf("[allan]\nwindow_s = 1e12\n");
  EXPECT_TRUE(contains(e, "x.toml:2: key 'allan.window_s': gyrod would need 8.8e+09 MB of memory")) << e;
  EXPECT_TRUE(contains(e, "above limits.memory_mb = 1024 MB")) << e;
  EXPECT_TRUE(contains(e, "(got 1e+12)")) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  const std::string ten_million = limitsErrorOf("[allan]\nwindow_s = 10000000\n");
  EXPECT_TRUE(contains(ten_million, "x.toml:2: key 'allan.window_s': gyrod would need")) << ten_million;
  EXPECT_TRUE(contains(ten_million, "(got 10000000)")) << ten_million;
}

TEST(ConfigLimits, EightKilohertzWithTheDefaultWindowIsNamedAtTheRate) {
  const std::string e = limitsErrorOf("[device]\nbackend = \"mock\"\ndlpf = 0\naccel = false\nrate_hz = 8000\n");
  EXPECT_TRUE(contains(e, "x.toml:5: key 'allan.window_s':")) << e;
  EXPECT_TRUE(contains(e, "9 streams x 2.88e+07 samples x 16 B")) << e;
  EXPECT_TRUE(contains(e, "(3600, the default)")) << e;
  // A shorter window, or a larger budget, is accepted.
  EXPECT_EQ(
      limitsErrorOf("[device]\nbackend = \"mock\"\ndlpf = 0\naccel = false\nrate_hz = 8000\n[allan]\nwindow_s = 600\n"),
      "");
  EXPECT_EQ(limitsErrorOf(
                "[device]\nbackend = \"mock\"\ndlpf = 0\naccel = false\nrate_hz = 8000\n[limits]\nmemory_mb = 6000\n"),
            "");
}

TEST(ConfigLimits, TheLargestConsumerIsNamed) {
  // 32 clients x 64 MiB of output buffer = 2.1 GB.
  const std::string e = limitsErrorOf("[socket]\nclient_buffer_kib = 65536\n");
  EXPECT_TRUE(contains(e, "x.toml:2: key 'socket.client_buffer_kib':")) << e;
  EXPECT_TRUE(contains(e, "32 clients x 65536 KiB")) << e;
  const std::string still = limitsErrorOf(
      "[device]\nbackend = \"mock\"\ndlpf = 0\naccel = false\nrate_hz = 8000\n[bias]\nstill_seconds = 3600\n"
      "[allan]\nwindow_s = 60\n[limits]\nmemory_mb = 500\n");
  EXPECT_TRUE(contains(still, "x.toml:7: key 'bias.still_seconds':")) << still;
  // With the budget at its line when the key is not in the file.
  const std::string at_budget = limitsErrorOf("[limits]\nmemory_mb = 16\n");
  EXPECT_TRUE(contains(at_budget, "x.toml:2: key 'allan.window_s':")) << at_budget;
  EXPECT_TRUE(contains(at_budget, "above limits.memory_mb = 16 MB")) << at_budget;
}

TEST(ConfigLimits, MemoryMbIsChecked) {
  EXPECT_EQ(parseConfig("[limits]\nmemory_mb = 4096\n", "x.toml").limits.memory_mb, 4096.0);
  EXPECT_TRUE(
      contains(limitsErrorOf("[limits]\nmemory_mb = 0\n"), "x.toml:2: key 'limits.memory_mb': must be 16..1e9 MB"));
  EXPECT_TRUE(contains(limitsErrorOf("[limits]\nmemory_mb = nan\n"), "key 'limits.memory_mb'"));
  EXPECT_TRUE(contains(limitsErrorOf("[limits]\nmemory = 1\n"), "unknown key 'memory' in [limits]"));
}

TEST(ConfigLimits, TheRecorderRingFollowsTheMockSpeed) {
  GyrodConfig c;
  c.device.backend = DeviceBackend::Mock;
  c.mock.speed = 50.0;
  EXPECT_EQ(recordedSamplesPerSecond(c), 2500.0);
  c.device.backend = DeviceBackend::I2c;
  EXPECT_EQ(recordedSamplesPerSecond(c), 50.0);
}

// Values and names from the file are echoed bounded (80 characters) and escaped, so that a
// hostile file cannot flood the terminal or act on it (formats/quoted_value.hpp).
TEST(ConfigEcho, BadValuesAndNamesAreQuotedBoundedAndEscaped) {
  const std::string long_value(100000, 'x');
  const std::string e = limitsErrorOf("[log]\nlevel = \"" + long_value + "\"\n");
  EXPECT_TRUE(contains(e, "x.toml:2: key 'log.level': must be one of")) << e;
  EXPECT_TRUE(contains(e, "(got '" + std::string(80, 'x') + "…' (100000 bytes))")) << e;
  EXPECT_LT(e.size(), 300u);
  const std::string esc = limitsErrorOf("[log]\nlevel = \"\\u001b[2J\\u202Eevil\"\n");
  EXPECT_TRUE(contains(esc, "(got '\\x1B[2J\\u{202E}evil')")) << esc;
  EXPECT_EQ(esc.find('\x1b'), std::string::npos);
  const std::string key = limitsErrorOf("[device]\n\"a\\u001bb\" = 1\n");
  EXPECT_TRUE(contains(key, "unknown key 'a\\x1Bb' in [device]")) << key;
  const std::string section = limitsErrorOf("[\"s\\u202E\"]\nx = 1\n");
  EXPECT_TRUE(contains(section, "unknown section ['s\\u{202E}']")) << section;
  const std::string top = limitsErrorOf("\"k\\u0007\" = 1\n");
  EXPECT_TRUE(contains(top, "unknown key 'k\\x07' at top level")) << top;
  // An ordinary value reads as before.
  EXPECT_TRUE(contains(limitsErrorOf("[log]\nlevel = \"verbose\"\n"), "(got \"verbose\")"));
}

TEST(ConfigRecordFlag, AFolderWithASlashIsRecordedInto) {
  GyrodConfig c;
  CommandLineOverrides o;
  o.record_path = "/var/lib/gyrod/";
  applyOverrides(c, o);
  EXPECT_EQ(c.record.path, "/var/lib/gyrod/gyro.csv");
  o.record_path = "/tmp/x.csv";
  applyOverrides(c, o);
  EXPECT_EQ(c.record.path, "/tmp/x.csv");
}

// record.path and --record follow one rule: a value ending in '/' is a folder recorded into.
TEST(ConfigRecordFlag, TheFileAndTheFlagTakeAFolderAlike) {
  const GyrodConfig from_file = parseConfig("[record]\npath = \"/x/rec/\"\n", "g.toml");
  EXPECT_EQ(from_file.record.path, "/x/rec/gyro.csv");
  GyrodConfig from_flag;
  CommandLineOverrides o;
  o.record_path = "/x/rec/";
  applyOverrides(from_flag, o);
  EXPECT_EQ(from_flag.record.path, from_file.record.path);
  EXPECT_EQ(parseConfig("[record]\npath = \"/x/rec/a.csv\"\n", "g.toml").record.path, "/x/rec/a.csv");
  EXPECT_FALSE(parseConfig("[record]\npath = \"\"\n", "g.toml").record.enabled());
}
