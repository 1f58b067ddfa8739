#include "daemon/config.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <grp.h>
#include <unistd.h>

#include "daemon/memory_budget.hpp"
#include "daemon/recorder.hpp"
#include "daemon/sample_pipeline.hpp"
#include "driver/fifo_frame.hpp"
#include "driver/mock/replay_clock.hpp"
#include "driver/mpu6050_config.hpp"
#include "formats/input_file.hpp"
#include "formats/model_toml.hpp"
#include "formats/motion_spec.hpp"
#include "formats/quoted_value.hpp"
#include "formats/recording_csv.hpp"
#include "formats/toml_document.hpp"

namespace gyrod::daemon {
namespace {

using Section = formats::TomlSection;
using formats::shortest;

const std::vector<std::string_view> kSections = {"device", "gpio", "bias",   "filter", "allan", "socket", "record",
                                                 "log",    "mock", "limits", "mqtt",   "state", "check"};
const std::vector<std::string_view> kBiasSourceNames = {"estimate", "model", "config"};
const std::vector<std::string_view> kMockSourceNames = {"simulator", "replay"};

// A name from the file as a message shows it: a long or hostile one bounded and escaped.
std::string shownName(std::string_view name) {
  const std::string quoted = formats::quotedValue(name);
  return quoted == "'" + std::string(name) + "'" ? std::string(name) : quoted;
}

bool isAllDigits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

void readDevice(const Section& s, DeviceConfig& d) {
  if (auto b = s.choice("backend", kBackendNames)) d.backend = *b == 0 ? DeviceBackend::I2c : DeviceBackend::Mock;
  if (const auto* n = s.node("bus")) {
    std::string text;
    if (auto i = n->as_integer())
      text = std::to_string(i->get());
    else if (auto str = n->as_string())
      text = str->get();
    else
      s.failType(*n, "bus", "must be a bus number (1 → /dev/i2c-1) or a device path");
    try {
      d.bus = i2cDevicePath(text);
    } catch (const ConfigError&) {
      s.failValue("bus", "must be a bus number ≥ 0 (1 → /dev/i2c-1) or a path starting with '/'");
    }
  }
  if (auto a = s.integer("address")) {
    if (*a != 0x68 && *a != 0x69) {
      std::ostringstream got;
      got << "0x" << std::hex << *a;
      s.fail(*s.node("address"), "address", "must be 0x68 (AD0 low) or 0x69 (AD0 high)", got.str());
    }
    d.address = static_cast<int>(*a);
  }
  if (auto v = s.integer("dlpf")) {
    if (*v < 0 || *v > 6) s.failValue("dlpf", "must be a DLPF_CFG value 0..6 (7 is reserved)");
    d.dlpf = static_cast<int>(*v);
  }
  if (auto v = s.integer("full_scale_dps")) {
    if (*v != 250 && *v != 500 && *v != 1000 && *v != 2000)
      s.failValue("full_scale_dps", "must be 250, 500, 1000 or 2000");
    d.full_scale_dps = static_cast<int>(*v);
  }
  if (auto v = s.boolean("accel")) d.accel = *v;
  if (auto v = s.integer("accel_range_g")) {
    if (*v != 2 && *v != 4 && *v != 8 && *v != 16) s.failValue("accel_range_g", "must be 2, 4, 8 or 16");
    d.accel_range_g = static_cast<int>(*v);
  }
  if (auto v = s.number("rate_hz")) d.rate_hz = *v;
  // Checked even when rate_hz keeps its default, since dlpf changes the internal rate.
  // The chip's rule (driver/mpu6050_config.hpp): gyro output rate / (1 + SMPLRT_DIV).
  const double internal = driver::mpu6050::gyroOutputRateHz(d.dlpf);
  if (!driver::smplrtDivFor(d.dlpf, d.rate_hz)) {
    std::ostringstream req;
    req << "must be " << shortest(internal) << " Hz / N for a whole N in 1..256 (the chip's rate with dlpf " << d.dlpf
        << ")";
    if (s.has("rate_hz")) s.failValue("rate_hz", req.str());
    const char* which = s.has("dlpf") ? "dlpf" : "rate_hz";
    s.fail(*s.node(which), "rate_hz", req.str(), shortest(d.rate_hz) + ", the default");
  }
  // The accelerometer's output rate is 1 kHz (Register Map rev 4.2, SMPLRT_DIV): faster, the
  // FIFO repeats each accel sample, and at 8 kHz its 1024 bytes hold 9 ms of 14-byte frames
  // (16 ms of the gyro's 8-byte ones). rate_hz is above 1000 only when written, so it is the
  // key to name.
  if (d.accel && d.rate_hz > driver::mpu6050::kAccelOutputRateHz)
    s.failValue("rate_hz",
                "must be at most 1000 Hz with device.accel = true: the accelerometer's output rate is "
                "1 kHz, so faster frames repeat its samples and fill the FIFO in 9 ms at 8 kHz; set "
                "device.accel = false for a gyro-only rate above 1 kHz");
  // On a real bus the FIFO's frames alone must fit in what I2C carries at the chip's fastest
  // clock; reading them costs more (addresses, FIFO_COUNT), so this refuses only what can
  // never stream. The mock's bus has no clock.
  if (d.backend == DeviceBackend::I2c) {
    namespace chip = driver::mpu6050;
    const auto frame_bytes = static_cast<double>(driver::frameBytesFor(d.accel));
    const double bits_per_s = d.rate_hz * frame_bytes * chip::kI2cClocksPerByte;
    if (bits_per_s > chip::kMaxI2cClockHz) {
      std::ostringstream req;
      req << "must keep the FIFO's " << frame_bytes << "-byte frames within what the I2C bus carries at the "
          << "MPU6050's fastest clock, 400 kHz: " << shortest(d.rate_hz) << " Hz needs "
          << std::llround(bits_per_s / 1000.0) << " kbit/s; the fastest rate that fits is "
          << shortest(internal / std::ceil(internal * frame_bytes * chip::kI2cClocksPerByte / chip::kMaxI2cClockHz))
          << " Hz";
      s.failValue("rate_hz", req.str());
    }
  }
}

void readGpio(const Section& s, GpioConfig& g) {
  if (auto c = s.string("chip")) {
    if (c->find_first_of(" \t\n") != std::string::npos)
      s.failValue("chip", "must be a chip name or path without spaces");
    g.chip = *c;
  }
  if (auto l = s.integer("line")) {
    if (*l < 0 || *l > 1023) s.failValue("line", "must be a line offset 0..1023");
    g.line = static_cast<int>(*l);
  }
  if (!g.chip.empty() && !g.line)
    s.failValue("chip", "needs gpio.line (the offset of the line wired to the MPU-6050 INT pin)");
}

void readBias(const Section& s, BiasConfig& b) {
  if (auto v = s.choice("source", kBiasSourceNames))
    b.source = *v == 0 ? BiasSource::Estimate : *v == 1 ? BiasSource::Model : BiasSource::Config;
  if (auto v = s.number("still_seconds")) {
    if (!(*v > 0.0 && *v <= 3600.0)) s.failValue("still_seconds", "must be > 0 and ≤ 3600 s");
    b.still_seconds = *v;
  }
  if (const auto* n = s.node("values")) {
    const auto* a = n->as_array();
    if (!a || a->size() != 3 || !std::all_of(a->begin(), a->end(), [](const toml::node& e) { return e.is_number(); }))
      s.fail(*n, "values", "must be an array of 3 numbers [x, y, z] in °/s",
             a ? "an array of " + std::to_string(a->size()) + " elements" : formats::tomlTypeAndValue(*n));
    b.values.clear();
    for (const auto& e : *a) b.values.push_back(s.numberFrom(e, "values"));
  }
}

// The still period must hold the samples its uses need (SamplePipeline refuses fewer): checked
// here, so that it is a configuration error at its line (EX_CONFIG) rather than a failure at start.
void checkStillPeriodLength(const Section& bias, GyrodConfig& c) {
  const auto& k = c.filter.kalman;
  const bool identifying = !(k.a && k.q && k.r);
  if (!identifying && c.bias.source != BiasSource::Estimate) return;  // no still period
  const double needed = identifying ? static_cast<double>(kMinimumIdentificationSamples) : 1.0;
  if (static_cast<double>(std::llround(c.bias.still_seconds * c.device.rate_hz)) >= needed) return;
  if (!bias.has("still_seconds")) {  // the default 10 s is too short below 10 Hz: as long as needed
    c.bias.still_seconds = std::ceil(needed / c.device.rate_hz);
    return;
  }
  std::ostringstream requirement;
  requirement << "must give at least " << shortest(needed) << (needed > 1.0 ? " samples" : " sample")
              << " at device.rate_hz = " << shortest(c.device.rate_hz) << " Hz (" << shortest(needed / c.device.rate_hz)
              << " s)" << (identifying ? " to identify the Kalman filter, unless filter.kalman gives a, q and r" : "");
  bias.failValue("still_seconds", requirement.str());
}

void readFilter(const Section& s, FilterConfig& f, double rate_hz) {
  if (auto v = s.integer("mean_window")) {
    if (*v < 1 || *v > 100000) s.failValue("mean_window", "must be a window length 1..100000 samples");
    f.mean_window = static_cast<std::size_t>(*v);
  }
  if (auto v = s.number("mean_threshold_dps")) {
    if (!(*v > 0.0)) s.failValue("mean_threshold_dps", "must be > 0 °/s");
    f.mean_threshold_dps = *v;
  }
  if (auto v = s.string("model")) f.model = *v;
  if (auto v = s.number("rate_low_pass_hz")) {
    // A first-order low-pass at or past Nyquist is no low-pass (its bilinear form breaks down).
    if (!(*v >= 0.0 && *v < rate_hz / 2.0))
      s.failValue("rate_low_pass_hz",
                  "must be 0 (off) or a cut-off > 0 Hz below half device.rate_hz (" + shortest(rate_hz / 2.0) + " Hz)");
    f.rate_low_pass_hz = *v;
  }
  for (const auto& k : s.tables("kalman", {"a", "q", "r"})) {
    if (!s.node("kalman")->is_table()) s.failType(*s.node("kalman"), "kalman", "must be a table");
    if (auto v = k.number("a")) {
      if (!(std::abs(*v) <= 1.0)) k.failValue("a", "must be in [-1, 1] (A = φ1 of the AR(1) drift model)");
      f.kalman.a = *v;
    }
    if (auto v = k.number("q")) {
      if (!(*v >= 0.0)) k.failValue("q", "must be ≥ 0 (Q is a variance, (°/s)²)");
      f.kalman.q = *v;
    }
    if (auto v = k.number("r")) {
      if (!(*v > 0.0)) k.failValue("r", "must be > 0 (R is a variance, (°/s)²)");
      f.kalman.r = *v;
    }
  }
}

void readAllan(const Section& s, AllanConfig& a, double rate_hz) {
  const double tau0 = 1.0 / rate_hz;
  if (auto v = s.number("window_s")) {
    if (!(*v * rate_hz >= 4.0))
      s.failValue("window_s", "must hold at least 4 samples (≥ " + shortest(4.0 * tau0) + " s at device.rate_hz)");
    a.window_s = *v;
  }
  if (auto v = s.number("refit_interval_s")) {
    if (!(*v > 0.0 && *v <= a.window_s))
      s.failValue("refit_interval_s", "must be > 0 and ≤ allan.window_s (" + shortest(a.window_s) + " s)");
    a.refit_interval_s = *v;
  }
  if (const auto* n = s.node("taus")) {
    if (auto str = n->as_string()) {
      if (str->get() != "octave") s.failValue("taus", "must be \"octave\" or an array of τ in seconds");
      a.taus_s.clear();
    } else if (auto arr = n->as_array()) {
      if (arr->empty()) s.fail(*n, "taus", "must be \"octave\" or a non-empty array of τ in seconds", "[]");
      a.taus_s.clear();
      // Overlapping ADEV at τ = m·τ0 needs M ≥ 2m samples (NIST SP 1065 eq. 14 has M − 2m + 1 terms).
      const double tau_max = a.window_s / 2.0;
      for (const auto& e : *arr) {
        if (!e.is_number()) s.failType(e, "taus", "must be \"octave\" or an array of τ in seconds");
        const double tau = s.numberFrom(e, "taus");
        const double m = tau * rate_hz;
        if (!(tau > 0.0) || std::abs(m - std::round(m)) > 1e-9 * std::max(1.0, m) || std::round(m) < 1.0)
          s.fail(e, "taus", "each τ must be a whole number of sample periods (τ0 = " + shortest(tau0) + " s)",
                 shortest(tau));
        if (tau > tau_max)
          s.fail(e, "taus", "each τ must be ≤ allan.window_s / 2 (" + shortest(tau_max) + " s)", shortest(tau));
        if (!a.taus_s.empty() && !(tau > a.taus_s.back()))
          s.fail(e, "taus", "τ values must be strictly increasing",
                 shortest(tau) + " after " + shortest(a.taus_s.back()));
        a.taus_s.push_back(tau);
      }
    } else {
      s.failType(*n, "taus", "must be \"octave\" or an array of τ in seconds");
    }
  }
}

void readSocket(const Section& s, SocketConfig& c) {
  if (auto v = s.string("path")) {
    if (v->empty()) s.failValue("path", "must not be empty");
    // sockaddr_un.sun_path holds 108 bytes including the terminating NUL.
    if (v->size() > 107) s.failValue("path", "must be at most 107 bytes (sockaddr_un limit)");
    c.path = *v;
  }
  if (s.has("mode") && !s.node("mode")->is_string())
    s.failType(*s.node("mode"), "mode", "must be a string of octal digits, e.g. \"0660\"");
  if (auto v = s.string("mode")) {
    unsigned mode = 0;
    const auto [end, ec] = std::from_chars(v->data(), v->data() + v->size(), mode, 8);
    if (v->empty() || ec != std::errc() || end != v->data() + v->size() || mode > 0777)
      s.failValue("mode", "must be octal permission bits as a string, e.g. \"0660\"");
    c.mode = mode;
  }
  if (auto v = s.string("group")) c.group = *v;
  if (auto v = s.integer("client_buffer_kib")) {
    if (*v < 4 || *v > 65536) s.failValue("client_buffer_kib", "must be 4..65536 KiB");
    c.client_buffer_kib = static_cast<std::size_t>(*v);
  }
}

// A topic level of our own: printable, no MQTT wildcard, no empty level.
bool validTopicPrefix(std::string_view p) {
  if (p.empty() || p.size() > 200 || p.front() == '/' || p.back() == '/' || hasControlCharacter(p)) return false;
  if (p.find_first_of("+#") != std::string_view::npos || p.find("//") != std::string_view::npos) return false;
  return true;
}

void readMqttTls(const Section& s, MqttConfig& m) {
  for (const auto& [key, member] :
       {std::pair{"ca_file", &MqttConfig::ca_file}, std::pair{"cert_file", &MqttConfig::cert_file},
        std::pair{"key_file", &MqttConfig::key_file}}) {
    if (auto v = s.string(key)) {
      if (v->empty() || hasControlCharacter(*v)) s.failValue(key, "must be a path without control characters");
      m.*member = *v;
    }
  }
  const bool tls = !m.url.empty() && parseMqttUrl(m.url).tls;
  for (const char* key : {"ca_file", "cert_file", "key_file"})
    if (s.has(key) && !tls) s.failValue(key, "needs an mqtts:// url (TLS)");
  if (!m.cert_file.empty() && m.key_file.empty())
    s.failValue("cert_file", "needs mqtt.key_file (the client certificate's private key)");
  if (!m.key_file.empty() && m.cert_file.empty()) s.failValue("key_file", "needs mqtt.cert_file (its certificate)");
}

void readMqtt(const Section& s, MqttConfig& m) {
  if (auto v = s.string("url")) {
    try {
      parseMqttUrl(*v);
    } catch (const std::invalid_argument& e) {
      s.failValue("url", e.what());
    }
    m.url = *v;
  }
  if (auto v = s.string("prefix")) {
    if (!validTopicPrefix(*v))
      s.failValue("prefix",
                  "must be topic levels like \"gyrod/bench-3\": no '+', '#', control characters, "
                  "empty levels or leading/trailing '/'");
    m.prefix = *v;
  }
  if (auto v = s.integer("qos")) {
    if (*v != 0 && *v != 1) s.failValue("qos", "must be 0 or 1");
    m.qos = static_cast<int>(*v);
  }
  if (auto v = s.string("client_id")) {
    if (v->empty() || v->size() > 64 || hasControlCharacter(*v))
      s.failValue("client_id", "must be 1..64 printable characters");
    m.client_id = *v;
  }
  if (auto v = s.integer("rate_every")) {
    if (*v < 1 || *v > 1'000'000) s.failValue("rate_every", "must be 1..1000000 (1: every RATE line)");
    m.rate_every = static_cast<std::size_t>(*v);
  }
  if (auto v = s.string("username")) {
    if (hasControlCharacter(*v)) s.failValue("username", "must not contain control characters");
    m.username = *v;
  }
  if (auto v = s.string("password_file")) {
    if (v->empty() || hasControlCharacter(*v))
      s.failValue("password_file", "must be a path without control characters");
    m.password_file = *v;
  }
  if (!m.password_file.empty() && m.username.empty())
    s.failValue("password_file", "needs mqtt.username (the broker checks the pair)");
  if (auto v = s.integer("buffer_messages")) {
    if (*v < 0 || *v > 100'000'000)
      s.failValue("buffer_messages", "must be 0..100000000 messages (0: none kept while the broker is away)");
    m.buffer_messages = static_cast<std::size_t>(*v);
  }
  readMqttTls(s, m);
  if (auto v = s.boolean("home_assistant")) m.home_assistant = *v;
  if (auto v = s.string("home_assistant_prefix")) {
    if (!validTopicPrefix(*v))
      s.failValue("home_assistant_prefix",
                  "must be topic levels like \"homeassistant\": no '+', '#', control characters, empty levels or "
                  "leading/trailing '/'");
    m.home_assistant_prefix = *v;
  }
}

void readRecord(const Section& s, RecordConfig& r) {
  if (auto v = s.string("path")) {
    if (hasControlCharacter(*v)) s.failValue("path", "must be a path without control characters");
    r.path = recordingBaseName(*v);
  }
  if (auto v = s.number("rotate_mb")) {
    if (!(*v == 0.0 || *v >= 0.01)) s.failValue("rotate_mb", "must be 0 (never) or ≥ 0.01 MB");
    r.rotate_mb = *v;
  }
  if (auto v = s.number("rotate_minutes")) {
    if (!(*v >= 0.0)) s.failValue("rotate_minutes", "must be 0 (never) or > 0 minutes");
    r.rotate_minutes = *v;
  }
  if (auto v = s.number("flush_interval_s")) {
    if (!(*v >= 0.01 && *v <= 3600.0)) s.failValue("flush_interval_s", "must be between 0.01 and 3600 s");
    r.flush_interval_s = *v;
  }
  if (auto v = s.boolean("fsync_each_flush")) r.fsync_each_flush = *v;
  if (auto v = s.integer("keep")) {
    if (*v < 0 || *v > 1000000) s.failValue("keep", "must be 0 (keep all) or a number of files ≥ 1");
    r.keep = static_cast<std::size_t>(*v);
  }
}

void readState(const Section& s, StateConfig& st) {
  if (auto v = s.string("directory")) {
    if (hasControlCharacter(*v)) s.failValue("directory", "must be a path without control characters");
    st.directory = *v;
  }
  if (auto v = s.number("save_interval_s")) {
    if (!(*v >= 1.0 && *v <= 86400.0)) s.failValue("save_interval_s", "must be between 1 and 86400 s");
    st.save_interval_s = *v;
  }
}

void readCheck(const Section& s, CheckConfig& c, double rate_hz) {
  if (auto v = s.boolean("enabled")) c.enabled = *v;
  if (auto v = s.number("interval_s")) {
    if (!(*v >= 60.0 && *v <= 86400.0)) s.failValue("interval_s", "must be between 60 and 86400 s");
    // The analysis rate: the device's, averaged down to at most kLiveCheckMaxRateHz.
    const double analysed = rate_hz / std::ceil(rate_hz / kLiveCheckMaxRateHz - 1e-9);
    if (*v * analysed < 512.0)
      s.failValue("interval_s", "must hold at least 512 samples at " + shortest(analysed) + " Hz");
    c.interval_s = *v;
  }
  if (auto v = s.number("baseline_s")) {
    if (!(*v >= c.interval_s && *v <= 604800.0))
      s.failValue("baseline_s",
                  "must be at least check.interval_s (" + shortest(c.interval_s) + " s) and at most 604800 s");
    c.baseline_s = *v;
  } else if (c.baseline_s < c.interval_s) {
    c.baseline_s = c.interval_s;  // the default baseline, when the interval is longer
  }
  if (auto v = s.number("false_alarms_per_week")) {
    if (!(*v > 0.0 && *v <= 100.0)) s.failValue("false_alarms_per_week", "must be > 0 and at most 100");
    c.false_alarms_per_week = *v;
  }
}

void readLimits(const Section& s, LimitsConfig& l) {
  if (auto v = s.number("memory_mb")) {
    if (!(*v >= 16.0 && *v <= 1e9)) s.failValue("memory_mb", "must be 16..1e9 MB (10^6 bytes)");
    l.memory_mb = *v;
  }
}

// The memory the configuration needs against limits.memory_mb and, with the reference
// checks, against what the kernel would grant; named at the line of the key that sizes most
// of it (its value echoed), else of the key it is multiplied by, else of memory_mb.
void checkMemory(const formats::TomlDocument& doc, const GyrodConfig& config, ReferenceChecks checks) {
  const MemoryNeed need = memoryNeeded(config);
  auto problem = memoryBudgetProblem(need, config.limits.memory_mb * 1e6,
                                     "limits.memory_mb = " + formats::shortest(config.limits.memory_mb) + " MB",
                                     "limits.memory_mb");
  if (!problem && checks == ReferenceChecks::On)
    if (const auto kernel = kernelMemoryLimit())
      problem = memoryBudgetProblem(need, kernel->bytes, kernel->name, kernel->raise);
  if (!problem) return;
  const auto* node = doc.root().at_path(problem->key).node();
  std::string where = doc.file() + ": ", suffix;
  if (node) {
    where = doc.location(node->source());
    suffix = " (got " + formats::tomlRendered(*node) + ")";
  } else {
    for (const char* other : {"device.rate_hz", "limits.memory_mb"}) {
      if (const auto* n = doc.root().at_path(other).node()) {
        where = doc.location(n->source());
        break;
      }
    }
    const auto item =
        std::find_if(need.items.begin(), need.items.end(), [&](const MemoryItem& i) { return i.key == problem->key; });
    suffix = " (" + item->value + ", the default)";
  }
  throw ConfigError(where + "key '" + problem->key + "': " + problem->message + suffix);
}

void readLog(const Section& s, LogConfig& l) {
  if (auto v = s.choice("level", kLogLevelNames)) l.level = kLogLevels[*v];
}

// Validated here, as every other key, so that a bad spec stops gyrod at start with the
// file and line of the key (a motion CSV's own errors name its file and line as well).
void readMockMotion(const Section& s, MockConfig& m) {
  const auto v = s.string("motion");
  if (!v || v->empty()) return;
  if (m.source == MockSource::Replay)
    s.failValue("motion", "applies to source = \"simulator\" only (a replayed recording already holds its motion)");
  try {
    (void)recording::motionFromSpec(*v);
  } catch (const std::invalid_argument& e) {
    s.failValue("motion", e.what());
  } catch (const recording::RecordingError& e) {
    s.failValue("motion", e.what());
  }
  m.motion = *v;
}

// [mock] warm_up ("DELTA_C,TAU_S", as gyroctl simulate --warm-up) and
// temperature_coefficient_dps_per_c (one number, or [x, y, z]): the simulator's board warms up and
// its bias follows through the coupling (docs/mock-device.md).
void readMockWarmUp(const Section& s, MockConfig& m) {
  if (auto v = s.string("warm_up"); v && !v->empty()) {
    if (m.source == MockSource::Replay) s.failValue("warm_up", "applies to source = \"simulator\" only");
    try {
      (void)processing::withWarmUp({}, recording::parseWarmUpSpec(*v));
    } catch (const std::invalid_argument& e) {
      s.failValue("warm_up", e.what());
    }
    m.warm_up = *v;
  }
  const std::string key = "temperature_coefficient_dps_per_c";
  const std::string requirement = "must be a finite number in °/s per °C, or an array of 3 of them [x, y, z]";
  const auto k = s.numbers(
      key, [](double v) { return std::isfinite(v); }, requirement);
  if (!k) return;
  if (m.source == MockSource::Replay) s.failValue(key, "applies to source = \"simulator\" only");
  if (k->size() != 1 && k->size() != 3) s.failValue(key, requirement);
  m.temperature_coefficient_dps_per_c = k->size() == 1 ? std::vector<double>(3, k->front()) : *k;
}

void readMock(const Section& s, MockConfig& m) {
  if (auto v = s.choice("source", kMockSourceNames)) m.source = *v == 0 ? MockSource::Simulator : MockSource::Replay;
  if (auto v = s.string("replay_file")) m.replay_file = *v;
  if (m.source == MockSource::Replay && m.replay_file.empty())
    s.failValue("source", "\"replay\" needs mock.replay_file (a recording CSV t,gx,gy,gz,temp)");
  if (auto v = s.integer("seed")) {
    if (*v < 0) s.failValue("seed", "must be ≥ 0");
    m.seed = static_cast<std::uint64_t>(*v);
  }
  if (auto v = s.number("speed")) {
    if (!(*v >= kMinMockSpeed && *v <= kMaxMockSpeed))
      s.failValue("speed", "must be between " + shortest(kMinMockSpeed) + " and " + shortest(kMaxMockSpeed) +
                               " (1 = real time)");
    m.speed = *v;
  }
  readMockMotion(s, m);
  readMockWarmUp(s, m);
  if (!s.has("faults")) return;
  if (!s.node("faults")->is_table()) s.failType(*s.node("faults"), "faults", "must be a table");
  const Section f(s.file(), *s.node("faults")->as_table(), s.qualified("faults"),
                  {"transfer_error_fraction", "error_burst", "vanish", "silent_reset_at_s", "fifo_overflow_at_s",
                   "who_am_i", "stuck_data_ready_at_s", "stuck_data_ready_duration_s", "glitch_burst"});
  auto& faults = m.faults;
  const auto nonNegative = [](double t) { return t >= 0.0; };
  const std::string time_requirement = "must be a time ≥ 0 s, or an array of them";
  if (auto v = f.number("transfer_error_fraction")) {
    if (!(*v >= 0.0 && *v <= 1.0)) f.failValue("transfer_error_fraction", "must be between 0 and 1");
    faults.transfer_error_fraction = *v;
  }
  for (const auto& b : f.tables("error_burst", {"at_s", "count"})) {
    MockErrorBurst burst;
    if (auto v = b.number("at_s")) {
      if (!(*v >= 0.0)) b.failValue("at_s", "must be ≥ 0 s");
      burst.at_s = *v;
    } else {
      f.failValue("error_burst", "each burst needs at_s");
    }
    if (auto v = b.integer("count")) {
      if (*v < 1 || *v > 1000000) b.failValue("count", "must be 1..1000000 transfers");
      burst.count = static_cast<std::uint32_t>(*v);
    }
    faults.error_bursts.push_back(burst);
  }
  for (const auto& g : f.tables("glitch_burst", {"at_s", "duration_s", "count", "axis", "bit"})) {
    MockGlitchBurst burst;
    if (auto v = g.number("at_s")) {
      if (!(*v >= 0.0)) g.failValue("at_s", "must be ≥ 0 s");
      burst.at_s = *v;
    } else {
      f.failValue("glitch_burst", "each burst needs at_s");
    }
    if (auto v = g.number("duration_s")) {
      if (!(*v >= 0.0)) g.failValue("duration_s", "must be ≥ 0 s");
      burst.duration_s = *v;
    }
    if (auto v = g.integer("count")) {
      if (*v < 1 || *v > 1000000) g.failValue("count", "must be 1..1000000 samples");
      burst.count = static_cast<std::uint32_t>(*v);
    }
    if (auto v = g.string("axis")) {
      if (*v != "x" && *v != "y" && *v != "z") g.failValue("axis", "must be \"x\", \"y\" or \"z\"");
      burst.axis = (*v)[0] - 'x';
    }
    if (auto v = g.integer("bit")) {
      if (*v < 0 || *v > 15) g.failValue("bit", "must be a bit of the 16-bit word, 0..15");
      burst.bit = static_cast<int>(*v);
    }
    faults.glitch_bursts.push_back(burst);
  }
  for (const auto& t : f.tables("vanish", {"at_s", "duration_s", "power_lost"})) {
    MockVanish v;
    if (auto x = t.number("at_s")) {
      if (!(*x >= 0.0)) t.failValue("at_s", "must be ≥ 0 s");
      v.at_s = *x;
    } else {
      f.failValue("vanish", "each outage needs at_s and duration_s");
    }
    if (auto x = t.number("duration_s")) {
      if (!(*x > 0.0)) t.failValue("duration_s", "must be > 0 s");
      v.duration_s = *x;
    } else {
      f.failValue("vanish", "each outage needs at_s and duration_s");
    }
    if (auto x = t.boolean("power_lost")) v.power_lost = *x;
    faults.vanish.push_back(v);
  }
  if (auto v = f.numbers("silent_reset_at_s", nonNegative, time_requirement)) faults.silent_reset_at_s = *v;
  if (auto v = f.numbers("fifo_overflow_at_s", nonNegative, time_requirement)) faults.fifo_overflow_at_s = *v;
  if (auto v = f.integer("who_am_i")) {
    if (*v < 0 || *v > 255) f.failValue("who_am_i", "must be a register value 0..255 (e.g. 0x72)");
    faults.who_am_i = static_cast<int>(*v);
  }
  if (auto v = f.numbers("stuck_data_ready_at_s", nonNegative, time_requirement)) faults.stuck_data_ready_at_s = *v;
  if (auto v = f.number("stuck_data_ready_duration_s")) {
    if (!(*v > 0.0)) f.failValue("stuck_data_ready_duration_s", "must be > 0 s");
    faults.stuck_data_ready_duration_s = *v;
  }
}

}  // namespace

std::string_view toString(DeviceBackend b) { return kBackendNames[b == DeviceBackend::I2c ? 0 : 1]; }
std::string_view toString(BiasSource s) {
  return kBiasSourceNames[s == BiasSource::Estimate ? 0 : s == BiasSource::Model ? 1 : 2];
}
std::string_view toString(MockSource s) { return kMockSourceNames[s == MockSource::Simulator ? 0 : 1]; }

std::string recordingBaseName(const std::string& setting) {
  if (!setting.empty() && setting.back() == '/') return setting + kDefaultRecordingName;
  return setting;
}

std::string i2cDevicePath(std::string_view bus) {
  if (isAllDigits(bus) && bus.size() <= 6) return "/dev/i2c-" + std::to_string(std::stoul(std::string(bus)));
  if (!bus.empty() && bus.front() == '/') return std::string(bus);
  throw ConfigError("I2C bus '" + std::string(bus) +
                    "': must be a bus number ≥ 0 (1 → /dev/i2c-1) or a path starting with '/'");
}

namespace {

bool groupExists(const std::string& name) {
  long size = ::sysconf(_SC_GETGR_R_SIZE_MAX);
  std::vector<char> buffer(size > 0 ? static_cast<std::size_t>(size) : 16384);
  group entry{};
  group* found = nullptr;
  while (::getgrnam_r(name.c_str(), &entry, buffer.data(), buffer.size(), &found) == ERANGE)
    buffer.resize(buffer.size() * 2);
  return found != nullptr;
}

// The files and names the configuration refers to, read as start-up will use them, so that
// a bad one stops gyrod with exit 78 and the file:line of its key, and a SIGHUP that names
// one keeps the running settings (both go through loadConfigFile).
// A TLS file is read by OpenSSL inside libmosquitto; it is checked here as every file gyrod
// reads is (formats/input_file.hpp), so that a directory or a FIFO is refused at its line.
void checkMqttFiles(const Section& mqtt, const MqttConfig& m) {
  for (const auto& [key, path] :
       {std::pair{"ca_file", &m.ca_file}, std::pair{"cert_file", &m.cert_file}, std::pair{"key_file", &m.key_file}}) {
    if (path->empty()) continue;
    try {
      (void)formats::readInputFile(*path, formats::kTlsFileInput);
    } catch (const std::exception& e) {
      mqtt.failValue(key, e.what());
    }
  }
}

void checkReferences(const Section& filter, const Section& socket, const Section& mock, const GyrodConfig& config) {
  if (!config.filter.model.empty()) {
    try {
      (void)recording::readModelToml(config.filter.model);
    } catch (const std::exception& e) {
      filter.failValue("model", e.what());
    }
  }
  if (!config.socket.group.empty() && !groupExists(config.socket.group))
    socket.failValue("group", "no such group on this system");
  if (config.device.backend == DeviceBackend::Mock && config.mock.source == MockSource::Replay) {
    double rate = 50.0;  // as the replay source assumes for a file without t
    try {
      recording::ReadOptions replay;
      replay.input_kind = &formats::kReplayInput;
      const recording::Recording rec = recording::readRecordingCsv(config.mock.replay_file, replay);
      if (rec.t.size() >= 2) rate = recording::sampleRateFromTimes(rec);
    } catch (const std::exception& e) {
      mock.failValue("replay_file", e.what());
    }
    // The mock holds each recorded sample for a whole number of the chip's ticks, its clock
    // run fast or slow by up to 10 % to make up the rest (driver/mock/replay_clock.hpp).
    const double internal = driver::mpu6050::gyroOutputRateHz(config.device.dlpf);
    if (!driver::replayClockFor(rate, internal)) {
      std::ostringstream cause;  // 6 digits: a rate inferred from t is not exact anyway
      cause << "a recording at " << rate << " Hz cannot be replayed at the chip's internal rate of " << internal
            << " Hz (no whole number of ticks per sample within the mock's 10 % clock tolerance)";
      mock.failValue("replay_file", cause.str());
    }
  }
}

GyrodConfig readConfig(const formats::TomlDocument& doc, ReferenceChecks checks) {
  const auto& root = doc.root();
  GyrodConfig config;
  // Unknown top-level names first, so that a misspelt section is reported as such.
  for (auto&& [key, node] : root) {
    const auto name = key.str();
    const auto where = doc.location(key.source());
    if (std::find(kSections.begin(), kSections.end(), name) == kSections.end()) {
      if (node.is_table())
        throw ConfigError(where + "unknown section [" + shownName(name) + "] (valid sections: " +
                          formats::joinedNames(kSections) + ")" + formats::didYouMean(name, kSections));
      throw ConfigError(where + "unknown key " + formats::quotedValue(name) +
                        " at top level (keys belong in a section: " + formats::joinedNames(kSections) + ")");
    }
    if (!node.is_table())
      throw ConfigError(where + "key " + formats::quotedValue(name) + ": must be a section [" + shownName(name) +
                        "] (got " + formats::tomlTypeAndValue(node) + ")");
  }
  const toml::table empty;
  const auto section = [&](std::string_view name, std::vector<std::string_view> keys) {
    const auto* t = root.get_as<toml::table>(name);
    return Section(doc.file(), t ? *t : empty, std::string(name), std::move(keys));
  };

  // device first: allan checks τ against device.rate_hz.
  readDevice(
      section("device", {"backend", "bus", "address", "rate_hz", "dlpf", "full_scale_dps", "accel", "accel_range_g"}),
      config.device);
  readGpio(section("gpio", {"chip", "line"}), config.gpio);
  const auto bias = section("bias", {"source", "still_seconds", "values"});
  readBias(bias, config.bias);
  const auto filter = section("filter", {"mean_window", "mean_threshold_dps", "model", "rate_low_pass_hz", "kalman"});
  readFilter(filter, config.filter, config.device.rate_hz);
  if (config.filter.rate_low_pass_hz.value_or(0.0) > 0.0 && config.filter.model.empty())
    filter.failValue("rate_low_pass_hz", "needs filter.model (without a model, rate is raw − the constant bias)");
  if (config.bias.source == BiasSource::Model && config.filter.model.empty())
    bias.failValue("source", "\"model\" needs filter.model (a model file from `gyroctl analyze --write-model`)");
  checkStillPeriodLength(bias, config);
  readAllan(section("allan", {"window_s", "refit_interval_s", "taus"}), config.allan, config.device.rate_hz);
  const auto socket = section("socket", {"path", "mode", "group", "client_buffer_kib"});
  readSocket(socket, config.socket);
  readRecord(section("record", {"path", "rotate_mb", "rotate_minutes", "flush_interval_s", "fsync_each_flush", "keep"}),
             config.record);
  readLog(section("log", {"level"}), config.log);
  const auto mock = section("mock", {"source", "replay_file", "seed", "speed", "motion", "warm_up",
                                     "temperature_coefficient_dps_per_c", "faults"});
  readMock(mock, config.mock);
  readLimits(section("limits", {"memory_mb"}), config.limits);
  const auto mqtt = section(
      "mqtt", {"url", "prefix", "qos", "client_id", "rate_every", "username", "password_file", "buffer_messages",
               "ca_file", "cert_file", "key_file", "home_assistant", "home_assistant_prefix"});
  readMqtt(mqtt, config.mqtt);
  readState(section("state", {"directory", "save_interval_s"}), config.state);
  readCheck(section("check", {"enabled", "interval_s", "baseline_s", "false_alarms_per_week"}), config.check,
            config.device.rate_hz);
  if (checks == ReferenceChecks::On) {
    checkReferences(filter, socket, mock, config);
    checkMqttFiles(mqtt, config.mqtt);
  }
  checkMemory(doc, config, checks);
  return config;
}

}  // namespace

GyrodConfig parseConfig(std::string_view toml_text, const std::string& source_name, ReferenceChecks checks) {
  try {
    return readConfig(formats::TomlDocument(toml_text, source_name, formats::SyntaxErrorColumn::Shown), checks);
  } catch (const formats::TomlError& e) {
    throw ConfigError(e.what());
  }
}

GyrodConfig loadConfigFile(const std::string& path) {
  std::string text;
  try {
    text = formats::readInputFile(path, formats::kConfigurationInput);
  } catch (const formats::InputFileError& e) {
    throw ConfigError(e.what());
  }
  return parseConfig(text, path, ReferenceChecks::On);
}

}  // namespace gyrod::daemon
