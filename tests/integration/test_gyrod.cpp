// gyrod end to end: the real binary on the mock backend (virtual clock, faster than real
// time), real socket clients, its own recording checked with gyroctl and the batch code.
#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <thread>

#include "formats/recording_csv.hpp"
#include "gyrod_process.hpp"
#include "processing/allan/allan.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

const char* kBiasText = "-3.34, 1.09, -0.5";

std::string mockConfig(const std::filesystem::path& dir, double speed, const std::string& extra = "") {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[bias]\nsource = \"config\"\nvalues = [" << kBiasText << "]\n"
    << "[filter]\nmean_window = 20\nmean_threshold_dps = 0.3\n"
    << "[filter.kalman]\na = 0.9\nq = 0.0001\nr = 0.01\n"
    << "[socket]\npath = \"" << (dir / "gyrod.sock").string() << "\"\n"
    << "[record]\npath = \"" << (dir / "rec.csv").string() << "\"\nflush_interval_s = 0.1\n"
    << "[mock]\nspeed = " << speed << "\nseed = 5\n"
    << extra;
  return c.str();
}

// Reads lines until `count` RATE lines arrived; GAP lines are kept too.
struct Stream {
  std::vector<json> rates, gaps;
};
Stream readRates(LineClient& c, std::size_t count) {
  Stream s;
  while (s.rates.size() < count) {
    const auto line = c.readLine(20s);
    if (!line) break;
    json j = json::parse(*line);
    if (j["class"] == "RATE") s.rates.push_back(std::move(j));
    if (j["class"] == "GAP") s.gaps.push_back(std::move(j));
  }
  return s;
}

// Connects a client to `sock`, takes its VERSION line and turns watching on.
void startWatching(LineClient& c) {
  ASSERT_TRUE(c.connected());
  ASSERT_TRUE(c.readLine());
  ASSERT_TRUE(c.send("{\"cmd\":\"watch\"}\n"));
}

// Consecutive RATE lines carry consecutive sequence numbers.
void expectContiguous(const std::vector<json>& rates) {
  for (std::size_t i = 1; i < rates.size(); ++i)
    ASSERT_EQ(rates[i]["seq"].get<std::uint64_t>(), rates[i - 1]["seq"].get<std::uint64_t>() + 1) << "line " << i;
}

std::string onlyRecordingFile(const std::filesystem::path& dir) {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().filename().string().rfind("rec-", 0) == 0) files.push_back(e.path().string());
  return files.size() == 1 ? files[0] : std::string();
}

}  // namespace

TEST(Gyrod, StreamFilterAndAllanAgreeWithTheOfflineToolsOnItsOwnRecording) {
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", mockConfig(d.path(), 50.0));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient watcher((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(watcher.connected()) << readWholeFile(d.path() / "log.txt");
  const auto version = json::parse(*watcher.readLine());
  EXPECT_EQ(version["class"], "VERSION");
  ASSERT_TRUE(watcher.send("{\"cmd\":\"watch\",\"enable\":true}\n"));
  const Stream s = readRates(watcher, 2500);
  ASSERT_EQ(s.rates.size(), 2500u);
  EXPECT_TRUE(s.gaps.empty());
  expectContiguous(s.rates);

  LineClient asker((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(asker.readLine());  // VERSION
  asker.send("{\"cmd\":\"allan\"}\n");
  const json allan = json::parse(*asker.readLine());
  ASSERT_EQ(allan["class"], "ALLAN") << allan.dump();

  gyrod.signal(SIGTERM);
  const auto status = gyrod.waitExit(1000ms);
  ASSERT_TRUE(status.has_value()) << "gyrod did not exit within a second of SIGTERM";
  EXPECT_EQ(*status, 0) << readWholeFile(d.path() / "log.txt");

  const std::string rec_path = onlyRecordingFile(d.path());
  ASSERT_FALSE(rec_path.empty());
  const auto rec = gyrod::recording::readRecordingCsv(rec_path);
  ASSERT_GE(rec.size(), s.rates.back()["seq"].get<std::size_t>() + 1);

  // The filtered values equal `gyroctl filter` run on the recording with the same bias
  // and parameters: row i of the recording is sample seq i (no gaps).
  const auto filtered = d.path() / "filtered.csv";
  const auto r = runGyroctl("filter " + rec_path + " -o " + filtered.string() +
                                " --bias=-3.34,1.09,-0.5 --mean-window 20 --mean-threshold 0.3"
                                " --ar-phi 0.9 --kalman-q 0.0001 --kalman-r 0.01",
                            d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  // The filter output's columns (gx_mean, ...) are not a recording: parse it by hand.
  std::ifstream f(filtered);
  std::string line;
  std::getline(f, line);
  ASSERT_EQ(line, "t,gx,gx_mean,gx_kalman,gy,gy_mean,gy_kalman,gz,gz_mean,gz_kalman");
  std::vector<std::array<double, 3>> offline_kalman;
  while (std::getline(f, line)) {
    std::stringstream ls(line);
    std::string field;
    std::vector<double> v;
    while (std::getline(ls, field, ',')) v.push_back(std::stod(field));
    offline_kalman.push_back({v[3], v[6], v[9]});
  }
  std::size_t compared = 0;
  for (const auto& rate : s.rates) {
    const auto seq = rate["seq"].get<std::size_t>();
    for (int a = 0; a < 3; ++a) ASSERT_EQ(rate["kalman"][a].get<double>(), offline_kalman[seq][a]) << "seq " << seq;
    ++compared;
  }
  EXPECT_EQ(compared, 2500u);

  // ALLAN equals the batch overlapping Allan deviation of the recorded samples it covered.
  const auto covered = allan["samples"].get<std::size_t>();
  ASSERT_GT(covered, 100u);
  ASSERT_LE(covered, rec.size());
  const std::vector<double> gx(rec.axes[0].begin(), rec.axes[0].begin() + static_cast<std::ptrdiff_t>(covered));
  const auto& taus = allan["tau"];
  ASSERT_GE(taus.size(), 5u);
  for (std::size_t k = 0; k < taus.size(); ++k) {
    const auto m = static_cast<std::size_t>(std::llround(taus[k].get<double>() * 50.0));
    const double batch = std::sqrt(gyrod::processing::overlappingAllanVariance(gx, m));
    EXPECT_NEAR(allan["adev"]["x"]["raw"][k].get<double>(), batch, 1e-9 * batch) << "m = " << m;
  }
}

TEST(Gyrod, GapsExplainEveryMissingSequenceNumberUnderFaults) {
  ScratchDir d;
  const auto cfg =
      d.write("gyrod.toml", mockConfig(d.path(), 50.0,
                                       "[mock.faults]\nfifo_overflow_at_s = [5.0]\nsilent_reset_at_s = [15.0]\n"
                                       "vanish = [{ at_s = 25, duration_s = 1 }]\n"));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient watcher((d.path() / "gyrod.sock").string());
  ASSERT_TRUE(watcher.connected());
  ASSERT_TRUE(watcher.readLine());
  watcher.send("{\"cmd\":\"watch\"}\n");
  // The watch starts within the first second or so of sensor time; 40 s covers the faults.
  std::vector<json> lines;
  std::uint64_t last_seq = 0;
  while (last_seq < 40 * 50) {
    const auto line = watcher.readLine(20s);
    ASSERT_TRUE(line.has_value()) << readWholeFile(d.path() / "log.txt");
    json j = json::parse(*line);
    if (j["class"] == "RATE") last_seq = j["seq"].get<std::uint64_t>();
    if (j["class"] == "RATE" || j["class"] == "GAP") lines.push_back(std::move(j));
  }
  std::optional<std::uint64_t> expected;
  std::size_t gap_lines = 0;
  std::map<std::string, int> reasons;
  for (const auto& j : lines) {
    if (j["class"] == "GAP") {
      if (expected) {
        EXPECT_EQ(j["seq"].get<std::uint64_t>(), *expected) << j.dump();
      }
      expected = j["seq"].get<std::uint64_t>() + j["count"].get<std::uint64_t>();
      ++gap_lines;
      ++reasons[j["reason"].get<std::string>()];
      continue;
    }
    const auto seq = j["seq"].get<std::uint64_t>();
    if (expected) {
      ASSERT_EQ(seq, *expected) << "a sequence number was skipped without a GAP";
    }
    expected = seq + 1;
  }
  EXPECT_GE(gap_lines, 3u) << readWholeFile(d.path() / "log.txt");
  EXPECT_EQ(reasons.count("fifo_overflow"), 1u);
  EXPECT_EQ(reasons.count("silent_reset"), 1u);
  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(2000ms), std::optional<int>(0));
}

TEST(Gyrod, StalledClientIsDroppedAndTheOthersReceiveEverything) {
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", mockConfig(d.path(), 10.0));
  // 64 KiB client buffers: a stalled watcher fills the kernel's socket buffer and then its
  // own within ~1000 lines; a reading one holds a few pump steps at most (5 lines each).
  std::string text = readWholeFile(cfg);
  text.replace(text.find("[record]"), 0, "client_buffer_kib = 64\n");
  d.write("gyrod.toml", text);
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  const std::string sock = (d.path() / "gyrod.sock").string();
  LineClient stalled(sock);
  ASSERT_TRUE(stalled.connected()) << readWholeFile(d.path() / "log.txt");
  stalled.send("{\"cmd\":\"watch\"}\n");  // and never read again
  std::vector<std::unique_ptr<LineClient>> watchers;
  for (int i = 0; i < 3; ++i) {
    watchers.push_back(std::make_unique<LineClient>(sock));
    ASSERT_TRUE(watchers.back()->readLine());
    watchers.back()->send("{\"cmd\":\"watch\"}\n");
  }
  // The three read concurrently, as independent clients would.
  std::vector<Stream> streams(watchers.size());
  std::vector<std::thread> readers;
  for (std::size_t i = 0; i < watchers.size(); ++i)
    readers.emplace_back([&, i] { streams[i] = readRates(*watchers[i], 2000); });
  for (auto& t : readers) t.join();
  for (const Stream& s : streams) {
    ASSERT_EQ(s.rates.size(), 2000u) << readWholeFile(d.path() / "log.txt");
    expectContiguous(s.rates);
  }
  LineClient asker(sock);
  ASSERT_TRUE(asker.readLine());
  asker.send("{\"cmd\":\"status\"}\n");
  const json status = json::parse(*asker.readLine());
  EXPECT_GE(status["clients_dropped"].get<int>(), 1) << status.dump();
}

// STATUS device_retrying: false from a fresh start, both while the device is brought up and
// once it streams; nothing is being retried.
TEST(Gyrod, AFreshStartIsNotRetrying) {
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", mockConfig(d.path(), 10.0));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  const std::string sock = (d.path() / "gyrod.sock").string();
  LineClient asker(sock);
  ASSERT_TRUE(asker.connected());
  ASSERT_TRUE(asker.readLine());
  asker.send("{\"cmd\":\"status\"}\n");
  const json early = json::parse(*asker.readLine());
  EXPECT_EQ(early["device_retrying"], false) << early.dump();
  LineClient w(sock);
  startWatching(w);
  if (HasFatalFailure()) return;
  ASSERT_EQ(readRates(w, 5).rates.size(), 5u);
  asker.send("{\"cmd\":\"status\"}\n");
  const json streaming = json::parse(*asker.readLine());
  EXPECT_EQ(streaming["device_state"], "streaming") << streaming.dump();
  EXPECT_EQ(streaming["device_retrying"], false) << streaming.dump();
  gyrod.signal(SIGINT);
  EXPECT_EQ(gyrod.waitExit(1000ms), std::optional<int>(0));
}

TEST(Gyrod, MalformedAndOversizedClientLines) {
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", mockConfig(d.path(), 10.0));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  const std::string sock = (d.path() / "gyrod.sock").string();
  LineClient c(sock);
  ASSERT_TRUE(c.connected());
  ASSERT_TRUE(c.readLine());
  c.send("hello\n");
  EXPECT_EQ(json::parse(*c.readLine())["class"], "ERROR");
  c.send("{\"cmd\":\"frobnicate\"}\n");
  EXPECT_EQ(json::parse(*c.readLine())["class"], "ERROR");
  c.send(std::string(5000, 'x') + "\n");
  const auto err = c.readLine();
  ASSERT_TRUE(err.has_value());
  EXPECT_EQ(json::parse(*err)["class"], "ERROR");
  EXPECT_FALSE(c.readLine(2s).has_value());  // dropped
  LineClient after(sock);
  ASSERT_TRUE(after.readLine());
  after.send("{\"cmd\":\"status\"}\n");
  EXPECT_EQ(json::parse(*after.readLine())["class"], "STATUS");
  gyrod.signal(SIGINT);
  EXPECT_EQ(gyrod.waitExit(1000ms), std::optional<int>(0));
}

TEST(Gyrod, BadConfigurationsExitWithExConfigAndNameTheKey) {
  ScratchDir d;
  const auto typo = d.write("typo.toml", "[device]\nbackend = \"mock\"\nrat_hz = 50\n");
  GyrodProcess a({"--config", typo.string()}, d.path() / "a.txt");
  EXPECT_EQ(a.waitExit(5000ms), std::optional<int>(78));
  const std::string a_log = readWholeFile(d.path() / "a.txt");
  EXPECT_NE(a_log.find(typo.string() + ":3"), std::string::npos) << a_log;
  EXPECT_NE(a_log.find("rat_hz"), std::string::npos) << a_log;
  EXPECT_EQ(std::count(a_log.begin(), a_log.end(), '\n'), 1) << a_log;

  const auto bad = d.write("bad.toml", "[device]\nbackend = \"mock\"\nrate_hz = 33\n");
  GyrodProcess b({"--config", bad.string()}, d.path() / "b.txt");
  EXPECT_EQ(b.waitExit(5000ms), std::optional<int>(78));
  EXPECT_NE(readWholeFile(d.path() / "b.txt").find("device.rate_hz"), std::string::npos);

  const auto section = d.write("section.toml", "[devise]\nbackend = \"mock\"\n");
  GyrodProcess c({"--config", section.string()}, d.path() / "c.txt");
  EXPECT_EQ(c.waitExit(5000ms), std::optional<int>(78));
  EXPECT_NE(readWholeFile(d.path() / "c.txt").find("devise"), std::string::npos);
}

TEST(Gyrod, SighupReloadsTheFilterWithoutLosingTheStream) {
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", mockConfig(d.path(), 20.0));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient w((d.path() / "gyrod.sock").string());
  startWatching(w);
  if (HasFatalFailure()) return;
  Stream before = readRates(w, 200);
  ASSERT_EQ(before.rates.size(), 200u);
  std::string text = readWholeFile(cfg);
  text.replace(text.find("mean_window = 20"), 16, "mean_window = 5 ");
  d.write("gyrod.toml", text);
  gyrod.signal(SIGHUP);
  Stream after = readRates(w, 1000);
  ASSERT_EQ(after.rates.size(), 1000u);
  EXPECT_TRUE(after.gaps.empty());
  EXPECT_EQ(after.rates.front()["seq"].get<std::uint64_t>(), before.rates.back()["seq"].get<std::uint64_t>() + 1);
  expectContiguous(after.rates);
  EXPECT_NE(readWholeFile(d.path() / "log.txt").find("filter reloaded"), std::string::npos);
  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(1000ms), std::optional<int>(0));
}

// A SIGHUP whose file would not start gyrod changes nothing: one error line naming file:line
// and key, the stream goes on. The same file at start-up exits 78.
TEST(Gyrod, SighupWithAMissingModelKeepsTheRunningSettings) {
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", mockConfig(d.path(), 20.0));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient w((d.path() / "gyrod.sock").string());
  startWatching(w);
  if (HasFatalFailure()) return;
  Stream before = readRates(w, 100);
  ASSERT_EQ(before.rates.size(), 100u);
  std::string text = readWholeFile(cfg);
  const auto missing = (d.path() / "gone-model.toml").string();
  text.replace(text.find("mean_window = 20"), 16, "model = \"" + missing + "\"\nmean_window = 5");
  d.write("gyrod.toml", text);
  gyrod.signal(SIGHUP);
  Stream after = readRates(w, 300);
  ASSERT_EQ(after.rates.size(), 300u);
  EXPECT_TRUE(after.gaps.empty());
  expectContiguous(after.rates);
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_EQ(log.find("filter reloaded"), std::string::npos) << log;
  const auto error = log.find("SIGHUP: keeping the running filter: " + cfg.string() + ":8: key 'filter.model': ");
  ASSERT_NE(error, std::string::npos) << log;
  EXPECT_NE(log.find("No such file or directory", error), std::string::npos) << log;
  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(1000ms), std::optional<int>(0));

  GyrodProcess again({"--config", cfg.string()}, d.path() / "again.txt");
  EXPECT_EQ(again.waitExit(5000ms), std::optional<int>(78));
  EXPECT_NE(readWholeFile(d.path() / "again.txt").find(cfg.string() + ":8: key 'filter.model'"), std::string::npos);
}

// A sensor stuck at one value (Linux's i2c-stub does this, tests/vm): every still period is
// refused, and the log says why in a user's words, with no internal function name in it.
TEST(Gyrod, AConstantSignalIsLoggedWithoutInternalNames) {
  ScratchDir d;
  std::string csv = "t,gx,gy,gz,temp\n";
  for (int i = 0; i < 1000; ++i) csv += std::to_string(i * 0.02) + ",0.5,-0.25,1.5,30\n";
  const auto replay = d.write("stuck.csv", csv);
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[bias]\nsource = \"estimate\"\nstill_seconds = 2\n"
    << "[socket]\npath = \"" << (d.path() / "gyrod.sock").string() << "\"\n"
    << "[mock]\nspeed = 20\nsource = \"replay\"\nreplay_file = \"" << replay.string() << "\"\n";
  const auto cfg = d.write("gyrod.toml", c.str());
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient w((d.path() / "gyrod.sock").string());
  startWatching(w);
  if (HasFatalFailure()) return;
  ASSERT_EQ(readRates(w, 350).rates.size(), 350u) << readWholeFile(d.path() / "log.txt");  // 3 still periods
  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(1000ms), std::optional<int>(0));
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find("the still period cannot identify the filter on axis x (the AR model fit needs a series that "
                     "varies; this one is constant"),
            std::string::npos)
      << log;
  static const std::regex internal_name(
      R"(\b([a-z][a-z0-9_]*[A-Z]\w*|[A-Z][a-z0-9_]+[A-Z]\w*|[A-Za-z_]\w*(::\w+)+)(\(\))?: |\w\(\): )");
  EXPECT_FALSE(std::regex_search(log, internal_name)) << log;
}

// A recording at 100.31 Hz (a real record's rate, which divides neither internal rate) replays
// at its own rate: the mock's chip clock runs 3100 ppm fast, so the 50 Hz the daemon asks for
// comes out at 50.155 Hz. Each time the recording ends, the log says that it starts over.
TEST(Gyrod, AReplayRunsAtTheRecordingsOwnRateAndSaysWhenItStartsOver) {
  ScratchDir d;
  constexpr double kRecordedRateHz = 100.31;
  std::string csv = "t,gx,gy,gz,temp\n";
  char line[128];
  for (int i = 0; i < 200; ++i) {  // 2 s: the replay loops within the test
    std::snprintf(line, sizeof line, "%.17g,%.2f,0.25,-0.5,30\n", i / kRecordedRateHz, 0.1 * (i % 7));
    csv += line;
  }
  const auto replay = d.write("real-rate.csv", csv);
  const auto cfg = d.write(
      "gyrod.toml", mockConfig(d.path(), 10.0, "source = \"replay\"\nreplay_file = \"" + replay.string() + "\"\n"));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  const std::string sock = (d.path() / "gyrod.sock").string();
  LineClient w(sock);
  startWatching(w);
  if (HasFatalFailure()) return;
  const Stream s = readRates(w, 400);  // 8 s of the sensor's time: the 2 s recording four times
  ASSERT_EQ(s.rates.size(), 400u) << readWholeFile(d.path() / "log.txt");
  const double span = s.rates.back()["t"].get<double>() - s.rates[100]["t"].get<double>();
  EXPECT_NEAR(299.0 / span, 50.0 * kRecordedRateHz / 100.0, 0.02) << "RATE t spacing";
  LineClient asker(sock);
  ASSERT_TRUE(asker.readLine());
  asker.send("{\"cmd\":\"status\"}\n");
  const json status = json::parse(*asker.readLine());
  EXPECT_NEAR(status["rate"].get<double>(), 50.0 * kRecordedRateHz / 100.0, 0.02) << status.dump();
  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(2000ms), std::optional<int>(0));
  const std::string log = readWholeFile(d.path() / "log.txt");
  EXPECT_NE(log.find("ppm to replay at the recording's rate"), std::string::npos) << log;
  EXPECT_NE(log.find("the replay of " + replay.string() + " reached its end (200 samples); starting over (pass 2)"),
            std::string::npos)
      << log;
}

TEST(Gyrod, UnknownSocketGroupAndBadReplayFileExitWithExConfig) {
  ScratchDir d;
  std::string text = mockConfig(d.path(), 20.0);
  text.replace(text.find("[record]"), 8, "group = \"no-such-group-gyrod\"\n[record]");
  const auto group = d.write("group.toml", text);
  GyrodProcess a({"--config", group.string()}, d.path() / "a.txt");
  EXPECT_EQ(a.waitExit(5000ms), std::optional<int>(78));
  const std::string a_log = readWholeFile(d.path() / "a.txt");
  EXPECT_NE(a_log.find("key 'socket.group': no such group on this system (got \"no-such-group-gyrod\")"),
            std::string::npos)
      << a_log;
  EXPECT_EQ(std::count(a_log.begin(), a_log.end(), '\n'), 1) << a_log;

  const auto csv = d.write("bad.csv", "t,gx,gy,gz,temp\n0,1,2,3,25\n0.02,1,2,oops,25\n");
  const auto replay = d.write(
      "replay.toml", mockConfig(d.path(), 20.0, "source = \"replay\"\nreplay_file = \"" + csv.string() + "\"\n"));
  GyrodProcess b({"--config", replay.string()}, d.path() / "b.txt");
  EXPECT_EQ(b.waitExit(5000ms), std::optional<int>(78));
  const std::string b_log = readWholeFile(d.path() / "b.txt");
  EXPECT_NE(b_log.find("key 'mock.replay_file': " + csv.string() + ":3: "), std::string::npos) << b_log;
}

TEST(Gyrod, RecordingReadsCleanlyAfterKillDashNine) {
  ScratchDir d;
  const auto cfg = d.write("gyrod.toml", mockConfig(d.path(), 20.0));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "log.txt");
  LineClient w((d.path() / "gyrod.sock").string());
  startWatching(w);
  if (HasFatalFailure()) return;
  const Stream s = readRates(w, 1500);
  ASSERT_EQ(s.rates.size(), 1500u);
  const auto seen = s.rates.back()["seq"].get<std::uint64_t>();
  gyrod.signal(SIGKILL);
  ASSERT_TRUE(gyrod.waitExit(2000ms).has_value());
  const std::string path = onlyRecordingFile(d.path());
  ASSERT_FALSE(path.empty());
  const auto rec = gyrod::recording::readRecordingCsv(path);  // throws on a torn line
  // Loss bounded by the flush interval: 0.1 s of real time at 20x speed and 50 Hz is 100
  // samples; allow a second flush period of scheduling slack on a loaded machine.
  EXPECT_GE(rec.size() + 200, seen + 1) << "recorded " << rec.size() << ", seen " << seen;
  const std::string text = readWholeFile(path);
  EXPECT_EQ(text.back(), '\n');
}
