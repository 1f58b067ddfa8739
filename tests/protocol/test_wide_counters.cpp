// Counters and sequence numbers past 2^32 go through the socket's lines unchanged on every
// target: gyrod running for months at 8 kHz passes 2^32 samples, and on a 32-bit board
// (armhf) a size_t or unsigned long anywhere on the way would wrap. scripts/cross-test.sh
// runs this under qemu-user for arm64 and armhf; it runs natively too.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <variant>

#include "driver/counter_names.hpp"
#include "protocol/protocol.hpp"

using namespace gyrod;
using namespace gyrod::protocol;

namespace {

template <class T>
T parsedWide(const std::string& line) {
  const ServerMessage m = parseServerLine(line.substr(0, line.size() - 1));  // without its '\n'
  const T* value = std::get_if<T>(&m);
  if (value == nullptr) throw std::runtime_error("parsed to another class: " + line);
  return *value;
}

constexpr std::uint64_t k2To32 = std::uint64_t{1} << 32;

TEST(WideCounters, EveryDriverCounterPast2To32ComesBackFromStatus) {
  StatusReport d;
  d.uptime_s = 4.0e6;  // 46 days
  d.device_state = "streaming";
  d.samples = 5 * k2To32 + 7;
  d.gaps = k2To32 + 1;
  d.missing_samples = 3 * k2To32;
  d.bus_errors = k2To32 - 1;
  d.resets = k2To32;
  std::uint64_t value = k2To32;
  for (const auto& c : driver::kDriverCounterNames) d.device_counters.push_back({std::string(c.name), value++});
  d.device_counters.back().value = UINT64_MAX;
  ServerStatus s;
  s.clients_total = k2To32 + 2;
  s.lines_dropped = 7 * k2To32;

  const StatusReply back = parsedWide<StatusReply>(statusLine(d, s));
  EXPECT_EQ(back.daemon.device_counters, d.device_counters);
  EXPECT_EQ(back.daemon.samples, d.samples);
  EXPECT_EQ(back.daemon.gaps, d.gaps);
  EXPECT_EQ(back.daemon.missing_samples, d.missing_samples);
  EXPECT_EQ(back.daemon.bus_errors, d.bus_errors);
  EXPECT_EQ(back.daemon.resets, d.resets);
  EXPECT_EQ(back.server.clients_total, s.clients_total);
  EXPECT_EQ(back.server.lines_dropped, s.lines_dropped);
}

TEST(WideCounters, RateAndGapSequenceNumbersPast2To32ComeBack) {
  RateSample r;
  r.seq = 9 * k2To32 + 3;
  r.t_s = 4.0e6 + 0.125;  // a CLOCK_MONOTONIC time 46 days after boot
  r.raw_dps = r.mean_dps = r.kalman_dps = {1.0, -2.0, 0.5};
  std::array<char, kMaxRateLineBytes> rate_buffer{};
  const std::size_t rate_size = formatRateLine(r, rate_buffer);
  const RateSample rate_back = parsedWide<RateSample>(std::string(rate_buffer.data(), rate_size));
  EXPECT_EQ(rate_back.seq, r.seq);
  EXPECT_EQ(rate_back.t_s, r.t_s);

  std::array<char, kMaxGapLineBytes> gap_buffer{};
  const std::size_t gap_size = formatGapLine({k2To32 + 11, 2 * k2To32, "fifo_overflow"}, gap_buffer);
  const GapNotice gap_back = parsedWide<GapNotice>(std::string(gap_buffer.data(), gap_size));
  EXPECT_EQ(gap_back.first_missing_seq, k2To32 + 11);
  EXPECT_EQ(gap_back.count, 2 * k2To32);
}

}  // namespace
