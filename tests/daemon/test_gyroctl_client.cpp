// gyroctl watch / allan / status / effects as a user runs them: a real gyroctl process against a
// server in this test process (the loop is pumped while gyroctl runs).
#include <fcntl.h>
#include <grp.h>
#include <pwd.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <sstream>

#include "server_fixture.hpp"

extern char** environ;

using namespace gyrod;
using namespace gyrod::test;

namespace {

std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> w;
  std::istringstream in(line);
  for (std::string s; in >> s;) w.push_back(s);
  return w;
}

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

class GyroctlTest : public ServerFixture {
 protected:
  // Starts gyroctl with `args`, pumps our loop until it exits, returns what it printed.
  // `env`: NAME=value entries replacing or adding to ours; `as_user`: run as this uid
  // (and its group), which needs root.
  CommandResult run(const std::vector<std::string>& args, const std::vector<std::string>& env = {},
                    std::optional<uid_t> as_user = std::nullopt) {
    const auto out_path = dir_.path() / "out.txt";
    const auto err_path = dir_.path() / "err.txt";
    const protocol::Fd out(::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666));
    const protocol::Fd err(::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666));
    std::vector<std::string> argv_s = binaryArgv("gyroctl");
    const std::string exe = argv_s.front();
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<std::string> env_s;
    for (char** e = environ; *e != nullptr; ++e) {
      const std::string entry(*e);
      const std::string name = entry.substr(0, entry.find('='));
      bool replaced = false;
      for (const auto& mine : env) replaced = replaced || mine.substr(0, mine.find('=')) == name;
      if (!replaced) env_s.push_back(entry);
    }
    env_s.insert(env_s.end(), env.begin(), env.end());
    std::vector<char*> argv, envp;
    for (auto& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);
    for (auto& e : env_s) envp.push_back(e.data());
    envp.push_back(nullptr);
    const passwd* user = as_user ? ::getpwuid(*as_user) : nullptr;
    const gid_t user_gid = user ? user->pw_gid : 0;

    const pid_t pid = ::fork();
    if (pid == 0) {
      ::dup2(out.get(), 1);
      ::dup2(err.get(), 2);
      const int devnull = ::open("/dev/null", O_RDONLY);
      ::dup2(devnull, 0);
      if (as_user && (::setgroups(0, nullptr) != 0 || ::setgid(user_gid) != 0 || ::setuid(*as_user) != 0)) ::_exit(125);
      ::execve(exe.c_str(), argv.data(), envp.data());
      ::_exit(126);
    }
    CommandResult result;
    if (pid < 0) {
      ADD_FAILURE() << "fork failed";
      return result;
    }
    int status = 0;
    bool reaped = false;
    const bool exited = pumpUntil(loop_, [&] { return reaped || (reaped = ::waitpid(pid, &status, WNOHANG) == pid); });
    if (!exited) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      ADD_FAILURE() << "gyroctl did not finish";
    }
    result.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    result.out = readWholeFile(out_path);
    result.err = readWholeFile(err_path);
    return result;
  }

  // Publishes sample k (k = 0, 1, ...) every 200 µs while someone watches; `after(k)` runs
  // after each, for GAPs.
  void publishWhileWatched(std::function<void(std::uint64_t)> after = {}) {
    auto next = std::make_shared<std::uint64_t>(0);
    loop_.addPeriodicTimer(200us, [this, next, after](std::uint64_t) {
      if (server_->watcherCount() == 0) return;
      const std::uint64_t k = (*next)++;
      server_->publishRate(syntheticSample(k));
      if (after) after(k);
    });
  }
};

}  // namespace

TEST_F(GyroctlTest, WatchJsonPassesLinesThroughUnchangedAndStopsAtCount) {
  startServer();
  publishWhileWatched();
  const CommandResult r = run({"watch", "--socket", socketPath(), "--json", "--count", "5"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto lines = splitLines(r.out);
  ASSERT_EQ(lines.size(), 7u) << r.out;
  EXPECT_EQ(json::parse(lines[0])["class"], "VERSION");
  EXPECT_EQ(json::parse(lines[1]), json::parse(R"({"class":"WATCH","enable":true,"decimate":1})"));
  for (std::size_t k = 0; k < 5; ++k) {
    std::array<char, protocol::kMaxRateLineBytes> expected;
    const std::size_t n = protocol::formatRateLine(syntheticSample(k), expected);
    EXPECT_EQ(lines[2 + k] + "\n", std::string(expected.data(), n));  // byte for byte
    expectRateLineCarries(lines[2 + k], syntheticSample(k));
  }
}

TEST_F(GyroctlTest, WatchShowsRawAndKalmanPerAxisAndGaps) {
  startServer();
  publishWhileWatched([this](std::uint64_t k) {
    if (k == 1) server_->publishGap({1002, 2, "fifo_overflow"});
  });
  const CommandResult r = run({"watch", "--socket", socketPath(), "--count", "3", "--decimate", "2"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto lines = splitLines(r.out);
  ASSERT_EQ(lines.size(), 6u) << r.out;  // header, t legend, row, gap, row, row
  const auto header = words(lines[0]);
  EXPECT_EQ(header.front(), "seq");
  EXPECT_NE(lines[0].find("kalman z"), std::string::npos);
  EXPECT_EQ(lines[1].rfind("t: CLOCK_MONOTONIC", 0), 0u) << lines[1];
  EXPECT_EQ(lines[3], "--- gap: 2 sample(s) missing from seq 1002 (fifo_overflow)");
  const std::size_t rows[] = {2, 4, 5};
  for (std::size_t i = 0; i < 3; ++i) {
    const protocol::RateSample s = syntheticSample(2 * i);  // decimate 2: samples 0, 2, 4
    const auto w = words(lines[rows[i]]);
    ASSERT_EQ(w.size(), 8u) << lines[rows[i]];
    EXPECT_EQ(w[0], std::to_string(s.seq));
    EXPECT_EQ(w[1], fixed(s.t_s, 3));
    for (std::size_t a = 0; a < 3; ++a) {
      EXPECT_EQ(w[2 + a], fixed(s.raw_dps[a], 5)) << lines[rows[i]];
      EXPECT_EQ(w[5 + a], fixed(s.kalman_dps[a], 5)) << lines[rows[i]];
    }
  }
}

TEST_F(GyroctlTest, WatchShowsRateFirstThenRawAndKalmanAndStillWhenGyrodSendsRate) {
  const auto withRate = [](std::uint64_t k) {
    protocol::RateSample s = syntheticSample(k);
    s.rate_dps = {0.5 + static_cast<double>(k), -1.25, 30.0};
    s.bias_dps = {0.01, 0.02, 0.03};
    s.still = k % 2 == 0;
    return s;
  };
  startServer();
  auto next = std::make_shared<std::uint64_t>(0);
  loop_.addPeriodicTimer(200us, [this, next, withRate](std::uint64_t) {
    if (server_->watcherCount() == 0) return;
    server_->publishRate(withRate((*next)++));
  });
  const CommandResult r = run({"watch", "--socket", socketPath(), "--count", "2"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto lines = splitLines(r.out);
  ASSERT_EQ(lines.size(), 4u) << r.out;  // header, t legend, row, row
  EXPECT_LT(lines[0].find("rate x"), lines[0].find("raw x")) << lines[0];
  EXPECT_LT(lines[0].find("raw z"), lines[0].find("kalman x")) << lines[0];
  EXPECT_NE(lines[0].find("still"), std::string::npos) << lines[0];
  for (std::size_t i = 0; i < 2; ++i) {
    const protocol::RateSample s = withRate(i);
    const auto w = words(lines[2 + i]);
    ASSERT_EQ(w.size(), 12u) << lines[2 + i];
    EXPECT_EQ(w[0], std::to_string(s.seq));
    for (std::size_t a = 0; a < 3; ++a) {
      EXPECT_EQ(w[2 + a], fixed(s.rate_dps[a], 5)) << lines[2 + i];
      EXPECT_EQ(w[5 + a], fixed(s.raw_dps[a], 5)) << lines[2 + i];
      EXPECT_EQ(w[8 + a], fixed(s.kalman_dps[a], 5)) << lines[2 + i];
    }
    EXPECT_EQ(w[11], i % 2 == 0 ? "yes" : "no");
  }
}

TEST_F(GyroctlTest, WatchAddsRollPitchAndHeadingWhenGyrodSendsTheOrientation) {
  const auto oriented = [](std::uint64_t k) {
    protocol::RateSample s = syntheticSample(k);
    s.rate_dps = {0.5, -1.25, 30.0};
    s.bias_dps = {0.01, 0.02, 0.03};
    s.still = false;
    s.quat = {0.9238795325112867, 0.0, 0.0, 0.3826834323650898};
    s.roll_pitch_heading_deg = {1.5, -2.25, 45.0 + static_cast<double>(k)};
    s.inclination_std_deg = 0.1;
    s.heading_std_deg = 0.2;
    return s;
  };
  startServer();
  auto next = std::make_shared<std::uint64_t>(0);
  loop_.addPeriodicTimer(200us, [this, next, oriented](std::uint64_t) {
    if (server_->watcherCount() == 0) return;
    server_->publishRate(oriented((*next)++));
  });
  const CommandResult r = run({"watch", "--socket", socketPath(), "--count", "2"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto lines = splitLines(r.out);
  ASSERT_EQ(lines.size(), 4u) << r.out;  // header, t legend, row, row
  EXPECT_LT(lines[0].find("still"), lines[0].find("roll")) << lines[0];
  EXPECT_LT(lines[0].find("pitch"), lines[0].find("heading")) << lines[0];
  for (std::size_t i = 0; i < 2; ++i) {
    const protocol::RateSample s = oriented(i);
    const auto w = words(lines[2 + i]);
    ASSERT_EQ(w.size(), 15u) << lines[2 + i];
    for (std::size_t a = 0; a < 3; ++a) EXPECT_EQ(w[12 + a], fixed(s.roll_pitch_heading_deg[a], 3)) << lines[2 + i];
  }
}

TEST_F(GyroctlTest, WatchHeaderSaysWhatTIsAndMapsItToUtc) {
  const auto withTime = [](std::uint64_t k) {
    protocol::RateSample s = syntheticSample(k);
    s.time_s = 1795000000.25 + static_cast<double>(k) / 50.0;  // 2026-11-18T11:06:40.25Z
    s.accel_g = {0.0, 0.0, 1.0};
    return s;
  };
  startServer();
  auto next = std::make_shared<std::uint64_t>(0);
  loop_.addPeriodicTimer(200us, [this, next, withTime](std::uint64_t) {
    if (server_->watcherCount() == 0) return;
    server_->publishRate(withTime((*next)++));
  });
  const CommandResult r = run({"watch", "--socket", socketPath(), "--count", "1"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto lines = splitLines(r.out);
  ASSERT_EQ(lines.size(), 3u) << r.out;  // header, t legend, row
  // The legend has a line of its own, so that the column header stays as wide as the columns.
  EXPECT_EQ(lines[0].substr(lines[0].size() - 7), "[deg/s]") << lines[0];
  EXPECT_EQ(lines[1],
            "t: CLOCK_MONOTONIC s of the data-ready edge; time: UTC, t 12345.678 = "
            "2026-11-18T11:06:40.250000Z");
}

TEST_F(GyroctlTest, StatusHumanAndJson) {
  content_.status.device_state = "streaming";
  content_.status.samples = 1234;
  content_.status.rate_hz = 49.97;
  content_.status.device = "/dev/i2c-1@0x68";
  startServer();
  const CommandResult j = run({"status", "--json"}, {"GYROD_SOCKET=" + socketPath()});  // socket from the environment
  ASSERT_EQ(j.exit_status, 0) << j.err;
  const json s = json::parse(j.out);
  EXPECT_EQ(s["class"], "STATUS");
  EXPECT_EQ(s["samples"], 1234);
  EXPECT_EQ(s["rate"].get<double>(), 49.97);
  ASSERT_EQ(s["client_list"].size(), 1u);
  EXPECT_EQ(s["client_list"][0]["self"], true);

  const CommandResult h = run({"status", "--socket", socketPath()});
  ASSERT_EQ(h.exit_status, 0) << h.err;
  EXPECT_NE(h.out.find(std::string("gyrod ") + GYROD_RELEASE + " (protocol 1.9)"), std::string::npos) << h.out;
  EXPECT_NE(h.out.find("device_state:    streaming\n"), std::string::npos) << h.out;
  EXPECT_NE(h.out.find("device:          /dev/i2c-1@0x68\n"), std::string::npos) << h.out;
  EXPECT_NE(h.out.find("samples:         1234\n"), std::string::npos) << h.out;
  EXPECT_NE(h.out.find("rate:            49.97 Hz\n"), std::string::npos) << h.out;
  EXPECT_NE(h.out.find("(this gyroctl)"), std::string::npos) << h.out;
}

TEST_F(GyroctlTest, StatusShowsTheDeviceReasonAndEveryDriverCounter) {
  content_.status.device_state = "failed";
  content_.status.device_reason = "WHO_AM_I reads 0x00: no MPU6050 at 0x68";
  content_.status.device_retrying = false;
  content_.status.device_counters = {{"transfers_failed", 12}, {"recoveries", 3}, {"data_ready_missed", 7}};
  content_.status.mqtt = protocol::MqttStatus{false, 250, 0, "Connection refused"};
  startServer();
  const CommandResult h = run({"status", "--socket", socketPath()});
  ASSERT_EQ(h.exit_status, 0) << h.err;
  EXPECT_NE(h.out.find("device_state:    failed\ndevice_reason:   WHO_AM_I reads 0x00: no MPU6050 at 0x68\n"
                       "device_retrying: no\n"),
            std::string::npos)
      << h.out;
  EXPECT_NE(h.out.find("driver counters:\n  transfers_failed:      12\n  recoveries:            3\n"
                       "  data_ready_missed:     7\n"),
            std::string::npos)
      << h.out;
  EXPECT_NE(h.out.find("mqtt:            not connected, 250 kept for the broker, 0 dropped; last error: Connection "
                       "refused\n"),
            std::string::npos)
      << h.out;

  const CommandResult j = run({"status", "--socket", socketPath(), "--json"});
  ASSERT_EQ(j.exit_status, 0) << j.err;
  const json s = json::parse(j.out);
  EXPECT_EQ(s["device_reason"], content_.status.device_reason);
  EXPECT_EQ(s["device_retrying"], false);
  EXPECT_EQ(s["counters"], json::parse(R"({"transfers_failed":12,"recoveries":3,"data_ready_missed":7})"));
  EXPECT_EQ(s["mqtt_buffered"], 250);
}

// The effects the live check names now, in a table whatever the effect (a kind this gyroctl does
// not know shows its parameters all the same); --json passes the EFFECTS line through.
TEST_F(GyroctlTest, EffectsTableAndJson) {
  content_.status.device_state = "streaming";
  content_.status.live_check = protocol::LiveCheckStatus{
      14,
      true,
      2,
      0,
      {R"({"class":"EFFECT","state":"new","effect":"line","axis":"y","t":4200.0,"onset_t":3600.0,)"
       R"("onset_t_95":[3300.0,3620.0],"params":{"centre_hz":12.4996,"centre_hz_95":[12.4988,12.5005],)"
       R"("width_hz":0.005,"rms_dps":0.0026,"rms_dps_95":[0.0021,0.0031],"power_ratio":23.0},)"
       R"("evidence":"periodogram over the last 600 s at 12.5 Hz stands 23 x the baseline's level"})",
       R"({"class":"EFFECT","state":"new","effect":"some_later_kind","axis":"z","t":4500.0,"onset_t":4380.5,)"
       R"("onset_t_95":[4300.0,4400.0],"params":{"step_dps":0.01},"evidence":"a later detector's words"})"}};
  startServer();
  const CommandResult h = run({"effects", "--socket", socketPath()});
  ASSERT_EQ(h.exit_status, 0) << h.err;
  const auto lines = splitLines(h.out);
  ASSERT_EQ(lines.size(), 5u) << h.out;
  EXPECT_EQ(lines[0], "live check: on, 14 intervals examined, baseline ready");
  EXPECT_EQ(words(lines[1]).front(), "effect") << h.out;
  EXPECT_NE(lines[2].find("line"), std::string::npos) << h.out;
  EXPECT_NE(lines[2].find("  y  "), std::string::npos) << h.out;
  EXPECT_NE(lines[2].find("3600 (3300..3620)"), std::string::npos) << h.out;
  EXPECT_NE(lines[2].find("4200.0"), std::string::npos) << h.out;
  EXPECT_NE(lines[2].find("centre_hz 12.5 (12.5..12.5), width_hz 0.005, rms_dps 0.0026 (0.0021..0.0031)"),
            std::string::npos)
      << h.out;
  EXPECT_NE(lines[2].find("stands 23 x the baseline's level"), std::string::npos) << h.out;
  EXPECT_NE(lines[3].find("some_later_kind"), std::string::npos) << h.out;
  EXPECT_NE(lines[3].find("step_dps 0.01"), std::string::npos) << h.out;
  EXPECT_NE(lines[3].find("a later detector's words"), std::string::npos) << h.out;
  // The columns line up: each row's axis starts where the header's does.
  EXPECT_EQ(lines[2].find(" y "), lines[1].find(" axis")) << h.out;
  EXPECT_EQ(lines[2].find("centre_hz"), lines[1].find("parameters")) << h.out;

  const CommandResult j = run({"effects", "--socket", socketPath(), "--json"});
  ASSERT_EQ(j.exit_status, 0) << j.err;
  const json e = json::parse(j.out);
  EXPECT_EQ(e["class"], "EFFECTS");
  EXPECT_EQ(e["live_check"], "on");
  ASSERT_EQ(e["effects"].size(), 2u);
  EXPECT_EQ(e["effects"][0]["params"]["centre_hz"], 12.4996);
  EXPECT_EQ(e["effects"][1]["effect"], "some_later_kind");

  content_.status.live_check->current.clear();
  content_.status.live_check->baseline_ready = false;
  const CommandResult none = run({"effects", "--socket", socketPath()});
  ASSERT_EQ(none.exit_status, 0) << none.err;
  EXPECT_EQ(none.out,
            "live check: on, 14 intervals examined, baseline not complete yet (nothing is compared with it before)\n"
            "no effect named now\n");
}

TEST_F(GyroctlTest, EffectsSaysWhenTheLiveCheckIsOff) {
  content_.status.device_state = "streaming";
  startServer();
  const CommandResult h = run({"effects", "--socket", socketPath()});
  ASSERT_EQ(h.exit_status, 0) << h.err;
  EXPECT_EQ(h.out, "live check: off (the daemon does not run the live check)\n");
  const CommandResult j = run({"effects", "--socket", socketPath(), "--json"});
  ASSERT_EQ(j.exit_status, 0) << j.err;
  EXPECT_EQ(json::parse(j.out),
            json::parse(R"({"class":"EFFECTS","live_check":"off","reason":"the daemon does not run the live check",)"
                        R"("effects":[]})"));
}

namespace {

protocol::AllanReport exampleAllan() {
  protocol::AllanReport a;
  a.window_s = 600.0;
  a.samples = 30000;
  a.tau0_s = 0.02;
  a.tau_s = {0.02, 0.2, 2.0};
  // White rate noise: σ(τ) ∝ τ^−1/2.
  for (std::size_t axis = 0; axis < 3; ++axis)
    for (const double tau : a.tau_s) {
      a.curves[axis][0].adev_dps.push_back(0.01 * (axis + 1) / std::sqrt(tau / 0.02));
      a.curves[axis][2].adev_dps.push_back(0.001 * (axis + 1) / std::sqrt(tau / 0.02));
    }
  processing::NoiseTerms t;
  t.quantization_urad = std::numeric_limits<double>::quiet_NaN();
  t.arw_deg_per_sqrt_h = 0.42;
  t.bias_instability_deg_per_h = std::numeric_limits<double>::quiet_NaN();
  t.rrw_deg_per_h_sqrt_h = std::numeric_limits<double>::quiet_NaN();
  t.rate_ramp_deg_per_h2 = std::numeric_limits<double>::quiet_NaN();
  a.curves[0][0].noise = t;
  processing::NoiseTerms sigma = t;
  sigma.arw_deg_per_sqrt_h = 0.03;
  a.curves[0][0].noise_uncertainty = sigma;
  a.span_s = 600.0;
  a.confidence = 0.683;
  // The x raw curve as a table: an interval at the first two τ, none yet at the third.
  for (std::size_t i = 0; i < a.tau_s.size(); ++i) {
    processing::AllanPoint p;
    p.tau_s = a.tau_s[i];
    p.m = static_cast<std::size_t>(std::llround(a.tau_s[i] / a.tau0_s));
    p.oadev = a.curves[0][0].adev_dps[i];
    p.oadev_terms = 30000 - 2 * p.m + 1;
    p.adev = std::numeric_limits<double>::quiet_NaN();
    p.edf = p.oadev_lo = p.oadev_hi = std::numeric_limits<double>::quiet_NaN();
    if (i < 2) {
      p.noise_alpha = 0;
      p.edf = 1000.0 / static_cast<double>(i + 1);
      p.oadev_lo = 0.9 * p.oadev;
      p.oadev_hi = 1.1 * p.oadev;
    }
    a.curves[0][0].points.push_back(p);
  }
  return a;
}

}  // namespace

TEST_F(GyroctlTest, AllanTableJsonAndPlot) {
  content_.allan = exampleAllan();
  startServer();
  const CommandResult h = run({"allan", "--socket", socketPath()});
  ASSERT_EQ(h.exit_status, 0) << h.err;
  const auto lines = splitLines(h.out);
  ASSERT_GE(lines.size(), 5u) << h.out;
  // How much data: the samples and the span they cover, then the configured window.
  EXPECT_NE(lines[0].find("of 30000 samples covering 600 s (window up to 600 s, tau0 0.02 s)"), std::string::npos)
      << lines[0];
  const auto head = words(lines[1]);
  const std::vector<std::string> expected_head = {"tau", "[s]", "x",      "raw", "x",   "kalman", "y",
                                                  "raw", "y",   "kalman", "z",   "raw", "z",      "kalman"};
  EXPECT_EQ(head, expected_head);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto w = words(lines[2 + i]);
    ASSERT_EQ(w.size(), 7u) << lines[2 + i];
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4e", content_.allan.curves[1][2].adev_dps[i]);
    EXPECT_EQ(w[4], buf);  // y kalman
  }
  // No noise term without its uncertainty or a "not enough data" mark.
  EXPECT_NE(h.out.find("angle random walk N [deg/sqrt(h)]    = 0.42 +- 0.03\n"), std::string::npos) << h.out;
  EXPECT_NE(h.out.find("bias instability B [deg/h]           not enough data\n"), std::string::npos) << h.out;
  // The intervals of the x raw table, and the τ without one yet.
  EXPECT_NE(h.out.find("68.3 % chi2 confidence intervals"), std::string::npos) << h.out;
  char row[160];
  const auto& p0 = content_.allan.curves[0][0].points[0];
  std::snprintf(row, sizeof row, "  %11.6g %11.4e %11.4e %11.4e %10zu", p0.tau_s, p0.oadev, p0.oadev_lo, p0.oadev_hi,
                p0.oadev_terms);
  EXPECT_NE(h.out.find(row), std::string::npos) << row << "\n" << h.out;
  EXPECT_NE(h.out.find("not enough data"), std::string::npos) << h.out;

  const CommandResult j = run({"allan", "--socket", socketPath(), "--json"});
  ASSERT_EQ(j.exit_status, 0) << j.err;
  EXPECT_EQ(j.out, protocol::allanLine(content_.allan));

  const auto png = dir_.path() / "adev.png";
  const CommandResult p = run({"allan", "--socket", socketPath(), "--plot", png.string()});
  if (p.err.find("gnuplot is not installed") != std::string::npos) GTEST_SKIP() << "gnuplot is not installed here";
  ASSERT_EQ(p.exit_status, 0) << p.err;
  const std::string image = readWholeFile(png);
  ASSERT_GT(image.size(), 1000u);
  EXPECT_EQ(image.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  // The error bars and the fitted term lines are drawn: a plot with them differs from one without.
  protocol::AllanReport bare = content_.allan;
  for (auto& axis : bare.curves)
    for (auto& curve : axis) {
      curve.points.clear();
      curve.noise.reset();
      curve.noise_uncertainty.reset();
    }
  content_.allan = bare;
  const auto bare_png = dir_.path() / "bare.png";
  ASSERT_EQ(run({"allan", "--socket", socketPath(), "--plot", bare_png.string()}).exit_status, 0);
  EXPECT_NE(readWholeFile(bare_png), image);
}

TEST_F(GyroctlTest, PlotWithoutGnuplotSaysSoAfterTheTable) {
  content_.allan = exampleAllan();
  startServer();
  const auto png = dir_.path() / "adev.png";
  const CommandResult r =
      run({"allan", "--socket", socketPath(), "--plot", png.string()}, {"PATH=/nonexistent-gyrod-test"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("gnuplot is not installed (apt-get install gnuplot-nox)"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("tau [s]"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(png));
  const CommandResult bad = run({"allan", "--socket", socketPath(), "--plot", (dir_.path() / "adev.gif").string()});
  EXPECT_EQ(bad.exit_status, 64);  // EX_USAGE: a bad option value
  EXPECT_NE(bad.err.find("must end in .png, .svg or .pdf"), std::string::npos) << bad.err;
}

TEST_F(GyroctlTest, ConnectionProblemsAreExplained) {
  const std::string missing = (dir_.path() / "none.sock").string();
  for (const char* cmd : {"watch", "allan", "status"}) {
    const CommandResult r = run({cmd, "--socket", missing});
    EXPECT_EQ(r.exit_status, 69) << cmd;  // EX_UNAVAILABLE
    EXPECT_EQ(r.err, "gyroctl: " + missing + ": no such socket (is gyrod running?)\n") << cmd;
    EXPECT_TRUE(r.out.empty());
  }

  // A socket file nobody listens on (a daemon that crashed).
  const std::string stale = (dir_.path() / "stale.sock").string();
  {
    daemon::SocketOptions so;
    so.path = stale;
    daemon::bindListeningSocket(so);
  }
  const CommandResult refused = run({"status", "--socket", stale});
  EXPECT_EQ(refused.exit_status, 69);
  EXPECT_NE(refused.err.find("connection refused"), std::string::npos) << refused.err;

  // A socket the user may not open (root may open anything, so run as nobody then).
  daemon::SocketOptions so;
  so.path = socketPath();
  so.mode = 0600;
  server_ = std::make_unique<daemon::UnixSocketServer>(loop_, daemon::bindListeningSocket(so), content_);
  std::optional<uid_t> as_user;
  if (::geteuid() == 0) {
    const passwd* nobody = ::getpwnam("nobody");
    if (nobody == nullptr) GTEST_SKIP() << "no 'nobody' user to test a permission refusal as";
    as_user = nobody->pw_uid;
  }
  const CommandResult r = run({"status", "--socket", socketPath()}, {}, as_user);
  EXPECT_EQ(r.exit_status, 69) << r.err;
  EXPECT_NE(r.err.find(socketPath() + ": permission denied (the socket is for members of group '"), std::string::npos)
      << r.err;
}
