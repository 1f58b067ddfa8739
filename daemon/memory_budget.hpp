#pragma once
// The memory a configuration makes gyrod allocate, computed from the configuration before
// anything is allocated, so that a window of 10^12 s is a configuration error naming its
// key (exit 78) instead of std::bad_alloc or the OOM killer. Figures are upper bounds of
// what the daemon's own structures hold; they are doubles so that absurd values do not wrap.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "daemon/config.hpp"

namespace gyrod::daemon {

// What the daemon itself needs besides the items below (code, libraries, stacks touched,
// the event loop's small buffers), in bytes.
inline constexpr double kBaseMemoryBytes = 16e6;
// Clients served at once (more are refused with ERROR too_many_clients); each may hold
// socket.client_buffer_kib of output.
inline constexpr std::size_t kMaxSocketClients = 32;

struct MemoryItem {
  std::string what;   // for a person: "Allan statistics: 9 streams × 180000 samples × 16 B"
  std::string key;    // the configuration key that sizes it ("allan.window_s")
  std::string value;  // that key's value as configured ("3600")
  double bytes = 0.0;
};

struct MemoryNeed {
  std::vector<MemoryItem> items;  // largest first
  double total_bytes = 0.0;       // the items and kBaseMemoryBytes
};

MemoryNeed memoryNeeded(const GyrodConfig& config);

// A configuration above a budget: the key that sizes most of the memory (its items summed),
// and the rest of the one-line message after "key 'K': ".
struct MemoryBudgetProblem {
  std::string key;
  std::string message;
};
// `budget_name` says where the budget comes from ("limits.memory_mb = 1024 MB"), `raise`
// what may be raised instead of lowering the key ("limits.memory_mb").
std::optional<MemoryBudgetProblem> memoryBudgetProblem(const MemoryNeed& need, double budget_bytes,
                                                       const std::string& budget_name, const std::string& raise);

// What the kernel would grant this process at most, and why: the address space left under
// RLIMIT_AS (less what is mapped now and the threads' stacks), and RAM plus swap (with the
// default overcommit heuristic the kernel refuses an allocation larger than both). None
// when neither can be read.
struct KernelMemoryLimit {
  double bytes = 0.0;
  std::string name;   // "what RLIMIT_AS leaves (300 MB, 25 MB mapped at start)", "this machine's RAM and swap (...)"
  std::string raise;  // "RLIMIT_AS (ulimit -v, LimitAS=)", "the machine's memory"
};
std::optional<KernelMemoryLimit> kernelMemoryLimit();

// Samples per second the recorder receives: the device's rate, times the mock's speed when
// the mock runs faster than real time.
double recordedSamplesPerSecond(const GyrodConfig& config);

// 1.23e+09 bytes as "1230 MB", 4.5e+06 as "4.5 MB" (10^6 bytes, 3 significant digits).
std::string megabytes(double bytes);

}  // namespace gyrod::daemon
