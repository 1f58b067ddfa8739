#include "daemon/config.hpp"

#include <CLI/CLI.hpp>
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "driver/mpu6050_config.hpp"


#ifndef GYROD_VERSION
#define GYROD_VERSION "unknown"
#endif

namespace gyrod::daemon {
namespace {

std::string shortest(double v) {
  std::array<char, 32> buf{};
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  (void)ec;  // 32 characters always hold the shortest round-trip form of a double
  return std::string(buf.data(), end);
}

std::string joined(const std::vector<std::string_view>& names, std::string_view separator = ", ") {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i) s += separator;
    s += names[i];
  }
  return s;
}

// Levenshtein distance, for "did you mean" on a misspelt key.
std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string suggestion(std::string_view typo, const std::vector<std::string_view>& valid) {
  std::string_view best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (auto v : valid) {
    const auto d = editDistance(typo, v);
    if (d < best_distance) best_distance = d, best = v;
  }
  // Only close matches: at most 2 edits, and fewer than half the letters.
  if (best_distance <= 2 && best_distance * 2 <= std::max(typo.size(), best.size()))
    return "; did you mean '" + std::string(best) + "'?";
  return {};
}

// A value as the user wrote it, for "(got ...)".
std::string rendered(const toml::node& n) {
  if (auto s = n.as_string()) return "\"" + s->get() + "\"";
  if (auto i = n.as_integer()) return std::to_string(i->get());
  if (auto f = n.as_floating_point()) return shortest(f->get());
  if (auto b = n.as_boolean()) return b->get() ? "true" : "false";
  if (n.is_array()) return "an array";
  if (n.is_table()) return "a table";
  return "a date/time";
}

std::string typeAndValue(const toml::node& n) {
  if (n.is_string()) return "string " + rendered(n);
  if (n.is_integer()) return "integer " + rendered(n);
  if (n.is_floating_point()) return "float " + rendered(n);
  if (n.is_boolean()) return "boolean " + rendered(n);
  return rendered(n);
}

// One table of the file with the keys it may hold. Knows the file and its own dotted
// name so that every message can say FILE:LINE: key 'section.key': ...
class Section {
 public:
  Section(const std::string& file, const toml::table& table, std::string name, std::vector<std::string_view> keys)
      : file_(file), table_(table), name_(std::move(name)), keys_(std::move(keys)) {
    for (auto&& [key, node] : table_) {
      (void)node;
      if (std::find(keys_.begin(), keys_.end(), key.str()) != keys_.end()) continue;
      std::ostringstream s;
      s << location(key.source()) << "unknown key '" << key.str() << "' in [" << name_ << "] (valid keys: "
        << joined(keys_) << ")" << suggestion(key.str(), keys_);
      throw ConfigError(s.str());
    }
  }

  const std::string& file() const { return file_; }
  const std::string& name() const { return name_; }
  std::string qualified(std::string_view key) const { return name_ + "." + std::string(key); }
  const toml::node* node(std::string_view key) const { return table_.get(key); }
  bool has(std::string_view key) const { return node(key) != nullptr; }

  std::string location(const toml::source_region& r) const {
    return r.begin.line > 0 ? file_ + ":" + std::to_string(r.begin.line) + ": " : file_ + ": ";
  }
  [[noreturn]] void fail(const toml::node& n, std::string_view key, const std::string& requirement,
                         const std::string& got) const {
    throw ConfigError(location(n.source()) + "key '" + qualified(key) + "': " + requirement + " (got " + got + ")");
  }
  [[noreturn]] void failValue(std::string_view key, const std::string& requirement) const {
    const auto& n = *node(key);
    fail(n, key, requirement, rendered(n));
  }
  [[noreturn]] void failType(const toml::node& n, std::string_view key, const std::string& requirement) const {
    fail(n, key, requirement, typeAndValue(n));
  }

  // A finite number (integers are accepted where a number is asked for).
  std::optional<double> number(std::string_view key) const {
    const auto* n = node(key);
    if (!n) return std::nullopt;
    return numberFrom(*n, key);
  }
  double numberFrom(const toml::node& n, std::string_view key) const {
    double v = 0.0;
    if (auto i = n.as_integer()) v = static_cast<double>(i->get());
    else if (auto f = n.as_floating_point()) v = f->get();
    else failType(n, key, "must be a number");
    if (!std::isfinite(v)) fail(n, key, "must be a finite number", rendered(n));
    return v;
  }
  std::optional<std::int64_t> integer(std::string_view key) const {
    const auto* n = node(key);
    if (!n) return std::nullopt;
    if (auto i = n->as_integer()) return i->get();
    failType(*n, key, "must be an integer");
  }
  std::optional<std::string> string(std::string_view key) const {
    const auto* n = node(key);
    if (!n) return std::nullopt;
    if (auto s = n->as_string()) return s->get();
    failType(*n, key, "must be a string");
  }
  std::optional<bool> boolean(std::string_view key) const {
    const auto* n = node(key);
    if (!n) return std::nullopt;
    if (auto b = n->as_boolean()) return b->get();
    failType(*n, key, "must be true or false");
  }
  // One of `choices`, returned as its index.
  std::optional<std::size_t> choice(std::string_view key, const std::vector<std::string_view>& choices) const {
    const auto s = string(key);
    if (!s) return std::nullopt;
    const auto it = std::find(choices.begin(), choices.end(), *s);
    if (it == choices.end()) failValue(key, "must be one of " + joined(choices, ", "));
    return static_cast<std::size_t>(it - choices.begin());
  }
  // A number, or an array of numbers, each checked by `ok`.
  template <class Ok>
  std::optional<std::vector<double>> numbers(std::string_view key, Ok ok, const std::string& requirement) const {
    const auto* n = node(key);
    if (!n) return std::nullopt;
    std::vector<double> values;
    if (auto a = n->as_array()) {
      for (const auto& element : *a) {
        if (!element.is_number()) failType(element, key, requirement);
        values.push_back(numberFrom(element, key));
        if (!ok(values.back())) fail(element, key, requirement, rendered(element));
      }
    } else {
      if (!n->is_number()) failType(*n, key, requirement);
      values.push_back(numberFrom(*n, key));
      if (!ok(values.back())) failValue(key, requirement);
    }
    return values;
  }
  // A sub-table, or an array of sub-tables (e.g. several bursts), each with `keys`.
  std::vector<Section> tables(std::string_view key, std::vector<std::string_view> keys) const {
    std::vector<Section> out;
    const auto* n = node(key);
    if (!n) return out;
    if (auto t = n->as_table()) {
      out.emplace_back(file_, *t, qualified(key), keys);
    } else if (auto a = n->as_array()) {
      for (const auto& element : *a) {
        if (!element.is_table()) failType(element, key, "must be a table { ... } or an array of them");
        out.emplace_back(file_, *element.as_table(), qualified(key), keys);
      }
    } else {
      failType(*n, key, "must be a table { ... } or an array of them");
    }
    return out;
  }

 private:
  const std::string& file_;
  const toml::table& table_;
  std::string name_;
  std::vector<std::string_view> keys_;
};

const std::vector<std::string_view> kSections = {"device", "gpio", "bias", "filter", "allan",
                                                 "socket", "record", "log", "mock"};
const std::vector<std::string_view> kBackendNames = {"i2c", "mock"};
const std::vector<std::string_view> kBiasSourceNames = {"estimate", "model", "config"};
const std::vector<std::string_view> kMockSourceNames = {"simulator", "replay"};
const std::vector<std::string_view> kLogLevelNames = {"trace", "debug", "info", "warn", "error", "critical", "off"};
constexpr std::array<spdlog::level::level_enum, 7> kLogLevels = {
    spdlog::level::trace, spdlog::level::debug, spdlog::level::info, spdlog::level::warn,
    spdlog::level::err,   spdlog::level::critical, spdlog::level::off};

bool isAllDigits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

void readDevice(const Section& s, DeviceConfig& d) {
  if (auto b = s.choice("backend", kBackendNames)) d.backend = *b == 0 ? DeviceBackend::I2c : DeviceBackend::Mock;
  if (const auto* n = s.node("bus")) {
    std::string text;
    if (auto i = n->as_integer()) text = std::to_string(i->get());
    else if (auto str = n->as_string()) text = str->get();
    else s.failType(*n, "bus", "must be a bus number (1 → /dev/i2c-1) or a device path");
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
    if (*v != 250 && *v != 500 && *v != 1000 && *v != 2000) s.failValue("full_scale_dps", "must be 250, 500, 1000 or 2000");
    d.full_scale_dps = static_cast<int>(*v);
  }
  if (auto v = s.number("rate_hz")) d.rate_hz = *v;
  // Checked even when rate_hz keeps its default, since dlpf changes the internal rate.
  // The chip's rule (driver/mpu6050_config.hpp): gyro output rate / (1 + SMPLRT_DIV).
  const double internal = driver::mpu6050::gyroOutputRateHz(d.dlpf);
  if (!driver::smplrtDivFor(d.dlpf, d.rate_hz)) {
    std::ostringstream req;
    req << "must be " << shortest(internal) << " Hz / N for a whole N in 1..256 (the chip's rate with dlpf "
        << d.dlpf << ")";
    if (s.has("rate_hz")) s.failValue("rate_hz", req.str());
    const char* which = s.has("dlpf") ? "dlpf" : "rate_hz";
    s.fail(*s.node(which), "rate_hz", req.str(), shortest(d.rate_hz) + ", the default");
  }
}

void readGpio(const Section& s, GpioConfig& g) {
  if (auto c = s.string("chip")) {
    if (c->find_first_of(" \t\n") != std::string::npos) s.failValue("chip", "must be a chip name or path without spaces");
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
    if (!a || a->size() != 3 ||
        !std::all_of(a->begin(), a->end(), [](const toml::node& e) { return e.is_number(); }))
      s.fail(*n, "values", "must be an array of 3 numbers [x, y, z] in °/s",
             a ? "an array of " + std::to_string(a->size()) + " elements" : typeAndValue(*n));
    b.values.clear();
    for (const auto& e : *a) b.values.push_back(s.numberFrom(e, "values"));
  }
}

void readFilter(const Section& s, FilterConfig& f) {
  if (auto v = s.integer("mean_window")) {
    if (*v < 1 || *v > 100000) s.failValue("mean_window", "must be a window length 1..100000 samples");
    f.mean_window = static_cast<std::size_t>(*v);
  }
  if (auto v = s.number("mean_threshold_dps")) {
    if (!(*v > 0.0)) s.failValue("mean_threshold_dps", "must be > 0 °/s");
    f.mean_threshold_dps = *v;
  }
  if (auto v = s.string("model")) f.model = *v;
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
    if (!(*v * rate_hz >= 4.0)) s.failValue("window_s", "must hold at least 4 samples (≥ " + shortest(4.0 * tau0) + " s at device.rate_hz)");
    a.window_s = *v;
  }
  if (auto v = s.number("refit_interval_s")) {
    if (!(*v > 0.0 && *v <= a.window_s)) s.failValue("refit_interval_s", "must be > 0 and ≤ allan.window_s (" + shortest(a.window_s) + " s)");
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
          s.fail(e, "taus", "each τ must be a whole number of sample periods (τ0 = " + shortest(tau0) + " s)", shortest(tau));
        if (tau > tau_max)
          s.fail(e, "taus", "each τ must be ≤ allan.window_s / 2 (" + shortest(tau_max) + " s)", shortest(tau));
        if (!a.taus_s.empty() && !(tau > a.taus_s.back()))
          s.fail(e, "taus", "τ values must be strictly increasing", shortest(tau) + " after " + shortest(a.taus_s.back()));
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

void readRecord(const Section& s, RecordConfig& r) {
  if (auto v = s.string("path")) {
    if (!v->empty() && (v->back() == '/' || std::filesystem::path(*v).filename() == "."))
      s.failValue("path", "must name a file (e.g. /var/lib/gyrod/gyro.csv), not a directory");
    r.path = *v;
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

void readLog(const Section& s, LogConfig& l) {
  if (auto v = s.choice("level", kLogLevelNames)) l.level = kLogLevels[*v];
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
    if (!(*v > 0.0 && *v <= 1000.0)) s.failValue("speed", "must be > 0 and ≤ 1000 (1 = real time)");
    m.speed = *v;
  }
  if (!s.has("faults")) return;
  if (!s.node("faults")->is_table()) s.failType(*s.node("faults"), "faults", "must be a table");
  const Section f(s.file(), *s.node("faults")->as_table(), s.qualified("faults"),
                  {"transfer_error_fraction", "error_burst", "vanish", "silent_reset_at_s", "fifo_overflow_at_s",
                   "who_am_i", "stuck_data_ready_at_s", "stuck_data_ready_duration_s"});
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

std::string i2cDevicePath(std::string_view bus) {
  if (isAllDigits(bus) && bus.size() <= 6) return "/dev/i2c-" + std::to_string(std::stoul(std::string(bus)));
  if (!bus.empty() && bus.front() == '/') return std::string(bus);
  throw ConfigError("I2C bus '" + std::string(bus) + "': must be a bus number ≥ 0 (1 → /dev/i2c-1) or a path starting with '/'");
}

GyrodConfig parseConfig(std::string_view toml_text, const std::string& source_name) {
  toml::table root;
  try {
    root = toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& e) {
    const auto& where = e.source().begin;
    throw ConfigError(source_name + ":" + std::to_string(where.line) + ":" + std::to_string(where.column) + ": " +
                      std::string(e.description()));
  }

  GyrodConfig config;
  // Unknown top-level names first, so that a misspelt section is reported as such.
  for (auto&& [key, node] : root) {
    const auto name = key.str();
    const auto where = key.source().begin.line > 0 ? source_name + ":" + std::to_string(key.source().begin.line) + ": "
                                                   : source_name + ": ";
    if (std::find(kSections.begin(), kSections.end(), name) == kSections.end()) {
      if (node.is_table())
        throw ConfigError(where + "unknown section [" + std::string(name) + "] (valid sections: " + joined(kSections) +
                          ")" + suggestion(name, kSections));
      throw ConfigError(where + "unknown key '" + std::string(name) + "' at top level (keys belong in a section: " +
                        joined(kSections) + ")");
    }
    if (!node.is_table())
      throw ConfigError(where + "key '" + std::string(name) + "': must be a section [" + std::string(name) + "] (got " +
                        typeAndValue(node) + ")");
  }
  const toml::table empty;
  const auto section = [&](std::string_view name, std::vector<std::string_view> keys) {
    const auto* t = root.get_as<toml::table>(name);
    return Section(source_name, t ? *t : empty, std::string(name), std::move(keys));
  };

  // device first: allan checks τ against device.rate_hz.
  readDevice(section("device", {"backend", "bus", "address", "rate_hz", "dlpf", "full_scale_dps"}), config.device);
  readGpio(section("gpio", {"chip", "line"}), config.gpio);
  const auto bias = section("bias", {"source", "still_seconds", "values"});
  readBias(bias, config.bias);
  readFilter(section("filter", {"mean_window", "mean_threshold_dps", "model", "kalman"}), config.filter);
  if (config.bias.source == BiasSource::Model && config.filter.model.empty())
    bias.failValue("source", "\"model\" needs filter.model (a model file from `gyroctl analyze --write-model`)");
  readAllan(section("allan", {"window_s", "refit_interval_s", "taus"}), config.allan, config.device.rate_hz);
  readSocket(section("socket", {"path", "mode", "group", "client_buffer_kib"}), config.socket);
  readRecord(section("record", {"path", "rotate_mb", "rotate_minutes", "flush_interval_s", "fsync_each_flush", "keep"}),
             config.record);
  readLog(section("log", {"level"}), config.log);
  readMock(section("mock", {"source", "replay_file", "seed", "speed", "faults"}), config.mock);
  return config;
}

GyrodConfig loadConfigFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ": cannot open: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw ConfigError(path + ": read error: " + std::strerror(errno));
  return parseConfig(text.str(), path);
}

void applyOverrides(GyrodConfig& config, const CommandLineOverrides& o) {
  if (o.backend) config.device.backend = *o.backend;
  if (o.socket_path) {
    if (o.socket_path->empty() || o.socket_path->size() > 107)
      throw ConfigError("--socket: must be a path of 1..107 bytes (got \"" + *o.socket_path + "\")");
    config.socket.path = *o.socket_path;
  }
  if (o.record_path) {
    if (!o.record_path->empty() && o.record_path->back() == '/')
      throw ConfigError("--record: must name a file, not a directory (got \"" + *o.record_path + "\")");
    config.record.path = *o.record_path;
  }
  if (o.mock_speed) {
    if (!(*o.mock_speed > 0.0 && *o.mock_speed <= 1000.0))
      throw ConfigError("--mock-speed: must be > 0 and ≤ 1000 (got " + shortest(*o.mock_speed) + ")");
    config.mock.speed = *o.mock_speed;
  }
  if (o.log_level) config.log.level = *o.log_level;
}

GyrodCommandLine parseGyrodCommandLine(int argc, const char* const* argv, const std::string& default_config_path) {
  CLI::App app{"gyrod: MPU-6050 gyroscope daemon (mean filter + Kalman, rolling Allan statistics)", "gyrod"};
  std::string config_file, backend, socket_path, record_path, log_level;
  double mock_speed = 0.0;
  app.add_option("--config", config_file, "Configuration file (default: " + default_config_path + " if it exists)");
  const auto strings = [](const std::vector<std::string_view>& v) { return std::vector<std::string>(v.begin(), v.end()); };
  app.add_option("--backend", backend, "Device backend")->check(CLI::IsMember(strings(kBackendNames)));
  app.add_option("--socket", socket_path, "Unix socket path (socket.path)");
  app.add_option("--record", record_path, "Record raw samples to this file (record.path); \"\" = off");
  app.add_option("--mock-speed", mock_speed, "Mock device speed, 1 = real time (mock.speed)");
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
