#pragma once
// A virtual-time rig for the MPU6050 driver: the mock chip, a data-ready source, a sink
// that records everything, and an event loop that steps the virtual clock from event to
// event the way the daemon's epoll loop would wake. Plus a checker that compares what the
// driver delivered with the mock's ground truth (SampleRecord per sample).
#include <gtest/gtest.h>
#include <poll.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "driver/clock.hpp"
#include "driver/mock/mock_mpu6050.hpp"
#include "driver/mpu6050_driver.hpp"
#include "driver/polling_data_ready.hpp"
#include "processing/base/portable_random.hpp"

namespace gyrod::driver::test {

struct StreamEvent {
  bool is_gap = false;
  GyroSample sample;
  SampleGap gap;
};

class Recorder final : public SampleSink {
 public:
  void onSample(const GyroSample& s) override {
    events.push_back({false, s, {}});
    samples.push_back(s);
  }
  void onGap(const SampleGap& g) override {
    events.push_back({true, {}, g});
    gaps.push_back(g);
  }
  void onStatus(const DeviceStatus& s) override { statuses.push_back(s); }
  bool everIn(DeviceState state) const {
    return std::any_of(statuses.begin(), statuses.end(), [&](const DeviceStatus& s) { return s.state == state; });
  }
  std::vector<StreamEvent> events;
  std::vector<GyroSample> samples;
  std::vector<SampleGap> gaps;
  std::vector<DeviceStatus> statuses;
};

// Wraps a data-ready source and delays each reported edge time by a seeded pseudo-random
// latency in [0, max_latency_ns] (interrupt latency), or shifts chosen edges (glitches).
class JitteredDataReady final : public DataReadySource {
 public:
  JitteredDataReady(DataReadySource& inner, std::int64_t max_latency_ns, std::uint64_t seed)
      : inner_(inner), max_latency_ns_(max_latency_ns), rng_(seed) {}
  int fd() const override { return inner_.fd(); }
  int consumeEdge(std::int64_t& t) override {
    const int r = inner_.consumeEdge(t);
    if (r != 0) return r;
    ++edges_;
    if (max_latency_ns_ > 0) {
      t += static_cast<std::int64_t>(rng_.next() % static_cast<std::uint64_t>(max_latency_ns_ + 1));
    }
    if (glitch_every_ > 0 && edges_ % glitch_every_ == 0) t += glitch_shift_ns_;
    return 0;
  }
  std::uint64_t edgesDropped() const override { return inner_.edgesDropped(); }
  void setGlitches(std::uint64_t every, std::int64_t shift_ns) {
    glitch_every_ = every;
    glitch_shift_ns_ = shift_ns;
  }

 private:
  DataReadySource& inner_;
  std::int64_t max_latency_ns_;
  processing::SplitMix64 rng_;
  std::uint64_t edges_ = 0;
  std::uint64_t glitch_every_ = 0;
  std::int64_t glitch_shift_ns_ = 0;
};

inline MockMpu6050Config quietMock() {
  MockMpu6050Config c;
  c.accel_noise_g = 0.0;
  return c;
}

struct RigOptions {
  Mpu6050Config driver;
  MockMpu6050Config mock = quietMock();
  std::int64_t edge_latency_ns = 0;  // > 0: edges pass through JitteredDataReady
  std::uint64_t jitter_seed = 1;
};

inline Mpu6050Config withPolling(Mpu6050Config c) {
  c.data_ready_mode = DataReadyMode::Polling;
  c.polling_period_ns = pollingPeriodNs(c);
  return c;
}

class DriverRig {
 public:
  DriverRig(SignalSource& source, RigOptions options = {})
      : options_(options),
        mock(clock, source, options.mock),
        polling(options.driver.data_ready_mode == DataReadyMode::Polling
                    ? std::optional<PollingDataReady>(std::in_place, clock, options.driver.polling_period_ns)
                    : std::nullopt),
        jitter(mock.dataReady(), options.edge_latency_ns, options.jitter_seed),
        driver(mock, readySource(), clock, recorder, options.driver, [this](LogLevel level, std::string_view m) {
          logs.push_back(std::string(logLevelName(level)) + ": " + std::string(m));
        }) {
    mock.setSampleObserver([this](const SampleRecord& r) { truth.push_back(r); });
  }

  // Steps virtual time to `end_ns`, waking the driver as an epoll loop would: when its
  // data-ready fd is readable (edges; `edge_latency_ns` after each sample tick, so every
  // reported edge time is in the past), at each poll (polling), and at its deadlines.
  void runUntil(std::int64_t end_ns) {
    int same_time = 0;
    std::int64_t last = -1;
    for (;;) {
      std::int64_t t = end_ns;
      if (!polling) {
        if (auto s = mock.nextSampleTimeNs()) t = std::min(t, *s + options_.edge_latency_ns);
      } else {
        t = std::min(t, polling->nextPollNs());
      }
      if (auto d = driver.nextDeadlineNs(); d && !stalled_) t = std::min(t, *d);
      t = std::max(t, clock.nowNs());
      clock.setNs(t);
      mock.sync();
      if (t == last) {
        ASSERT_LT(++same_time, 10000) << "the driver keeps asking for the same instant " << t;
      } else {
        same_time = 0;
      }
      last = t;
      if (!stalled_) {
        if (polling) {
          if (t >= polling->nextPollNs()) driver.onDataReady();
        } else if (readable(driver.pollFd())) {
          driver.onDataReady();
        }
        if (auto d = driver.nextDeadlineNs(); d && *d <= t) driver.onTimer(t);
      }
      if (t >= end_ns) break;
    }
  }
  void runFor(std::int64_t dt_ns) { runUntil(clock.nowNs() + dt_ns); }
  // The loop is busy elsewhere: the driver is not called until resume().
  void stall() { stalled_ = true; }
  void resume() { stalled_ = false; }

  void start() { driver.start(); }
  // Start and run until the first sample arrives (at most 2 s).
  void startStreaming() {
    start();
    const std::int64_t limit = clock.nowNs() + 2 * kNsPerSecond;
    while (recorder.samples.empty() && clock.nowNs() < limit) runFor(10 * kNsPerMillisecond);
    ASSERT_FALSE(recorder.samples.empty()) << "no sample within 2 s";
  }

  // The chip's true sample period for the driver's configuration and the mock's clock error.
  double truePeriodNs() const {
    const Mpu6050Config& c = options_.driver;
    return 1e9 * (1.0 + sampleRateDivider(c)) /
           (mpu6050::gyroOutputRateHz(c.dlpf_cfg) * (1.0 + options_.mock.clock_error_ppm * 1e-6));
  }
  bool logged(const std::string& needle) const {
    return std::any_of(logs.begin(), logs.end(),
                       [&](const std::string& l) { return l.find(needle) != std::string::npos; });
  }

  VirtualClock clock{5 * kNsPerSecond};
  RigOptions options_;
  MockMpu6050 mock;
  std::optional<PollingDataReady> polling;
  JitteredDataReady jitter;
  Recorder recorder;
  std::vector<SampleRecord> truth;
  std::vector<std::string> logs;
  Mpu6050Driver driver;

 private:
  DataReadySource& readySource() {
    if (polling) return *polling;
    if (options_.edge_latency_ns > 0) return jitter;
    return mock.dataReady();
  }
  static bool readable(int fd) {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, 0) == 1 && (p.revents & POLLIN);
  }
  bool stalled_ = false;
};

// What the checker found, for test-specific assertions.
struct StreamCheck {
  std::size_t matched = 0;
  struct GapTruth {
    SampleGap gap;
    std::uint64_t produced_between = 0;  // mock samples strictly between the neighbours
    bool chip_ran = false;               // the chip's sample clock ran on across the gap
    std::uint64_t slots = 0;             // round(Δt_true / P_true) − 1
  };
  std::vector<GapTruth> gaps;  // one per hole between delivered samples (adjacent gaps merged)
  double max_abs_time_error_ns = 0.0;
  std::uint64_t total_seq = 0;  // last seq + 1
};

struct CheckOptions {
  // |t_driver − t_true| allowed for every sample.
  double timestamp_bound_ns = 1e6;
  // Gaps may differ from the truth by this much (polling mode: 1, see docs/driver.md).
  std::uint64_t gap_slack = 0;
};

// The driver's stream against the mock's truth:
//  1. sequence continuity: samples and gaps tile 0, 1, 2, ... with no hole or overlap;
//  2. each sample is a distinct mock sample, in order (equal raw words, found near its time);
//  3. each gap, where the chip's clock ran on, equals the mock samples produced between its
//     neighbours exactly; where the chip restarted, equals the whole periods of the hole
//     (and is at least what the chip produced meanwhile);
//  4. timestamps strictly increase and are within the bound of the true sample times.
inline StreamCheck checkStream(const Recorder& rec, const std::vector<SampleRecord>& truth, double true_period_ns,
                               const CheckOptions& opt = {}) {
  StreamCheck out;
  std::uint64_t expected = 0;
  for (const StreamEvent& e : rec.events) {
    if (e.is_gap) {
      EXPECT_EQ(e.gap.first_seq, expected) << "a gap does not start where the stream stopped";
      EXPECT_GE(e.gap.count, 1u);
      expected = e.gap.first_seq + e.gap.count;
    } else {
      EXPECT_EQ(e.sample.seq, expected) << "sequence hole or duplicate";
      expected = e.sample.seq + 1;
    }
  }
  out.total_seq = expected;

  std::size_t next_truth = 0;
  std::optional<std::size_t> prev_truth;
  const GyroSample* prev_sample = nullptr;
  bool have_gap = false;  // a plain flag: GCC 12 warns on an optional<SampleGap> here
  SampleGap pending_gap{};
  std::int64_t prev_t = INT64_MIN;
  const double window = opt.timestamp_bound_ns + true_period_ns;
  for (const StreamEvent& e : rec.events) {
    if (e.is_gap) {
      // Gaps with no sample between them (a FIFO restart that failed again) form one hole.
      if (have_gap) {
        pending_gap.count += e.gap.count;
      } else {
        pending_gap = e.gap;
        have_gap = true;
      }
      continue;
    }
    const GyroSample& s = e.sample;
    EXPECT_GT(s.t_ns, prev_t) << "timestamps must increase (seq " << s.seq << ")";
    prev_t = s.t_ns;
    // The mock sample after the previous match, within the window, with equal words,
    // nearest in time.
    std::optional<std::size_t> found;
    for (std::size_t i = next_truth; i < truth.size(); ++i) {
      const SampleRecord& r = truth[i];
      if (static_cast<double>(r.time_ns) > static_cast<double>(s.t_ns) + window) break;
      if (std::fabs(static_cast<double>(r.time_ns - s.t_ns)) > window) continue;
      if (r.written_to_fifo && r.gyro[0] == s.raw_gyro[0] && r.gyro[1] == s.raw_gyro[1] && r.gyro[2] == s.raw_gyro[2] &&
          r.temperature == s.raw_temp &&
          (!found || std::llabs(r.time_ns - s.t_ns) < std::llabs(truth[*found].time_ns - s.t_ns))) {
        found = i;
      }
    }
    if (!found) {
      ADD_FAILURE() << "sample seq " << s.seq << " at " << s.t_ns << " ns matches no mock sample";
      return out;
    }
    const SampleRecord& r = truth[*found];
    const double err = static_cast<double>(s.t_ns - r.time_ns);
    out.max_abs_time_error_ns = std::max(out.max_abs_time_error_ns, std::fabs(err));
    EXPECT_LE(std::fabs(err), opt.timestamp_bound_ns) << "seq " << s.seq;
    if (prev_truth && prev_sample) {
      const SampleRecord& pr = truth[*prev_truth];
      const std::uint64_t d = s.seq - prev_sample->seq;
      const std::uint64_t e_mock = r.sequence - pr.sequence;
      const double dt = static_cast<double>(r.time_ns - pr.time_ns);
      // The mock's tick k is at anchor + round(k·period): with one anchor, differences are
      // e·P within a nanosecond per tick of rounding.
      const bool ran = std::fabs(dt - static_cast<double>(e_mock) * true_period_ns) < 2.0 + 1e-6 * dt;
      const auto whole = static_cast<std::uint64_t>(std::llround(dt / true_period_ns));
      if (have_gap) {
        StreamCheck::GapTruth g{pending_gap, e_mock - 1, ran, whole - 1};
        out.gaps.push_back(g);
        if (ran) {
          EXPECT_LE(d > e_mock ? d - e_mock : e_mock - d, opt.gap_slack)
              << "gap at seq " << pending_gap.first_seq << " (" << gapCauseName(pending_gap.cause) << "): driver "
              << d - 1 << " lost, mock produced " << e_mock - 1 << " in between";
        } else {
          const double frac = dt / true_period_ns - std::floor(dt / true_period_ns);
          const std::uint64_t slack = opt.gap_slack + (std::fabs(frac - 0.5) < 0.02 ? 1 : 0);
          EXPECT_LE(d > whole ? d - whole : whole - d, slack)
              << "gap at seq " << pending_gap.first_seq << " (" << gapCauseName(pending_gap.cause)
              << ") after a chip restart: " << d - 1 << " slots reported, hole is " << dt / true_period_ns
              << " periods";
          EXPECT_LE(e_mock, d + opt.gap_slack) << "fewer slots than samples the chip produced";
        }
      } else {
        EXPECT_EQ(d, 1u);
        EXPECT_EQ(e_mock, 1u) << "consecutive samples skip mock samples without a gap at seq " << s.seq;
      }
    }
    have_gap = false;
    prev_truth = found;
    prev_sample = &s;
    next_truth = *found + 1;
    ++out.matched;
  }
  EXPECT_EQ(out.matched, rec.samples.size());
  return out;
}

}  // namespace gyrod::driver::test
