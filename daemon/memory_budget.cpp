#include "daemon/memory_budget.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include <sys/resource.h>
#include <unistd.h>

#include "daemon/client_handover.hpp"
#include "daemon/recorder.hpp"
#include "formats/toml_document.hpp"
#include "processing/allan/rolling_allan.hpp"

namespace gyrod::daemon {
namespace {

using processing::RollingOverlappingAllan;

constexpr double kStreams = 9.0;  // raw, mean and Kalman of three axes

double allanClusterSizes(const AllanConfig& a, double window_samples) {
  if (!a.octave()) return static_cast<double>(a.taus_s.size());
  // m = 1, 2, 4, ... ≤ window / 2
  return window_samples >= 2.0 ? std::floor(std::log2(window_samples / 2.0)) + 1.0 : 1.0;
}

std::string count(double n) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", n);
  return buf;
}

bool stillPeriodNeeded(const GyrodConfig& c) {
  const auto& k = c.filter.kalman;
  return c.bias.source == BiasSource::Estimate || !(k.a && k.q && k.r);
}

// Stacks of the recorder's writer and the noise refit worker (glibc's default 8 MiB each).
constexpr double kThreadStacksBytes = 2.0 * 8.0 * 1024.0 * 1024.0;

double mappedBytesNow() {
  std::ifstream statm("/proc/self/statm");
  double pages = 0.0;
  if (!(statm >> pages)) return 0.0;
  return pages * static_cast<double>(::sysconf(_SC_PAGESIZE));
}

// "MemTotal:  8039552 kB" and "SwapTotal: ..." of /proc/meminfo, in bytes; 0 when unread.
double ramAndSwapBytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string name;
  double kb = 0.0, total = 0.0;
  std::string unit;
  while (meminfo >> name >> kb) {
    if (name == "MemTotal:" || name == "SwapTotal:") total += kb * 1024.0;
    std::getline(meminfo, unit);
  }
  return total;
}

}  // namespace

std::optional<MemoryBudgetProblem> memoryBudgetProblem(const MemoryNeed& need, double budget_bytes,
                                                       const std::string& budget_name, const std::string& raise) {
  if (!(need.total_bytes > budget_bytes)) return std::nullopt;
  std::map<std::string, double> by_key;
  for (const auto& item : need.items) by_key[item.key] += item.bytes;
  const auto top =
      std::max_element(by_key.begin(), by_key.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  std::ostringstream m;
  m << "gyrod would need " << megabytes(need.total_bytes) << " of memory, above " << budget_name << " (";
  bool first = true;
  for (const auto& item : need.items) {
    if (item.key != top->first) continue;
    m << (first ? "" : "; ") << item.what << " = " << megabytes(item.bytes);
    first = false;
  }
  m << "); lower " << top->first << " or raise " << raise;
  return MemoryBudgetProblem{top->first, m.str()};
}

std::optional<KernelMemoryLimit> kernelMemoryLimit() {
  std::optional<KernelMemoryLimit> limit;
  rlimit as{};
  if (::getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) {
    const double in_use = mappedBytesNow();
    limit = KernelMemoryLimit{static_cast<double>(as.rlim_cur) - in_use - kThreadStacksBytes,
                              "what RLIMIT_AS leaves (" + megabytes(static_cast<double>(as.rlim_cur)) + ", " +
                                  megabytes(in_use) + " mapped at start)",
                              "RLIMIT_AS (ulimit -v, systemd LimitAS=)"};
  }
  if (const double ram = ramAndSwapBytes(); ram > 0.0 && (!limit || ram < limit->bytes))
    limit = KernelMemoryLimit{ram, "this machine's RAM and swap (" + megabytes(ram) + ")", "the swap space"};
  return limit;
}

double recordedSamplesPerSecond(const GyrodConfig& c) {
  const double speed = c.device.backend == DeviceBackend::Mock ? std::max(1.0, c.mock.speed) : 1.0;
  return c.device.rate_hz * speed;
}

std::string megabytes(double bytes) {
  char buf[48];
  const double mb = bytes / 1e6;
  std::snprintf(buf, sizeof buf, mb >= 100.0 && mb < 1e9 ? "%.0f MB" : "%.3g MB", mb);
  return buf;
}

MemoryNeed memoryNeeded(const GyrodConfig& c) {
  MemoryNeed need;
  const double rate = c.device.rate_hz;
  const double window = std::round(c.allan.window_s * rate);
  const double per_stream =
      static_cast<double>(RollingOverlappingAllan::kBytesPerWindowSample) * (window + 1.0) +
      allanClusterSizes(c.allan, window) * static_cast<double>(RollingOverlappingAllan::kBytesPerClusterSize);
  need.items.push_back({"Allan statistics: " + count(kStreams) + " streams x " + count(window) + " samples x " +
                            std::to_string(RollingOverlappingAllan::kBytesPerWindowSample) + " B",
                        "allan.window_s", formats::shortest(c.allan.window_s), kStreams * per_stream});
  // The refit worker's copy of one raw stream, and the window's rates and averages it
  // rebuilds to identify the noise type (8 B each).
  need.items.push_back({"noise refit: a copy of one stream and 16 B x " + count(window) + " samples of work arrays",
                        "allan.window_s", formats::shortest(c.allan.window_s), per_stream + 16.0 * window});
  if (stillPeriodNeeded(c)) {
    const double still = std::ceil(c.bias.still_seconds * rate);
    need.items.push_back({"still period: 3 axes x " + count(still) + " samples x 8 B", "bias.still_seconds",
                          formats::shortest(c.bias.still_seconds), 3.0 * 8.0 * still});
  }
  need.items.push_back({"mean filters: 3 axes x " + count(static_cast<double>(c.filter.mean_window)) + " samples",
                        "filter.mean_window", std::to_string(c.filter.mean_window),
                        3.0 * 16.0 * static_cast<double>(c.filter.mean_window)});
  need.items.push_back(
      {"client output buffers: " + std::to_string(kMaxSocketClients) + " clients x " +
           std::to_string(c.socket.client_buffer_kib) + " KiB",
       "socket.client_buffer_kib", std::to_string(c.socket.client_buffer_kib),
       static_cast<double>(kMaxSocketClients) * static_cast<double>(c.socket.client_buffer_kib) * 1024.0});
  const auto handover = static_cast<double>(clientQueueLines(recordedSamplesPerSecond(c)));
  need.items.push_back({"hand-over to the delivery thread: " + count(handover) + " lines x " +
                            std::to_string(sizeof(LineForClients)) + " B",
                        "device.rate_hz", formats::shortest(c.device.rate_hz),
                        handover * static_cast<double>(sizeof(LineForClients))});
  if (c.check.enabled && !c.filter.model.empty()) {
    // At its analysis rate (the device's averaged down to kLiveCheckMaxRateHz): the baseline's
    // intervals kept until it is complete, the interval filling, the one examined, the one before
    // and the two together (8 B a sample, 3 axes), and the periodogram's work (≈ 64 B a sample of
    // the two-interval window).
    const double analysed = rate / std::ceil(rate / kLiveCheckMaxRateHz - 1e-9);
    const double interval = std::round(c.check.interval_s * analysed);
    const double baseline = std::ceil(c.check.baseline_s / c.check.interval_s - 1e-9) * interval;
    need.items.push_back({"live check: 3 axes x " + count(baseline + 5.0 * interval) + " samples x 8 B and its work",
                          "check.baseline_s", formats::shortest(c.check.baseline_s),
                          24.0 * (baseline + 5.0 * interval) + 128.0 * interval});
  }
  if (c.mqtt.enabled() && c.mqtt.qos == 1 && c.mqtt.buffer_messages > 0) {
    const auto kept = static_cast<double>(c.mqtt.buffer_messages);
    // 1.5 times: the array it grew from is still there while its lines are copied.
    need.items.push_back({"MQTT messages kept while the broker is away: " + count(kept) + " x " +
                              std::to_string(sizeof(LineForClients)) + " B x 1.5 (while it grows)",
                          "mqtt.buffer_messages", std::to_string(c.mqtt.buffer_messages),
                          1.5 * kept * static_cast<double>(sizeof(LineForClients))});
  }
  if (c.record.enabled()) {
    const auto ring = static_cast<double>(recorderOptions(c.record, recordedSamplesPerSecond(c)).ring_capacity);
    need.items.push_back(
        {"recorder ring: " + count(ring) + " records x " + std::to_string(sizeof(RecorderRecord)) + " B", "record.path",
         "\"" + c.record.path + "\"", ring * static_cast<double>(sizeof(RecorderRecord)) * 2.0 + (1 << 17)});
  }
  std::sort(need.items.begin(), need.items.end(),
            [](const MemoryItem& a, const MemoryItem& b) { return a.bytes > b.bytes; });
  need.total_bytes = kBaseMemoryBytes;
  for (const auto& item : need.items) need.total_bytes += item.bytes;
  return need;
}

}  // namespace gyrod::daemon
