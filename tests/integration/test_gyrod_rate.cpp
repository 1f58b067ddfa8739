// gyrod's `rate` stream on the accelerated mock turned by a [mock] motion, with a sensor model
// (filter.model) of the mock's chip: rate follows the true rotation (the mean over a constant
// turn is the truth within the noise and the model's bias error) while the paper's kalman
// stream is shrunk; the still detector sees the rest before the turn and not the turn; and
// `gyroctl filter --model` on gyrod's own recording gives the stream's rate, bias and still
// bit for bit; and the recording itself holds them (and `time`) as published.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "formats/recording_csv.hpp"
#include "gyrod_process.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

constexpr double kTurnStartS = 4.0;
// With accel the still detector says "moving" until its accel window (250 samples, 5 s) is full
// (docs/motion.md), so the rest before the turn must last longer to be seen.
constexpr double kMotionStartWithAccelS = 9.0;
double motionStartS(bool accel) { return accel ? kMotionStartWithAccelS : kTurnStartS; }
constexpr double kTurnRateDps = 30.0;
constexpr std::array<double, 3> kMockBias = {-3.34, 1.09, -0.5};  // the default mock model's
constexpr double kModelBiasStdDps = 0.02;

// The default mock model's terms and biases (daemon/device_backend.cpp), as a sensor model
// with a calibration: what `gyroctl analyze --write-model` would find on a long still record.
// The mock simulates the file filter.model names, so this is the simulated chip's own model
// (at a constant 25 °C: the file has no [temperature]).
std::string sensorModel() {
  std::ostringstream m;
  m << "rate_hz = 50\n";
  for (int a = 0; a < 3; ++a) {
    const char* axis = a == 0 ? "x" : a == 1 ? "y" : "z";
    m << "[" << axis << "]\nquantization_urad = 0.1663\narw_deg_per_sqrt_h = 0.95164\n"
      << "bias_instability_deg_per_h = 0.60565\nrrw_deg_per_h_sqrt_h = 0.07759\nbias_dps = " << kMockBias[a] << "\n"
      << "[" << axis << ".calibration]\nbias_std_dps = " << kModelBiasStdDps << "\ntemperature_reference_c = 30.0\n";
  }
  return m.str();
}

// accel on (the default): the recording carries ax, ay, az and `gyroctl filter` gives them to the
// still detector as gyrod does; accel off: neither has any, and the verdict is the gyro's alone.
// Either way live and offline must be the same bits.
std::string rateConfig(const std::filesystem::path& dir, const std::filesystem::path& model,
                       const std::string& extra = "", bool accel = true) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\naccel = " << (accel ? "true" : "false") << "\n"
    << "[bias]\nsource = \"config\"\nvalues = [-3.34, 1.09, -0.5]\n"
    << "[filter]\nmodel = \"" << model.string() << "\"\n"
    << "[filter.kalman]\na = 0.9\nq = 0.0001\nr = 0.01\n"
    << "[socket]\npath = \"" << (dir / "gyrod.sock").string() << "\"\n"
    << "[record]\npath = \"" << (dir / "rec.csv").string() << "\"\nflush_interval_s = 0.1\n"
    << "[mock]\nspeed = 50\nseed = 9\nmotion = \"constant:axis=z,rate=" << kTurnRateDps
    << ",start=" << motionStartS(accel) << "\"\n"
    << extra;
  return c.str();
}

// Reads RATE lines until `count` arrived (GAP lines would be a failure here: none are injected).
std::vector<json> readRateLines(LineClient& c, std::size_t count) {
  std::vector<json> rates;
  while (rates.size() < count) {
    const auto line = c.readLine(20s);
    if (!line) break;
    json j = json::parse(*line);
    EXPECT_NE(j["class"], "GAP") << *line;
    if (j["class"] == "RATE") rates.push_back(std::move(j));
  }
  return rates;
}

std::string statusRateModel(const std::filesystem::path& socket) {
  LineClient asker(socket.string());
  if (!asker.readLine()) return "(no VERSION)";
  asker.send("{\"cmd\":\"status\"}\n");
  while (const auto line = asker.readLine(10s))
    if (line->find("\"STATUS\"") != std::string::npos) return json::parse(*line).value("rate_model", "(none)");
  return "(no STATUS)";
}

double meanOf(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m += x / static_cast<double>(v.size());
  return m;
}
double stdOf(const std::vector<double>& v) {
  const double m = meanOf(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m) / static_cast<double>(v.size() - 1);
  return std::sqrt(s);
}

// `gyroctl filter --model`'s rate columns: per row gx_rate, gx_bias, ..., still.
struct OfflineRate {
  double t = 0.0;
  std::array<double, 3> kalman{}, rate{}, bias{};
  bool still = false;
};
std::vector<OfflineRate> offlineRate(const std::string& rec_path, const std::filesystem::path& model,
                                     const ScratchDir& d) {
  const auto filtered = d.path() / "filtered.csv";
  const auto r = runGyroctl("filter " + rec_path + " -o " + filtered.string() + " --model " + model.string() +
                                " --rate 50 --bias=-3.34,1.09,-0.5 --ar-phi 0.9 --kalman-q 0.0001 --kalman-r 0.01",
                            d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  std::ifstream f(filtered);
  std::string line;
  std::getline(f, line);
  EXPECT_NE(line.find(",gx_rate,gx_bias,gy_rate,gy_bias,gz_rate,gz_bias,still"), std::string::npos) << line;
  std::vector<OfflineRate> out;
  while (std::getline(f, line)) {
    std::stringstream ls(line);
    std::string field;
    std::vector<double> v;
    while (std::getline(ls, field, ',')) v.push_back(std::stod(field));
    OfflineRate o;
    o.t = v[0];
    for (int a = 0; a < 3; ++a) {
      o.kalman[a] = v[3 + 3 * a];
      o.rate[a] = v[10 + 2 * a];
      o.bias[a] = v[11 + 2 * a];
    }
    o.still = v[16] != 0.0;
    out.push_back(o);
  }
  return out;
}

// `gyroctl attitude --model`'s last nine columns per row: qw, qx, qy, qz, roll, pitch, heading,
// inclination_std, heading_std.
using AttitudeRow = std::array<double, 9>;
std::vector<AttitudeRow> offlineAttitude(const std::string& rec_path, const std::filesystem::path& model,
                                         const ScratchDir& d) {
  const auto out_path = d.path() / "attitude.csv";
  const auto r = runGyroctl(
      "attitude " + rec_path + " -o " + out_path.string() + " --model " + model.string() + " --rate 50", d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  std::ifstream f(out_path);
  std::string line;
  std::getline(f, line);
  EXPECT_NE(line.find(",qw,qx,qy,qz,roll,pitch,heading,inclination_std,heading_std"), std::string::npos) << line;
  std::vector<AttitudeRow> out;
  while (std::getline(f, line)) {
    std::stringstream ls(line);
    std::string field;
    std::vector<double> v;
    while (std::getline(ls, field, ',')) v.push_back(std::stod(field));
    AttitudeRow row{};
    std::copy(v.end() - 9, v.end(), row.begin());
    out.push_back(row);
  }
  return out;
}

// RATE's orientation fields in the order of AttitudeRow.
AttitudeRow attitudeOf(const json& r) {
  return {r["quat"][0].get<double>(),    r["quat"][1].get<double>(),
          r["quat"][2].get<double>(),    r["quat"][3].get<double>(),
          r["roll"].get<double>(),       r["pitch"].get<double>(),
          r["heading"].get<double>(),    r["inclination_std"].get<double>(),
          r["heading_std"].get<double>()};
}

// With the accel, every RATE line carries the orientation and it is `gyroctl attitude --model`'s
// on the recording, bit for bit, row by row; without it no line does.
void expectTheAttitudeIsTheOfflineOne(const std::vector<json>& rates, const std::vector<AttitudeRow>& offline,
                                      const std::function<std::size_t(std::uint64_t)>& rowOf, bool accel) {
  for (const json& r : rates) {
    ASSERT_EQ(r.contains("quat"), accel) << r.dump();
    if (!accel) continue;
    const std::size_t i = rowOf(r["seq"].get<std::uint64_t>());
    ASSERT_LT(i, offline.size());
    const AttitudeRow live = attitudeOf(r);
    for (std::size_t k = 0; k < live.size(); ++k) ASSERT_EQ(live[k], offline[i][k]) << "row " << i << " field " << k;
  }
}

void expectRateFollowsTheMotionAndIsTheOfflineRateStream(bool accel) {
  ScratchDir d;
  const auto model = d.write("sensor.toml", sensorModel());
  const auto cfg = d.write("gyrod.toml", rateConfig(d.path(), model, "", accel));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient watcher((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(watcher.connected()) << readWholeFile(d.path() / "log.txt");
  ASSERT_TRUE(watcher.readLine());  // VERSION
  ASSERT_TRUE(watcher.send("{\"cmd\":\"watch\"}\n"));
  std::vector<json> rates;
  const std::size_t samples = accel ? 800 : 600;  // 16 or 12 s of sensor time
  while (rates.size() < samples) {
    const auto line = watcher.readLine(20s);
    ASSERT_TRUE(line.has_value()) << readWholeFile(d.path() / "log.txt");
    json j = json::parse(*line);
    if (j["class"] == "RATE") rates.push_back(std::move(j));
  }
  LineClient asker((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(asker.readLine());  // VERSION
  ASSERT_TRUE(asker.send("{\"cmd\":\"status\"}\n"));
  std::optional<std::string> status_line;
  while ((status_line = asker.readLine(10s)) && status_line->find("\"STATUS\"") == std::string::npos) {}
  ASSERT_TRUE(status_line.has_value());
  EXPECT_EQ(json::parse(*status_line)["rate_model"], "model " + model.string());
  gyrod.signal(SIGTERM);
  ASSERT_EQ(gyrod.waitExit(2000ms), std::optional<int>(0)) << readWholeFile(d.path() / "log.txt");

  std::string rec_path;
  for (const auto& e : std::filesystem::directory_iterator(d.path()))
    if (e.path().filename().string().rfind("rec-", 0) == 0) rec_path = e.path().string();
  ASSERT_FALSE(rec_path.empty());
  const auto offline = offlineRate(rec_path, model, d);
  for (const json& r : rates) {
    const auto seq = r["seq"].get<std::size_t>();
    ASSERT_LT(seq, offline.size());
    for (int a = 0; a < 3; ++a) {
      ASSERT_EQ(r["rate"][a].get<double>(), offline[seq].rate[a]) << "seq " << seq << " axis " << a;
      ASSERT_EQ(r["bias"][a].get<double>(), offline[seq].bias[a]) << "seq " << seq << " axis " << a;
    }
    ASSERT_TRUE(r.contains("rate") && r.contains("bias") && r.contains("still")) << r.dump();
    ASSERT_EQ(r["still"].get<bool>(), offline[seq].still) << "seq " << seq;
  }
  if (accel) {
    const auto attitude = offlineAttitude(rec_path, model, d);
    ASSERT_EQ(attitude.size(), offline.size());
    expectTheAttitudeIsTheOfflineOne(
        rates, attitude, [](std::uint64_t seq) { return seq; }, accel);
    // The board turns about z, which points up: the heading follows the rate stream's integral
    // about z (the 0.5°), and roll and pitch stay put.
    double heading_change = 0.0, rate_integral = 0.0, largest_tilt = 0.0;
    for (std::size_t i = 1; i < attitude.size(); ++i) {
      if (offline[i].t <= motionStartS(accel) + 1.0) continue;
      double step = attitude[i][6] - attitude[i - 1][6];
      step -= 360.0 * std::round(step / 360.0);  // unwrapped across ±180°
      heading_change += step;
      rate_integral += offline[i].rate[2] / 50.0;
      largest_tilt = std::max({largest_tilt, std::fabs(attitude[i][4]), std::fabs(attitude[i][5])});
    }
    std::printf(
        "turn about z: heading change %.4f deg, the rate stream's integral %.4f deg; roll and pitch within %.3f deg\n",
        heading_change, rate_integral, largest_tilt);
    EXPECT_GT(heading_change, 100.0);
    EXPECT_NEAR(heading_change, rate_integral, 0.5);
    EXPECT_LT(largest_tilt, 1.0);
  } else {
    expectTheAttitudeIsTheOfflineOne(
        rates, {}, [](std::uint64_t seq) { return seq; }, accel);
  }

  // The figures over every sample of the recording (the stream equals it bit for bit, above):
  // at mock speed 50 a loaded machine may connect the watcher after the still period.
  std::array<std::vector<double>, 3> rate_still, rate_turning, kalman_turning;
  std::size_t still_before = 0, n_before = 0, still_during = 0;
  for (const OfflineRate& r : offline) {
    const double t = r.t;
    const bool before = t > (accel ? 5.5 : 1.0) && t < motionStartS(accel) - 0.5;
    const bool during = t > motionStartS(accel) + 1.0;
    for (int a = 0; a < 3; ++a) {
      if (before) rate_still[a].push_back(r.rate[a]);
      if (during) rate_turning[a].push_back(r.rate[a]);
      if (during) kalman_turning[a].push_back(r.kalman[a]);
    }
    if (before) {
      ++n_before;
      still_before += r.still ? 1 : 0;
    }
    if (during) still_during += r.still ? 1 : 0;
  }
  ASSERT_GE(n_before, 100u);
  ASSERT_GE(rate_turning[2].size(), 200u);
  EXPECT_GT(still_before, n_before / 2) << "the still detector should see the rest before the turn";
  EXPECT_EQ(still_during, 0u) << "a 30 deg/s turn is never still";
  for (int a = 0; a < 3; ++a) {
    // The mean over the turn: the truth within 5 standard errors of white noise, the model's
    // bias error (5 of its σ) and one quantum (1/131 °/s).
    const double n = static_cast<double>(rate_turning[a].size());
    const double tolerance = 5.0 * stdOf(rate_still[a]) / std::sqrt(n) + 5.0 * kModelBiasStdDps + 1.0 / 131.0;
    const double truth = a == 2 ? kTurnRateDps : 0.0;
    EXPECT_NEAR(meanOf(rate_turning[a]), truth, tolerance) << "axis " << a;
  }
  // The paper's filter, a low-pass of DC gain well below 1 (docs/motion.md), shrinks the turn.
  EXPECT_LT(meanOf(kalman_turning[2]), 0.6 * kTurnRateDps);
}

}  // namespace

TEST(GyrodRate, RateFollowsTheMotionAndIsTheOfflineRateStreamOfTheRecording) {
  expectRateFollowsTheMotionAndIsTheOfflineRateStream(true);
}

TEST(GyrodRate, WithAccelOffRateFollowsTheMotionAndIsTheOfflineRateStreamOfTheRecording) {
  expectRateFollowsTheMotionAndIsTheOfflineRateStream(false);
}

TEST(GyrodRate, BadRateLowPassExitsWithExConfigNamingFileLineAndKey) {
  ScratchDir d;
  const auto cfg =
      d.write("gyrod.toml", "[device]\nbackend = \"mock\"\n[filter]\nmodel = \"m.toml\"\nrate_low_pass_hz = 30\n");
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  EXPECT_EQ(gyrod.waitExit(5000ms), std::optional<int>(78));
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find(cfg.string() + ":5"), std::string::npos) << log;
  EXPECT_NE(log.find("filter.rate_low_pass_hz"), std::string::npos) << log;
}

TEST(GyrodRate, SighupAppliesANewModelWithoutLosingTheStreamAndABadOneChangesNothing) {
  ScratchDir d;
  const auto model = d.write("sensor.toml", sensorModel());
  std::string config = rateConfig(d.path(), model);
  const std::string model_line = "model = \"" + model.string() + "\"\n";
  config.erase(config.find(model_line), model_line.size());  // start without a model
  const auto cfg = d.write("gyrod.toml", config);
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient w((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(w.connected()) << readWholeFile(d.path() / "log.txt");
  ASSERT_TRUE(w.readLine());  // VERSION
  ASSERT_TRUE(w.send("{\"cmd\":\"watch\"}\n"));
  const auto before = readRateLines(w, 100);
  ASSERT_EQ(before.size(), 100u);
  EXPECT_EQ(statusRateModel(d.path() / "gyrod.sock"), "bias");
  for (const json& r : before) {
    ASSERT_TRUE(r.contains("rate")) << r.dump();  // raw − the configured bias, from the first sample
    EXPECT_FALSE(r.contains("still")) << r.dump();
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(r["rate"][a].get<double>(), r["raw"][a].get<double>() - kMockBias[a]) << r.dump();
  }

  // A model file that does not parse: the running stream is kept.
  const auto broken = d.write("broken.toml", "[x]\narw_deg_per_sqrt_h = \"fast\"\n");
  std::string with_broken = config;
  with_broken.insert(with_broken.find("[filter]\n") + 9, "model = \"" + broken.string() + "\"\n");
  d.write("gyrod.toml", with_broken);
  gyrod.signal(SIGHUP);
  (void)readRateLines(w, 50);
  EXPECT_EQ(statusRateModel(d.path() / "gyrod.sock"), "bias");
  EXPECT_NE(readWholeFile(d.path() / "log.txt").find("keeping the running filter"), std::string::npos);

  d.write("gyrod.toml", rateConfig(d.path(), model));
  gyrod.signal(SIGHUP);
  std::vector<json> after;
  for (int tries = 0; tries < 20 && (after.empty() || !after.back().contains("still")); ++tries) {
    auto more = readRateLines(w, 50);
    after.insert(after.end(), more.begin(), more.end());
  }
  ASSERT_FALSE(after.empty());
  EXPECT_TRUE(after.back().contains("still")) << after.back().dump();
  EXPECT_EQ(statusRateModel(d.path() / "gyrod.sock"), "model " + model.string());
  EXPECT_EQ(after.back()["seq"].get<std::uint64_t>() - before.back()["seq"].get<std::uint64_t>(), 50 + after.size())
      << "no sample lost across the reloads";
  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(2000ms), std::optional<int>(0)) << readWholeFile(d.path() / "log.txt");
}

TEST(GyrodRate, RateLowPassWithoutAModelIsAConfigError) {
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", "[device]\nbackend = \"mock\"\n[filter]\nrate_low_pass_hz = 5\n");
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  EXPECT_EQ(gyrod.waitExit(5000ms), std::optional<int>(78));
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find(cfg.string() + ":4"), std::string::npos) << log;
  EXPECT_NE(log.find("needs filter.model"), std::string::npos) << log;
}

// The rate estimator is not restarted at a GAP (b̂ is the model's function of temperature and
// time plus a residual that does not need contiguous samples), and the recording holds every
// sample it was fed, in order: the offline stream matches across gaps as well.
namespace {

void expectTheOfflineRateStreamMatchesAcrossGaps(bool accel) {
  ScratchDir d;
  const auto model = d.write("sensor.toml", sensorModel());
  const auto cfg =
      d.write("gyrod.toml", rateConfig(d.path(), model, "[mock.faults]\nfifo_overflow_at_s = [6, 9]\n", accel));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient watcher((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(watcher.connected()) << readWholeFile(d.path() / "log.txt");
  ASSERT_TRUE(watcher.readLine());  // VERSION
  ASSERT_TRUE(watcher.send("{\"cmd\":\"watch\"}\n"));
  std::vector<json> rates;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> gaps;  // first missing seq, count
  while (rates.size() < 700) {
    const auto line = watcher.readLine(20s);
    ASSERT_TRUE(line.has_value()) << readWholeFile(d.path() / "log.txt");
    json j = json::parse(*line);
    if (j["class"] == "GAP") gaps.emplace_back(j["seq"].get<std::uint64_t>(), j["count"].get<std::uint64_t>());
    if (j["class"] == "RATE") rates.push_back(std::move(j));
  }
  gyrod.signal(SIGTERM);
  ASSERT_EQ(gyrod.waitExit(2000ms), std::optional<int>(0)) << readWholeFile(d.path() / "log.txt");
  ASSERT_GE(gaps.size(), 1u);
  // The watcher connected before the first gap (at 6 s), so it saw every GAP: a sample's row in
  // the recording is its seq less the samples lost before it.
  ASSERT_LT(rates.front()["seq"].get<std::uint64_t>(), gaps.front().first);
  const auto rowOf = [&gaps](std::uint64_t seq) {
    std::uint64_t lost = 0;
    for (const auto& [first, count] : gaps) lost += first < seq ? count : 0;
    return static_cast<std::size_t>(seq - lost);
  };
  std::string rec_path;
  for (const auto& e : std::filesystem::directory_iterator(d.path()))
    if (e.path().filename().string().rfind("rec-", 0) == 0) rec_path = e.path().string();
  ASSERT_FALSE(rec_path.empty());
  const auto offline = offlineRate(rec_path, model, d);
  for (const json& r : rates) {
    const std::size_t i = rowOf(r["seq"].get<std::uint64_t>());
    ASSERT_LT(i, offline.size());
    for (int a = 0; a < 3; ++a) ASSERT_EQ(r["rate"][a].get<double>(), offline[i].rate[a]) << "row " << i;
    ASSERT_EQ(r["still"].get<bool>(), offline[i].still) << "row " << i;
  }
  // The recording holds the stream itself (issue 11: recoverable even after a SIGHUP model change
  // or DROPPED rows), and the wall clock of each sample as RATE's `time` gave it.
  const auto recorded = gyrod::recording::readRecordingCsv(rec_path);
  ASSERT_EQ(recorded.size(), offline.size());
  for (const json& r : rates) {
    const std::size_t i = rowOf(r["seq"].get<std::uint64_t>());
    ASSERT_EQ(recorded.t[i], r["t"].get<double>()) << "row " << i;
    ASSERT_EQ(recorded.time[i], r["time"].get<double>()) << "row " << i;
    for (int a = 0; a < 3; ++a) {
      ASSERT_EQ(recorded.rate[a][i], r["rate"][a].get<double>()) << "row " << i;
      ASSERT_EQ(recorded.bias[a][i], r["bias"][a].get<double>()) << "row " << i;
    }
    ASSERT_EQ(recorded.still[i], r["still"].get<bool>() ? 1.0 : 0.0) << "row " << i;
  }
  const auto gap_lines = std::count_if(recorded.lost.begin(), recorded.lost.end(), [](const auto& l) {
    return l.kind == gyrod::recording::LostSamples::Kind::Gap;
  });
  ASSERT_EQ(static_cast<std::size_t>(gap_lines), gaps.size());
  // The recording carries the accel exactly when the device gave it (what the offline still detector used).
  for (const auto& column : recorded.accel_g) EXPECT_EQ(column.size(), accel ? recorded.size() : 0u);
  // And the orientation as RATE published it; `gyroctl attitude --model` recomputes it across the gaps.
  for (const auto& column : recorded.attitude) ASSERT_EQ(column.size(), accel ? recorded.size() : 0u);
  if (accel) {
    for (const json& r : rates) {
      const std::size_t i = rowOf(r["seq"].get<std::uint64_t>());
      const AttitudeRow live = attitudeOf(r);
      for (std::size_t k = 0; k < live.size(); ++k) ASSERT_EQ(recorded.attitude[k][i], live[k]) << "row " << i;
    }
    expectTheAttitudeIsTheOfflineOne(rates, offlineAttitude(rec_path, model, d), rowOf, accel);
  }
}

}  // namespace

TEST(GyrodRate, TheOfflineRateStreamMatchesAcrossGaps) { expectTheOfflineRateStreamMatchesAcrossGaps(true); }

TEST(GyrodRate, WithAccelOffTheOfflineRateStreamMatchesAcrossGaps) {
  expectTheOfflineRateStreamMatchesAcrossGaps(false);
}

TEST(GyrodRate, AModelFileThatIsNotOneExitsWithExConfigNamingItsLine) {
  ScratchDir d;
  const auto model = d.write("sensor.toml", "rate_hz = 50\n[x]\narw_deg_per_sqrt_h = \"fast\"\n");
  const auto cfg =
      d.write("gyrod.toml", "[device]\nbackend = \"mock\"\n[filter]\nmodel = \"" + model.string() + "\"\n");
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  EXPECT_EQ(gyrod.waitExit(5000ms), std::optional<int>(78));
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find(model.string() + ":3"), std::string::npos) << log;
  EXPECT_NE(log.find("filter.model"), std::string::npos) << log;
}
