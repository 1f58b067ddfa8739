// gyroctl watch / allan / status: the client side of the gyrod socket (docs/protocol.md).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/protocol.hpp"
#include "processing/noise_terms.hpp"
#include "tools/gyroctl/commands.hpp"
#include "tools/gyroctl/daemon_client.hpp"

namespace gyrod::gyroctl {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

constexpr const char* kDefaultSocket = "/run/gyrod/gyrod.sock";
// allan and status are answered at once by a healthy daemon; a stuck one is reported.
constexpr auto kReplyTimeout = 10s;

struct CommonOptions {
  std::string socket = kDefaultSocket;
  bool json = false;
};

void addCommonOptions(CLI::App* sub, CommonOptions& opt) {
  sub->add_option("--socket", opt.socket, "gyrod's socket")->envname("GYROD_SOCKET")->default_val(kDefaultSocket);
}

std::optional<double> numberAt(const json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number()) return std::nullopt;
  return it->get<double>();
}

// ---- watch ---------------------------------------------------------------------------------

struct WatchOptions {
  CommonOptions common;
  std::uint32_t decimate = 1;
  std::optional<std::uint64_t> count;
};

void printRateHeader() {
  std::printf("%10s %12s  %10s %10s %10s  %10s %10s %10s  [deg/s]\n", "seq", "t [s]", "raw x", "raw y", "raw z", "kalman x",
              "kalman y", "kalman z");
}

void printAxisTriple(const json& j, const char* key) {
  const auto it = j.find(key);
  for (std::size_t i = 0; i < 3; ++i) {
    if (it != j.end() && it->is_array() && it->size() == 3 && (*it)[i].is_number())
      std::printf(" %10.5f", (*it)[i].get<double>());
    else
      std::printf(" %10s", "-");
  }
}

void printRate(const json& j) {
  const auto t = numberAt(j, "t");
  std::printf("%10llu ", static_cast<unsigned long long>(j.value("seq", std::uint64_t{0})));
  if (t)
    std::printf("%12.3f ", *t);
  else
    std::printf("%12s ", "-");
  printAxisTriple(j, "raw");
  std::printf(" ");
  printAxisTriple(j, "kalman");
  std::printf("\n");
}

void printGap(const json& j) {
  std::printf("--- gap: %llu sample(s) missing from seq %llu (%s)\n", static_cast<unsigned long long>(j.value("count", std::uint64_t{0})),
              static_cast<unsigned long long>(j.value("seq", std::uint64_t{0})), j.value("reason", std::string("?")).c_str());
}

int runWatch(const WatchOptions& opt) {
  if (opt.count && *opt.count == 0) throw std::invalid_argument("--count must be >= 1");
  DaemonConnection conn = DaemonConnection::open(opt.common.socket, kReplyTimeout);
  if (opt.common.json) std::printf("%s\n", conn.versionLine().c_str());
  conn.sendLine(json({{"cmd", "watch"}, {"enable", true}, {"decimate", opt.decimate}}).dump());
  std::uint64_t rates = 0;
  bool header_printed = false;
  while (!opt.count || rates < *opt.count) {
    const std::string line = conn.readLine(std::nullopt);
    const json j = parseServerLine(line);
    const std::string& cls = j["class"].get_ref<const std::string&>();
    if (cls == "ERROR") throw DaemonConnectionError("gyrod: " + j.value("message", std::string("error")));
    if (cls == "RATE") ++rates;
    if (opt.common.json) {
      std::printf("%s\n", line.c_str());
    } else if (cls == "RATE") {
      if (!header_printed) printRateHeader();
      header_printed = true;
      printRate(j);
    } else if (cls == "GAP") {
      printGap(j);
    }
    std::fflush(stdout);
  }
  return kExitOk;
}

// ---- allan ---------------------------------------------------------------------------------

struct AllanOptions {
  CommonOptions common;
  std::string plot;
};

struct Curve {
  std::string label;  // "x raw"
  std::vector<double> adev;
};

std::vector<Curve> curvesOf(const json& j, std::size_t n_tau) {
  std::vector<Curve> curves;
  const json adev = j.value("adev", json::object());
  for (const auto axis : daemon::kAxisNames) {
    const auto a = adev.find(std::string(axis));
    if (a == adev.end() || !a->is_object()) continue;
    for (const auto stream : daemon::kStreamNames) {
      const auto s = a->find(std::string(stream));
      if (s == a->end()) continue;
      if (!s->is_array() || s->size() != n_tau)
        throw DaemonConnectionError("gyrod's ALLAN curve " + std::string(axis) + "/" + std::string(stream) + " does not match its tau list");
      Curve c{std::string(axis) + " " + std::string(stream), {}};
      for (const auto& v : *s) c.adev.push_back(v.get<double>());
      curves.push_back(std::move(c));
    }
  }
  return curves;
}

void printAllanTable(const json& j, const std::vector<double>& tau, const std::vector<Curve>& curves) {
  std::printf("Allan deviation [deg/s]");
  if (const auto w = numberAt(j, "window")) std::printf(", window %.6g s", *w);
  std::printf(" (%llu samples", static_cast<unsigned long long>(j.value("samples", std::uint64_t{0})));
  if (const auto t0 = numberAt(j, "tau0")) std::printf(", tau0 %.6g s", *t0);
  std::printf(")\n");
  if (tau.empty()) {
    std::printf("not enough samples in the window for an Allan deviation yet\n");
    return;
  }
  std::printf("%12s", "tau [s]");
  for (const auto& c : curves) std::printf(" %11s", c.label.c_str());
  std::printf("\n");
  for (std::size_t i = 0; i < tau.size(); ++i) {
    std::printf("%12.6g", tau[i]);
    for (const auto& c : curves) std::printf(" %11.4e", c.adev[i]);
    std::printf("\n");
  }
  const json noise = j.value("noise", json::object());
  if (noise.empty()) return;
  std::printf("\nnoise terms (IEEE Std 952)\n");
  for (const auto axis : daemon::kAxisNames) {
    const auto a = noise.find(std::string(axis));
    if (a == noise.end() || !a->is_object()) continue;
    for (const auto stream : daemon::kStreamNames) {
      const auto s = a->find(std::string(stream));
      if (s == a->end() || !s->is_object()) continue;
      std::printf("  %s %s:", std::string(axis).c_str(), std::string(stream).c_str());
      const char* sep = " ";
      for (const auto t : processing::kAllNoiseTerms) {
        const auto v = s->find(std::string(processing::noiseTermKey(t)));
        if (v == s->end() || !v->is_number()) continue;
        std::printf("%s%s = %.4g", sep, std::string(processing::noiseTermLabel(t)).c_str(), v->get<double>());
        sep = ", ";
      }
      std::printf("\n");
    }
  }
}

std::optional<std::string> findOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return std::nullopt;
  std::string dirs(path);
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string dir = end > start ? dirs.substr(start, end - start) : ".";
    const std::string candidate = dir + "/" + program;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    start = end + 1;
  }
  return std::nullopt;
}

// gnuplot terminal for the plot file's extension; std::invalid_argument for others.
std::string gnuplotTerminal(const std::string& file) {
  const std::string ext = std::filesystem::path(file).extension().string();
  if (ext == ".png") return "pngcairo size 1000,700 enhanced";
  if (ext == ".svg") return "svg size 1000,700 enhanced";
  if (ext == ".pdf") return "pdfcairo size 7in,5in enhanced";
  throw std::invalid_argument("--plot: '" + file + "' must end in .png, .svg or .pdf");
}

// A gnuplot single-quoted string: a quote inside is written twice.
std::string gnuplotQuoted(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

void plotAllan(const std::string& file, const std::vector<double>& tau, const std::vector<Curve>& curves) {
  const auto gnuplot = findOnPath("gnuplot");
  if (!gnuplot)
    throw std::runtime_error("--plot: gnuplot is not installed (apt-get install gnuplot-nox); the table above was printed, no plot was drawn");
  if (tau.empty()) throw std::runtime_error("--plot: no Allan deviation to plot yet");
  std::string script = "set terminal " + gnuplotTerminal(file) + "\nset output " + gnuplotQuoted(file) + "\n";
  script +=
      "set logscale xy\nset grid xtics ytics mxtics mytics\nset format x '10^{%L}'\nset format y '10^{%L}'\n"
      "set xlabel 'averaging time {/Symbol t} [s]'\nset ylabel 'Allan deviation [deg/s]'\n"
      "set title 'gyrod: Allan deviation of the rolling window'\nset key outside right\n$adev << EOD\n";
  char buf[64];
  for (std::size_t i = 0; i < tau.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%.17g", tau[i]);
    script += buf;
    for (const auto& c : curves) {
      std::snprintf(buf, sizeof buf, " %.17g", c.adev[i]);
      script += buf;
    }
    script += '\n';
  }
  script += "EOD\nplot ";
  for (std::size_t k = 0; k < curves.size(); ++k) {
    script += (k ? ", " : "") + std::string("$adev using 1:") + std::to_string(k + 2) + " with linespoints title " +
              gnuplotQuoted(curves[k].label);
  }
  script += "\n";
  const std::string command = "'" + *gnuplot + "'";
  FILE* pipe = ::popen(command.c_str(), "w");
  if (pipe == nullptr) throw std::runtime_error("--plot: cannot start gnuplot");
  std::fwrite(script.data(), 1, script.size(), pipe);
  const int status = ::pclose(pipe);
  if (status != 0) throw std::runtime_error("--plot: gnuplot failed (status " + std::to_string(status) + ") writing " + file);
  std::fprintf(stderr, "wrote the Allan plot to %s\n", file.c_str());
}

int runAllan(const AllanOptions& opt) {
  if (!opt.plot.empty()) gnuplotTerminal(opt.plot);  // a bad extension is reported before connecting
  DaemonConnection conn = DaemonConnection::open(opt.common.socket, kReplyTimeout);
  conn.sendLine(R"({"cmd":"allan"})");
  std::string raw;
  const json j = conn.readObjectOfClass("ALLAN", kReplyTimeout, &raw);
  std::vector<double> tau;
  for (const auto& v : j.value("tau", json::array())) tau.push_back(v.get<double>());
  const std::vector<Curve> curves = curvesOf(j, tau.size());
  if (opt.common.json)
    std::printf("%s\n", raw.c_str());
  else
    printAllanTable(j, tau, curves);
  std::fflush(stdout);
  if (!opt.plot.empty()) plotAllan(opt.plot, tau, curves);
  return kExitOk;
}

// ---- status --------------------------------------------------------------------------------

std::string scalarText(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v.get<double>());
    return buf;
  }
  return v.dump();
}

int runStatus(const CommonOptions& opt) {
  DaemonConnection conn = DaemonConnection::open(opt.socket, kReplyTimeout);
  conn.sendLine(R"({"cmd":"status"})");
  std::string raw;
  const json j = conn.readObjectOfClass("STATUS", kReplyTimeout, &raw);
  if (opt.json) {
    std::printf("%s\n", raw.c_str());
    return kExitOk;
  }
  std::printf("gyrod %s (protocol %d.%d)\n", conn.version().value("release", std::string("?")).c_str(),
              conn.version().value("proto_major", 0), conn.version().value("proto_minor", 0));
  // Known fields in a fixed order with units, then whatever a newer gyrod added.
  const std::vector<std::pair<std::string, std::string>> known = {
      {"device_state", ""}, {"device", ""},        {"uptime", "s"},        {"samples", ""},        {"rate", "Hz"},
      {"nominal_rate", "Hz"}, {"temp", "degC"},    {"gaps", ""},           {"missing", "samples"}, {"bus_errors", ""},
      {"resets", ""},       {"bias_source", ""},   {"recording", ""},      {"clients", ""},        {"clients_total", ""},
      {"clients_dropped", ""}, {"lines_dropped", ""}, {"client_buffer", "bytes"}};
  for (const auto& [key, unit] : known) {
    const auto it = j.find(key);
    if (it == j.end()) continue;
    std::printf("%-16s %s%s%s\n", (key + ":").c_str(), scalarText(*it).c_str(), unit.empty() ? "" : " ", unit.c_str());
  }
  for (auto it = j.begin(); it != j.end(); ++it) {
    const bool listed = it.key() == "class" || it.key() == "client_list" ||
                        std::any_of(known.begin(), known.end(), [&](const auto& k) { return k.first == it.key(); });
    if (!listed) std::printf("%-16s %s\n", (it.key() + ":").c_str(), scalarText(*it).c_str());
  }
  const json list = j.value("client_list", json::array());
  if (!list.empty()) {
    std::printf("%6s %8s %6s %8s %12s %12s %10s\n", "client", "pid", "watch", "decimate", "lines sent", "lines queued", "buffered");
    for (const auto& c : list) {
      std::printf("%6llu %8s %6s %8u %12llu %12llu %10llu%s\n", static_cast<unsigned long long>(c.value("id", 0ULL)),
                  c.contains("pid") ? std::to_string(c["pid"].get<long long>()).c_str() : "-", c.value("watch", false) ? "yes" : "no",
                  c.value("decimate", 1u), static_cast<unsigned long long>(c.value("lines_sent", 0ULL)),
                  static_cast<unsigned long long>(c.value("lines_queued", 0ULL)),
                  static_cast<unsigned long long>(c.value("buffered", 0ULL)), c.value("self", false) ? "  (this gyroctl)" : "");
    }
  }
  return kExitOk;
}

}  // namespace

void addClientCommands(CLI::App& app, CommandRunner& run) {
  {
    auto opt = std::make_shared<WatchOptions>();
    auto* sub = app.add_subcommand("watch", "Show gyrod's live samples: seq, t, raw and Kalman rate per axis (RATE lines)");
    addCommonOptions(sub, opt->common);
    sub->add_flag("--json", opt->common.json, "print gyrod's lines unchanged (one JSON object per line)");
    sub->add_option("--decimate", opt->decimate, "receive every N-th sample")
        ->check(CLI::Range(std::uint32_t{1}, daemon::kMaxDecimate));
    sub->add_option("--count", opt->count, "stop after N RATE lines");
    sub->callback([&run, opt] { run = [opt] { return runWatch(*opt); }; });
  }
  {
    auto opt = std::make_shared<AllanOptions>();
    auto* sub = app.add_subcommand("allan", "Show the Allan deviation of gyrod's rolling window per axis and stream");
    addCommonOptions(sub, opt->common);
    sub->add_flag("--json", opt->common.json, "print gyrod's ALLAN line unchanged");
    sub->add_option("--plot", opt->plot, "also draw the log-log curves with gnuplot into FILE (.png, .svg or .pdf)");
    sub->callback([&run, opt] { run = [opt] { return runAllan(*opt); }; });
  }
  {
    auto opt = std::make_shared<CommonOptions>();
    auto* sub = app.add_subcommand("status", "Show gyrod's state: device, rates, counters and clients");
    addCommonOptions(sub, *opt);
    sub->add_flag("--json", opt->json, "print gyrod's STATUS line unchanged");
    sub->callback([&run, opt] { run = [opt] { return runStatus(*opt); }; });
  }
}

}  // namespace gyrod::gyroctl
