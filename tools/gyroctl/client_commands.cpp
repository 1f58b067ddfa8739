// gyroctl watch / allan / status / effects: the client side of the gyrod socket (docs/protocol.md).
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "formats/recording_format.hpp"
#include "processing/allan/allan.hpp"
#include "processing/base/noise_terms.hpp"
#include "protocol/protocol.hpp"
#include "protocol/socket_path.hpp"
#include "tools/gyroctl/commands.hpp"
#include "tools/gyroctl/daemon_client.hpp"

namespace gyrod::gyroctl {
namespace {

using namespace std::chrono_literals;

// allan and status are answered at once by a healthy daemon; a stuck one is reported.
constexpr auto kReplyTimeout = 10s;

struct CommonOptions {
  std::string socket = protocol::kDefaultSocketPath;
  bool json = false;
};

void addCommonOptions(CLI::App* sub, CommonOptions& opt) {
  sub->add_option("--socket", opt.socket, "gyrod's socket")
      ->envname("GYROD_SOCKET")
      ->default_val(protocol::kDefaultSocketPath);
}

// ---- watch ---------------------------------------------------------------------------------

struct WatchOptions {
  CommonOptions common;
  std::uint32_t decimate = 1;
  std::optional<std::uint64_t> count;
};

// What `t` is, on its own line under the column header: the clock, and the UTC time (RATE
// "time") of the sample the header is printed for, so the two can be lined up.
std::string timeLegend(const protocol::RateSample& r) {
  std::string legend = "t: CLOCK_MONOTONIC s of the data-ready edge; time: UTC";
  if (!std::isfinite(r.time_s) || !std::isfinite(r.t_s)) return legend + " (not sent by this gyrod)";
  const auto us = static_cast<std::int64_t>(std::llround(r.time_s * 1e6));
  const auto seconds = us / 1'000'000 - (us % 1'000'000 < 0 ? 1 : 0);
  const std::tm tm = recording::utcCalendarTime(seconds);
  char stamp[64];
  const auto n = std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", &tm);
  std::snprintf(stamp + n, sizeof stamp - n, ".%06lldZ", static_cast<long long>(us - seconds * 1'000'000));
  char at[32];
  std::snprintf(at, sizeof at, "%.3f", r.t_s);
  return legend + ", t " + at + " = " + stamp;
}

// Two layouts. Once a RATE line carries `rate` the stream to read comes first, then raw and
// the paper's kalman, then the still detector, with a new header where the switch happens;
// until then (an older gyrod, or gyrod still estimating its start-up bias) raw and kalman.
// Lines that carry the orientation add roll, pitch and heading [deg] at the end.
struct WatchLayout {
  bool rate = false;
  bool attitude = false;
  bool operator==(const WatchLayout&) const = default;
};

void printRateHeader(WatchLayout layout, const protocol::RateSample& first) {
  if (layout.rate) {
    std::printf("%10s %12s  %10s %10s %10s  %10s %10s %10s  %10s %10s %10s %6s  [deg/s]", "seq", "t [s]", "rate x",
                "rate y", "rate z", "raw x", "raw y", "raw z", "kalman x", "kalman y", "kalman z", "still");
    if (layout.attitude) std::printf("  %9s %9s %9s  [deg]", "roll", "pitch", "heading");
    std::printf("\n");
  } else {
    std::printf("%10s %12s  %10s %10s %10s  %10s %10s %10s  [deg/s]\n", "seq", "t [s]", "raw x", "raw y", "raw z",
                "kalman x", "kalman y", "kalman z");
  }
  std::printf("%s\n", timeLegend(first).c_str());
}

// A value the line left out comes back from the parser as NaN and shows as "-".
void printAxisTriple(const std::array<double, 3>& v) {
  for (const double x : v) {
    if (std::isfinite(x))
      std::printf(" %10.5f", x);
    else
      std::printf(" %10s", "-");
  }
}

void printRate(const protocol::RateSample& r, WatchLayout layout) {
  const bool with_rate = layout.rate;
  std::printf("%10llu ", static_cast<unsigned long long>(r.seq));
  if (std::isfinite(r.t_s))
    std::printf("%12.3f ", r.t_s);
  else
    std::printf("%12s ", "-");
  if (with_rate) {
    printAxisTriple(r.rate_dps);
    std::printf(" ");
  }
  printAxisTriple(r.raw_dps);
  std::printf(" ");
  printAxisTriple(r.kalman_dps);
  if (with_rate) std::printf(" %6s", r.still ? (*r.still ? "yes" : "no") : "-");
  if (with_rate && layout.attitude) {
    std::printf("         ");
    for (const double x : r.roll_pitch_heading_deg) {
      if (std::isfinite(x))
        std::printf(" %9.3f", x);
      else
        std::printf(" %9s", "-");
    }
  }
  std::printf("\n");
}

void printGap(const protocol::GapNotice& g) {
  std::printf("--- gap: %llu sample(s) missing from seq %llu (%s)\n", static_cast<unsigned long long>(g.count),
              static_cast<unsigned long long>(g.first_missing_seq), g.reason.c_str());
}

// The live check's EFFECT object as a person reads it: "line on y at 12.5 Hz, onset 3600 s".
std::string effectSummary(const nlohmann::json& e) {
  const auto number = [](const nlohmann::json& v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v.is_number() ? v.get<double>() : std::nan(""));
    return std::string(buf);
  };
  std::string s = e.value("effect", std::string("?")) + " on " + e.value("axis", std::string("?"));
  const nlohmann::json params = e.value("params", nlohmann::json::object());
  if (params.contains("centre_hz")) s += " at " + number(params["centre_hz"]) + " Hz";
  if (params.contains("count")) s += ", " + number(params["count"]) + " outliers";
  if (e.contains("onset_t")) s += ", onset t " + number(e["onset_t"]) + " s";
  return s;
}

// An EFFECT line in the text layout: "--- effect new: line on y at 12.5 Hz, onset t 3600 s: ...".
void printEffect(const std::string& line) {
  const nlohmann::json e = nlohmann::json::parse(line, nullptr, false);
  if (!e.is_object()) return;
  std::printf("--- effect %s: %s: %s\n", e.value("state", std::string("?")).c_str(), effectSummary(e).c_str(),
              e.value("evidence", std::string()).c_str());
}

int runWatch(const WatchOptions& opt) {
  if (opt.count && *opt.count == 0) throw std::invalid_argument("--count must be >= 1");
  DaemonConnection conn = DaemonConnection::open(opt.common.socket, kReplyTimeout);
  if (opt.common.json) std::printf("%s\n", conn.versionLine().c_str());
  conn.sendLine(protocol::requestLine(protocol::WatchRequest{true, opt.decimate}));
  std::uint64_t rates = 0;
  std::optional<WatchLayout> layout;  // none before the first RATE line
  while (!opt.count || rates < *opt.count) {
    const std::string line = conn.readLine(std::nullopt);
    const protocol::ServerMessage message = parseServerLine(line);
    throwIfError(message);
    const auto* rate = std::get_if<protocol::RateSample>(&message);
    if (rate) ++rates;
    if (opt.common.json) {
      std::printf("%s\n", line.c_str());
    } else if (rate) {
      const bool carries_rate = std::isfinite(rate->rate_dps[0]) || rate->still.has_value();
      const bool carries_attitude = carries_rate && std::isfinite(rate->roll_pitch_heading_deg[0]);
      // A layout grows (rate, then the orientation) and does not shrink back.
      const WatchLayout seen{carries_rate || (layout && layout->rate),
                             carries_attitude || (layout && layout->attitude)};
      if (!layout || !(seen == *layout)) {
        layout = seen;
        printRateHeader(*layout, *rate);
      }
      printRate(*rate, *layout);
    } else if (const auto* gap = std::get_if<protocol::GapNotice>(&message)) {
      printGap(*gap);
    } else if (const auto* other = std::get_if<protocol::OtherClass>(&message); other && other->name == "EFFECT") {
      printEffect(line);
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
  std::size_t axis = 0, stream = 0;
  std::vector<double> adev;
  std::vector<processing::AllanPoint> points;  // with intervals where gyrod identified the noise type
  std::optional<processing::NoiseTerms> noise;
};

// The computed curves in axis-then-stream order (the parser has checked their lengths).
std::vector<Curve> curvesOf(const protocol::AllanReport& report) {
  std::vector<Curve> curves;
  for (std::size_t a = 0; a < protocol::kAxisNames.size(); ++a)
    for (std::size_t s = 0; s < protocol::kStreamNames.size(); ++s) {
      const auto& c = report.curves[a][s];
      if (c.adev_dps.empty()) continue;
      curves.push_back({std::string(protocol::kAxisNames[a]) + " " + std::string(protocol::kStreamNames[s]), a, s,
                        c.adev_dps, c.points, c.noise});
    }
  return curves;
}

// Every term of a fitted curve: its value with its 1 σ, or "not enough data" — never a bare
// number (a gyrod older than protocol 1.3 sends no uncertainties, and says so).
void printNoiseTerms(const protocol::AllanReport& report) {
  bool any = false;
  for (const auto& axis : report.curves)
    for (const auto& curve : axis) any = any || curve.noise.has_value();
  if (!any) return;
  std::printf("\nnoise terms (IEEE Std 952, +- 1 sigma)\n");
  for (std::size_t a = 0; a < protocol::kAxisNames.size(); ++a)
    for (std::size_t s = 0; s < protocol::kStreamNames.size(); ++s) {
      const auto& c = report.curves[a][s];
      if (!c.noise) continue;
      std::printf("  %s %s:\n", std::string(protocol::kAxisNames[a]).c_str(),
                  std::string(protocol::kStreamNames[s]).c_str());
      for (const auto t : processing::kAllNoiseTerms) {
        const double v = c.noise->get(t);
        const double u = c.noise_uncertainty ? c.noise_uncertainty->get(t) : std::nan("");
        const std::string label(processing::noiseTermLabel(t));
        if (!std::isfinite(v))
          std::printf("    %-36s not enough data\n", label.c_str());
        else if (std::isfinite(u))
          std::printf("    %-36s = %.4g +- %.2g\n", label.c_str(), v, u);
        else
          std::printf("    %-36s = %.4g (no uncertainty: gyrod sent none)\n", label.c_str(), v);
      }
    }
}

// Per curve: the deviation with its confidence interval at each τ, or why there is none yet.
void printIntervals(const protocol::AllanReport& report, const std::vector<Curve>& curves) {
  bool any = false;
  for (const auto& c : curves) any = any || !c.points.empty();
  if (!any) return;
  std::printf("\n");
  if (std::isfinite(report.confidence))
    std::printf("%.1f %% chi2 confidence intervals (edf for the noise type gyrod identified at its last refit)\n",
                100.0 * report.confidence);
  for (const auto& c : curves) {
    if (c.points.empty()) continue;
    std::printf("  %s\n  %11s %11s %11s %11s %10s %8s %5s\n", c.label.c_str(), "tau [s]", "oadev", "oadev_lo",
                "oadev_hi", "terms", "edf", "alpha");
    for (const auto& p : c.points) {
      if (std::isfinite(p.oadev_lo) && std::isfinite(p.oadev_hi))
        std::printf("  %11.6g %11.4e %11.4e %11.4e %10zu %8.3g %5d\n", p.tau_s, p.oadev, p.oadev_lo, p.oadev_hi,
                    p.oadev_terms, p.edf, p.noise_alpha);
      else
        std::printf("  %11.6g %11.4e %23s %10zu  (no interval until the next refit)\n", p.tau_s, p.oadev,
                    "not enough data", p.oadev_terms);
    }
  }
}

void printAllanTable(const protocol::AllanReport& report, const std::vector<Curve>& curves) {
  const std::vector<double>& tau = report.tau_s;
  // How much data: the samples and the time they cover, then what the window could hold.
  std::printf("Allan deviation [deg/s] of %llu samples", static_cast<unsigned long long>(report.samples));
  if (std::isfinite(report.span_s)) std::printf(" covering %.6g s", report.span_s);
  std::printf(" (");
  if (std::isfinite(report.window_s)) std::printf("window up to %.6g s, ", report.window_s);
  if (std::isfinite(report.tau0_s)) std::printf("tau0 %.6g s", report.tau0_s);
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
  printIntervals(report, curves);
  printNoiseTerms(report);
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
  if (ext == ".png") return "pngcairo size 1200,800 enhanced";
  if (ext == ".svg") return "svg size 1200,800 enhanced";
  if (ext == ".pdf") return "pdfcairo size 7in,5in enhanced";
  throw std::invalid_argument("--plot: '" + file + "' must end in .png, .svg or .pdf");
}

// A gnuplot single-quoted string: a quote inside is written twice.
std::string gnuplotQuoted(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

// Colours that read on white (Okabe & Ito's palette without its yellow), one per axis; the
// streams differ by point and dash type.
constexpr std::array<const char*, 3> kAxisColours = {"#0072B2", "#D55E00", "#009E73"};
constexpr std::array<int, 3> kStreamPointTypes = {7, 5, 9};  // filled circle, square, triangle
// One dash pattern per IEEE 952 term (Q, N, B, K, R); the measured curves are solid.
constexpr std::array<const char*, 5> kTermDashes = {"(3,4)", "(14,6)", "(14,5,3,5)", "(22,6,3,6,3,6)", "(6,6)"};

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// One inline data block per curve: τ, σ, and the interval (σ itself where there is none, so
// the bar has no length).
std::string curveBlock(std::size_t k, const Curve& c, const std::vector<double>& tau) {
  std::string block = "$c" + std::to_string(k) + " << EOD\n";
  if (c.points.empty()) {
    for (std::size_t i = 0; i < tau.size(); ++i)
      block += number(tau[i]) + " " + number(c.adev[i]) + " " + number(c.adev[i]) + " " + number(c.adev[i]) + "\n";
  }
  for (const auto& p : c.points) {
    const bool bar = std::isfinite(p.oadev_lo) && std::isfinite(p.oadev_hi);
    block += number(p.tau_s) + " " + number(p.oadev) + " " + number(bar ? p.oadev_lo : p.oadev) + " " +
             number(bar ? p.oadev_hi : p.oadev) + "\n";
  }
  return block + "EOD\n";
}

// The fitted terms of a curve as gnuplot functions of τ, each its own IEEE 952 line
// σ(τ) = √(c·τ^p), dashed in the curve's colour; none for a term fitted to 0 or not estimated.
std::string termLines(const Curve& c, const std::vector<double>& tau) {
  if (!c.noise) return {};
  std::string plot;
  for (const auto t : processing::kAllNoiseTerms) {
    const double v = c.noise->get(t);
    if (!(std::isfinite(v) && v > 0.0)) continue;
    const double coefficient = processing::allanVarianceCoefficient(t, v);
    const std::string power = std::to_string(processing::noiseTermVariancePower(t));
    const std::string range = "[" + number(tau.front()) + ":" + number(tau.back()) + "]";
    std::string name(processing::noiseTermLabel(t));
    name = name.substr(0, name.find(" ["));
    plot += ", " + range + " sqrt(" + number(coefficient) + "*x**(" + power + ")) with lines dashtype " +
            kTermDashes[static_cast<std::size_t>(t)] + " linewidth 1.5 linecolor rgb '" + kAxisColours[c.axis] +
            "' title " + gnuplotQuoted(c.label + " fit: " + name);
  }
  return plot;
}

std::string allanPlotScript(const std::string& file, const std::vector<double>& tau, const std::vector<Curve>& curves) {
  std::string script =
      "set terminal " + gnuplotTerminal(file) + " background rgb 'white'\nset output " + gnuplotQuoted(file) + "\n";
  script +=
      "set logscale xy\nset grid xtics ytics mxtics mytics linecolor rgb '#c0c0c0'\nset format x '10^{%L}'\n"
      "set format y '10^{%L}'\nset xlabel 'averaging time {/Symbol t} [s]'\nset ylabel 'Allan deviation [deg/s]'\n"
      "set title \"gyrod: overlapping Allan deviation of the rolling window\\nbars: confidence interval of each "
      "point; dashed: the fitted IEEE 952 noise terms\"\nset key outside right top font ',9'\nset samples 200\n";
  for (std::size_t k = 0; k < curves.size(); ++k) script += curveBlock(k, curves[k], tau);
  script += "plot ";
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const Curve& c = curves[k];
    const std::size_t stream = c.stream;
    const std::string colour = std::string("linecolor rgb '") + kAxisColours[c.axis] + "'";
    const std::string data = "$c" + std::to_string(k);
    script += (k ? ", " : "") + data + " using 1:2:3:4 with yerrorbars pointtype " +
              std::to_string(kStreamPointTypes[stream]) + " pointsize 0.8 " + colour + " title " +
              gnuplotQuoted(c.label) + ", " + data + " using 1:2 with lines linewidth 1.2 " + colour + " notitle";
    script += termLines(c, tau);
  }
  return script + "\n";
}

void plotAllan(const std::string& file, const std::vector<double>& tau, const std::vector<Curve>& curves) {
  const auto gnuplot = findOnPath("gnuplot");
  if (!gnuplot)
    throw std::runtime_error(
        "--plot: gnuplot is not installed (apt-get install gnuplot-nox); the table above was printed, no plot was drawn");
  if (tau.empty()) throw std::runtime_error("--plot: no Allan deviation to plot yet");
  const std::string script = allanPlotScript(file, tau, curves);
  const std::string command = "'" + *gnuplot + "'";
  FILE* pipe = ::popen(command.c_str(), "w");
  if (pipe == nullptr) throw std::runtime_error("--plot: cannot start gnuplot");
  std::fwrite(script.data(), 1, script.size(), pipe);
  const int status = ::pclose(pipe);
  if (status != 0)
    throw std::runtime_error("--plot: gnuplot failed (status " + std::to_string(status) + ") writing " + file);
  std::fprintf(stderr, "wrote the Allan plot to %s\n", file.c_str());
}

int runAllan(const AllanOptions& opt) {
  if (!opt.plot.empty()) gnuplotTerminal(opt.plot);  // a bad extension is reported before connecting
  DaemonConnection conn = DaemonConnection::open(opt.common.socket, kReplyTimeout);
  conn.sendLine(protocol::requestLine(protocol::AllanRequest{}));
  std::string raw;
  const auto report = conn.readReply<protocol::AllanReport>(kReplyTimeout, &raw);
  const std::vector<Curve> curves = curvesOf(report);
  if (opt.common.json)
    std::printf("%s\n", raw.c_str());
  else
    printAllanTable(report, curves);
  std::fflush(stdout);
  if (!opt.plot.empty()) plotAllan(opt.plot, report.tau_s, curves);
  return kExitOk;
}

// ---- status --------------------------------------------------------------------------------

std::string realText(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

void printField(const std::string& key, const std::string& value, const std::string& unit = "") {
  std::printf("%-16s %s%s%s\n", (key + ":").c_str(), value.c_str(), unit.empty() ? "" : " ", unit.c_str());
}

void printField(const std::string& key, const std::optional<double>& value, const std::string& unit) {
  if (value && std::isfinite(*value)) printField(key, realText(*value), unit);
}

void printField(const std::string& key, const std::optional<std::string>& value) {
  if (value) printField(key, *value);
}

// The fields this gyroctl knows, in a fixed order with units; then whatever a newer gyrod
// added; then the driver's counters and the clients.
void printStatus(const protocol::StatusReply& status) {
  const protocol::StatusReport& d = status.daemon;
  const protocol::ServerStatus& s = status.server;
  const auto count = [](std::uint64_t v) { return std::to_string(v); };
  printField("device_state", d.device_state);
  if (!d.device_reason.empty()) printField("device_reason", d.device_reason);
  if (d.device_retrying) printField("device_retrying", std::string(*d.device_retrying ? "yes" : "no"));
  printField("device", d.device);
  printField("uptime", d.uptime_s, "s");
  printField("samples", count(d.samples));
  printField("rate", d.rate_hz, "Hz");
  printField("nominal_rate", d.nominal_rate_hz, "Hz");
  printField("temp", d.temp_c, "degC");
  printField("gaps", count(d.gaps));
  printField("missing", count(d.missing_samples), "samples");
  printField("bus_errors", count(d.bus_errors));
  printField("resets", count(d.resets));
  printField("bias_source", d.bias_source);
  printField("still_check", d.still_check);
  printField("still_check_detail", d.still_check_detail);
  printField("rate_model", d.rate_model);
  printField("recording", d.recording);
  if (const auto& r = d.recorder)
    printField("recorder", count(r->written) + " written, " + count(r->dropped) + " dropped (ring full), " +
                               count(r->lost) + " lost to write errors (" + count(r->errors) + " failed calls)" +
                               (r->last_error.empty() ? "" : "; last: " + r->last_error));
  if (const auto& m = d.mqtt)
    printField("mqtt", std::string(m->connected ? "connected" : "not connected") + ", " + count(m->buffered) +
                           " kept for the broker, " + count(m->dropped) + " dropped" +
                           (m->last_error.empty() ? "" : "; last error: " + m->last_error));
  if (const auto& c = d.calibration_state)
    printField("calibration_state", c->file + (c->restored ? " (the rate stream started from it)" : "") + ", " +
                                        count(c->writes) + " writes" +
                                        (c->last_error.empty() ? "" : "; last error: " + c->last_error));
  if (const auto& l = d.live_check) {
    std::string now;
    for (const std::string& e : l->current)
      now += (now.empty() ? "" : "; ") + effectSummary(nlohmann::json::parse(e, nullptr, false));
    printField("live_check", count(l->intervals) + " intervals, baseline " + (l->baseline_ready ? "ready" : "not yet") +
                                 ", " + count(l->named) + " named, " + count(l->skipped) +
                                 " skipped; now: " + (now.empty() ? "nothing" : now));
  }
  printField("clients", count(s.clients));
  printField("clients_total", count(s.clients_total));
  printField("clients_dropped", count(s.clients_dropped));
  printField("lines_dropped", count(s.lines_dropped));
  printField("client_buffer", count(s.client_buffer_bytes), "bytes");
  for (const protocol::OtherField& f : status.other_fields)
    printField(f.key, f.text ? *f.text : f.real ? realText(*f.real) : f.json);
  if (!d.device_counters.empty()) {
    std::printf("driver counters:\n");
    for (const protocol::NamedCount& c : d.device_counters)
      std::printf("  %-22s %llu\n", (c.name + ":").c_str(), static_cast<unsigned long long>(c.value));
  }
  if (s.client_list.empty()) return;
  std::printf("%6s %8s %6s %8s %12s %12s %10s\n", "client", "pid", "watch", "decimate", "lines sent", "lines queued",
              "buffered");
  for (const protocol::ClientStatus& c : s.client_list) {
    std::printf("%6llu %8s %6s %8u %12llu %12llu %10llu%s\n", static_cast<unsigned long long>(c.id),
                c.pid ? std::to_string(*c.pid).c_str() : "-", c.watch ? "yes" : "no", c.decimate,
                static_cast<unsigned long long>(c.lines_sent), static_cast<unsigned long long>(c.lines_queued),
                static_cast<unsigned long long>(c.buffered_bytes), c.self ? "  (this gyroctl)" : "");
  }
}

int runStatus(const CommonOptions& opt) {
  DaemonConnection conn = DaemonConnection::open(opt.socket, kReplyTimeout);
  conn.sendLine(protocol::requestLine(protocol::StatusRequest{}));
  std::string raw;
  const auto status = conn.readReply<protocol::StatusReply>(kReplyTimeout, &raw);
  if (opt.json) {
    std::printf("%s\n", raw.c_str());
    return kExitOk;
  }
  const protocol::VersionReply& version = conn.version();
  std::printf("gyrod %s (protocol %lld.%lld)\n", version.release.empty() ? "?" : version.release.c_str(),
              static_cast<long long>(version.proto_major.value_or(0)),
              static_cast<long long>(version.proto_minor.value_or(0)));
  printStatus(status);
  return kExitOk;
}

// ---- effects -------------------------------------------------------------------------------

std::string effectNumber(const nlohmann::ordered_json& v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v.is_number() ? v.get<double>() : std::nan(""));
  return buf;
}

// A value with its 95 % interval when the line gives one ([lo, hi]).
std::string withInterval(const nlohmann::ordered_json& value, const nlohmann::ordered_json* interval95) {
  std::string s = value.is_number() ? effectNumber(value) : value.dump();
  if (interval95 != nullptr && interval95->is_array() && interval95->size() == 2)
    s += " (" + effectNumber((*interval95)[0]) + ".." + effectNumber((*interval95)[1]) + ")";
  return s;
}

// Every parameter the line carries, whatever the effect: "name value (lo..hi)", a parameter's
// 95 % interval (its name + "_95") beside it rather than on its own.
std::string paramsText(const nlohmann::ordered_json& params) {
  std::string s;
  if (!params.is_object()) return s;
  for (auto it = params.begin(); it != params.end(); ++it) {
    if (it.key().ends_with("_95") && params.contains(it.key().substr(0, it.key().size() - 3))) continue;
    const auto interval = params.find(it.key() + "_95");
    s += (s.empty() ? "" : ", ") + it.key() + " " + withInterval(*it, interval == params.end() ? nullptr : &*interval);
  }
  return s;
}

std::string timeText(const nlohmann::ordered_json& t) {
  if (!t.is_number()) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", t.get<double>());
  return buf;
}

// One row per effect named now: what, where, when it began and when it was named (RATE's t),
// its parameters and the evidence, in columns as wide as their longest entry.
void printEffects(const protocol::EffectsReport& r) {
  if (!r.live_check) {
    const std::string why = r.reason.empty() ? "" : " (" + r.reason + ")";
    std::printf("live check: off%s\n", why.c_str());
    return;
  }
  std::printf("live check: on, %llu intervals examined, baseline %s\n", static_cast<unsigned long long>(r.intervals),
              r.baseline_ready ? "ready" : "not complete yet (nothing is compared with it before)");
  if (r.effects.empty()) {
    std::printf("no effect named now\n");
    return;
  }
  using Row = std::array<std::string, 6>;
  std::vector<Row> rows = {{"effect", "axis", "onset t [s] (95 %)", "t [s]", "parameters", "evidence"}};
  for (const std::string& line : r.effects) {
    const nlohmann::ordered_json e = nlohmann::ordered_json::parse(line, nullptr, false);
    if (!e.is_object()) continue;
    const auto interval = e.find("onset_t_95");
    rows.push_back({e.value("effect", std::string("?")), e.value("axis", std::string("?")),
                    e.contains("onset_t") ? withInterval(e["onset_t"], interval == e.end() ? nullptr : &*interval)
                                          : std::string("-"),
                    timeText(e.value("t", nlohmann::ordered_json())),
                    paramsText(e.value("params", nlohmann::ordered_json::object())),
                    e.value("evidence", std::string())});
  }
  std::array<int, 5> width{};
  for (const Row& row : rows)
    for (std::size_t c = 0; c < width.size(); ++c) width[c] = std::max(width[c], static_cast<int>(row[c].size()));
  for (const Row& row : rows)
    std::printf("%-*s  %-*s  %-*s  %-*s  %-*s  %s\n", width[0], row[0].c_str(), width[1], row[1].c_str(), width[2],
                row[2].c_str(), width[3], row[3].c_str(), width[4], row[4].c_str(), row[5].c_str());
  std::printf("t: when the live check named it, onset t: when it began; both on the clock of RATE's t\n");
}

int runEffects(const CommonOptions& opt) {
  DaemonConnection conn = DaemonConnection::open(opt.socket, kReplyTimeout);
  conn.sendLine(protocol::requestLine(protocol::EffectsRequest{}));
  std::string raw;
  const auto effects = conn.readReply<protocol::EffectsReport>(kReplyTimeout, &raw);
  if (opt.json)
    std::printf("%s\n", raw.c_str());
  else
    printEffects(effects);
  return kExitOk;
}

}  // namespace

void addClientCommands(CLI::App& app, CommandRunner& run) {
  {
    auto opt = std::make_shared<WatchOptions>();
    auto* sub = app.add_subcommand(
        "watch",
        "Show gyrod's live samples: seq, t (CLOCK_MONOTONIC s of the data-ready edge; the header maps it to UTC), "
        "then per axis rate (the stream to read while the board moves), raw and the paper's Kalman, and the still "
        "detector, and with a sensor model and the accelerometer roll, pitch and heading (RATE lines)");
    addCommonOptions(sub, opt->common);
    sub->add_flag("--json", opt->common.json, "print gyrod's lines unchanged (one JSON object per line)");
    sub->add_option("--decimate", opt->decimate, "receive every N-th sample")
        ->check(CLI::Range(std::uint32_t{1}, protocol::kMaxDecimate));
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
  {
    auto opt = std::make_shared<CommonOptions>();
    auto* sub = app.add_subcommand(
        "effects", "Show what gyrod's live check names now: each effect, its axis, onset, parameters and evidence");
    addCommonOptions(sub, *opt);
    sub->add_flag("--json", opt->json, "print gyrod's EFFECTS line unchanged");
    sub->callback([&run, opt] { run = [opt] { return runEffects(*opt); }; });
  }
}

}  // namespace gyrod::gyroctl
