// gyrod keeps what its rate stream learns in its state directory (docs/calibration-state.md):
// after two hours of a 15 °C warm-up on the accelerated mock, a restarted gyrod's first sample
// has the bias the first run had learned, where a gyrod without the state starts from the
// sensor model's; a state file that is corrupt or was learned with another model is refused in
// one line, kept aside, and gyrod starts as if there were none.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "formats/calibration_state.hpp"
#include "formats/recording_csv.hpp"
#include "gyrod_process.hpp"
#include "tools/run_command.hpp"

using namespace gyrod::test;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

// The mock's chip: bias 0.5 °/s on every axis in the model, and a temperature coupling the model
// does not have (it states the coefficient as 0 ± 0.05 °/s per °C), so the residual filter has
// to learn it from the still samples of a warm-up.
constexpr std::array<double, 3> kTrueCoefficient = {0.03, -0.02, 0.015};
constexpr double kModelBiasDps = 0.5;
constexpr double kReferenceC = 25.0;         // the simulator's coupling is zero here
constexpr double kTemperatureNoiseC = 0.02;  // of each die temperature reading

// The sensor model; `start_c` and `final_c` are the temperature the mock plays (the board's,
// not the calibration: the state's fingerprint does not cover them).
std::string sensorModel(double start_c, double final_c, double bias_dps = kModelBiasDps) {
  std::ostringstream m;
  m << "rate_hz = 50\n[temperature]\nstart_c = " << start_c << "\nfinal_c = " << final_c
    << "\ntime_constant_s = 900.0\nnoise_std_c = " << kTemperatureNoiseC << "\n";
  for (const char* axis : {"x", "y", "z"}) {
    m << "[" << axis << "]\nquantization_urad = 0.1663\narw_deg_per_sqrt_h = 0.95164\n"
      << "bias_instability_deg_per_h = 0.60565\nrrw_deg_per_h_sqrt_h = 0.07759\nbias_dps = " << bias_dps << "\n"
      << "[" << axis << ".calibration]\nbias_std_dps = 0.02\ntemperature_coefficient_dps_per_c = 0.0\n"
      << "temperature_coefficient_std_dps_per_c = 0.05\ntemperature_reference_c = " << kReferenceC << "\n";
  }
  return m.str();
}

std::string config(const ScratchDir& d, const std::filesystem::path& model, double speed, bool record) {
  std::ostringstream c;
  c << "[device]\nbackend = \"mock\"\nrate_hz = 50\n"
    << "[filter]\nmodel = \"" << model.string() << "\"\n"
    << "[socket]\npath = \"" << (d.path() / "gyrod.sock").string() << "\"\n"
    << "[state]\ndirectory = \"" << (d.path() / "state").string() << "\"\n"
    << "[mock]\nspeed = " << speed << "\nseed = 3\ntemperature_coefficient_dps_per_c = [" << kTrueCoefficient[0] << ", "
    << kTrueCoefficient[1] << ", " << kTrueCoefficient[2] << "]\n";
  if (record) c << "[record]\npath = \"" << (d.path() / "rec").string() << "/\"\nflush_interval_s = 0.1\n";
  return c.str();
}

// The chip's bias at true temperature T (its drift terms, below a mdps over these times, aside).
double trueBias(std::size_t axis, double temperature_c) {
  return kModelBiasDps + kTrueCoefficient[axis] * (temperature_c - kReferenceC);
}
// The mock's die temperature (the model's curve, without its 0.02 °C noise) t s after its start.
double warmUpTemperature(double t_s) { return 40.0 - 15.0 * std::exp(-t_s / 900.0); }

double numberAfter(const std::string& line, const std::string& key) {
  const auto at = line.find("\"" + key + "\":");
  return at == std::string::npos ? std::nan("") : std::strtod(line.c_str() + at + key.size() + 3, nullptr);
}

// The published bias of the first second recorded (50 samples), first sample first.
struct FirstSample {
  std::array<std::vector<double>, 3> bias;
};
FirstSample firstRecordedSample(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(folder)) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  EXPECT_FALSE(files.empty());
  FirstSample f;
  if (files.empty()) return f;
  const auto rec = gyrod::recording::readRecordingCsv(files.front().string());
  EXPECT_FALSE(rec.bias[0].empty());
  if (rec.bias[0].empty()) return f;
  for (std::size_t a = 0; a < 3; ++a)
    f.bias[a].assign(rec.bias[a].begin(), rec.bias[a].begin() + std::min<std::ptrdiff_t>(50, rec.bias[a].size()));
  return f;
}

// Runs gyrod on `model` until `seconds` of data, recording, and returns the first sample.
FirstSample shortRun(const ScratchDir& d, const std::filesystem::path& model, const std::string& log_name) {
  std::filesystem::remove_all(d.path() / "rec");
  std::filesystem::create_directories(d.path() / "rec");
  const auto cfg = d.write("short.toml", config(d, model, 50.0, true));
  GyrodProcess gyrod({"--config", cfg.string()}, d.path() / log_name);
  LineClient watcher((d.path() / "gyrod.sock").string());
  EXPECT_TRUE(watcher.connected());
  watcher.readLine();  // VERSION
  watcher.send("{\"cmd\":\"watch\"}\n");
  for (int rates = 0; rates < 100;) {
    const auto line = watcher.readLine(20s);
    if (!line) break;
    if (line->find("\"RATE\"") != std::string::npos) ++rates;
  }
  gyrod.signal(SIGTERM);
  EXPECT_EQ(gyrod.waitExit(5000ms), std::optional<int>(0)) << readWholeFile(d.path() / log_name);
  return firstRecordedSample(d.path() / "rec");
}

// The comma-separated fields of each line.
std::vector<std::vector<std::string>> csvFields(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> fields;
    std::istringstream ls(line);
    for (std::string f; std::getline(ls, f, ',');) fields.push_back(f);
    rows.push_back(std::move(fields));
  }
  return rows;
}
std::size_t columnOf(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  EXPECT_NE(it, names.end()) << name;
  return static_cast<std::size_t>(it - names.begin());
}

std::size_t linesContaining(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  std::istringstream s(text);
  for (std::string line; std::getline(s, line);) n += line.find(what) != std::string::npos;
  return n;
}

}  // namespace

TEST(GyrodCalibrationState, ARestartedGyrodStartsFromTheBiasItHadLearned) {
  ScratchDir d;
  std::filesystem::create_directories(d.path() / "state");
  const auto warming = d.write("warming.toml", sensorModel(25.0, 40.0));
  // Two hours of data at rest through the warm-up (25 → 40 °C, τ = 15 min); the watcher keeps
  // the bias error of the last minute before the stop (lines it could not take are skipped:
  // GAPs).
  const auto cfg = d.write("gyrod.toml", config(d, warming, 400.0, false));
  std::array<double, 3> squared_error{};
  std::size_t last_minute = 0;
  {
    GyrodProcess gyrod({"--config", cfg.string()}, d.path() / "run1.txt");
    // A watcher of the whole stream could not keep up with 400x real time (gyrod drops a client
    // that does not read), so it joins near the end: STATUS counts the samples.
    for (std::uint64_t samples = 0; samples < 7100 * 50;) {
      std::this_thread::sleep_for(50ms);
      LineClient asker((d.path() / "gyrod.sock").string());
      ASSERT_TRUE(asker.connected()) << readWholeFile(d.path() / "run1.txt");
      ASSERT_TRUE(asker.readLine());  // VERSION
      ASSERT_TRUE(asker.send("{\"cmd\":\"status\"}\n"));
      const auto status = asker.readLine(10s);
      ASSERT_TRUE(status.has_value()) << readWholeFile(d.path() / "run1.txt");
      const json j = json::parse(*status);
      samples = j.value("samples", std::uint64_t{0});
      ASSERT_TRUE(j.contains("calibration_state")) << *status;
      EXPECT_EQ(j["calibration_state"]["file"], (d.path() / "state" / "calibration.toml").string());
      EXPECT_EQ(j["calibration_state"]["restored"], false);
    }
    LineClient watcher((d.path() / "gyrod.sock").string());
    ASSERT_TRUE(watcher.connected()) << readWholeFile(d.path() / "run1.txt");
    ASSERT_TRUE(watcher.readLine());  // VERSION
    // Every 10th sample: 2000 lines a second at 400x, which the watcher takes with room to spare
    // even when it is slowed (ASan + UBSan: a watcher of every sample fell 450 lines behind and
    // was dropped).
    ASSERT_TRUE(watcher.send("{\"cmd\":\"watch\",\"decimate\":10}\n"));
    double t0 = std::nan("");
    while (true) {
      const auto line = watcher.readLine(30s);
      ASSERT_TRUE(line.has_value()) << readWholeFile(d.path() / "run1.txt");
      if (line->find("\"RATE\"") == std::string::npos) continue;
      const double t = numberAfter(*line, "t");
      if (std::isnan(t0)) t0 = t - numberAfter(*line, "seq") / 50.0;  // the mock's start
      if (t - t0 < 7140.0) continue;
      const json j = json::parse(*line);
      for (std::size_t a = 0; a < 3; ++a)
        squared_error[a] += std::pow(j["bias"][a].get<double>() - trueBias(a, warmUpTemperature(t - t0)), 2);
      ++last_minute;
      if (t - t0 >= 7200.0) break;
    }
    gyrod.signal(SIGTERM);
    ASSERT_EQ(gyrod.waitExit(5000ms), std::optional<int>(0)) << readWholeFile(d.path() / "run1.txt");
  }
  ASSERT_GT(last_minute, 250u);  // of the 300 a minute brings
  const std::string log1 = readWholeFile(d.path() / "run1.txt");
  EXPECT_EQ(linesContaining(log1, "calibration state: none yet at"), 1u) << log1;
  EXPECT_EQ(linesContaining(log1, "calibration state: written to"), 1u) << log1;
  const gyrod::formats::CalibrationState state =
      gyrod::formats::readCalibrationStateToml((d.path() / "state" / "calibration.toml").string());
  EXPECT_GE(state.data_time_s, 7200.0);
  for (std::size_t a = 0; a < 3; ++a)  // it learned the coupling the model did not have
    EXPECT_NEAR(state.residual.axes[a].slope_dps_per_c, kTrueCoefficient[a], 0.002) << "axis " << a;

  // Restarted with the board still warm (the model's temperature now starts at 40 °C; its
  // calibration, and so the state's fingerprint, unchanged).
  const auto warm = d.write("warm.toml", sensorModel(40.0, 40.0));
  const FirstSample restarted = shortRun(d, warm, "run2.txt");
  const std::string log2 = readWholeFile(d.path() / "run2.txt");
  EXPECT_EQ(linesContaining(log2, "calibration state: restored from"), 1u) << log2;
  for (std::size_t a = 0; a < 3; ++a) {
    ASSERT_EQ(restarted.bias[a].size(), 50u);
    const double before = std::sqrt(squared_error[a] / static_cast<double>(last_minute));
    const double first = std::fabs(restarted.bias[a].front() - trueBias(a, 40.0));
    double first_second = 0.0;
    for (double b : restarted.bias[a]) first_second += std::pow(b - trueBias(a, 40.0), 2) / 50.0;
    first_second = std::sqrt(first_second);
    const double from_model = std::fabs(kModelBiasDps - trueBias(a, 40.0));
    std::printf(
        "axis %zu: bias error after the restart %.5f deg/s at the first sample, %.5f RMS over the first "
        "second; RMS over the last minute before it %.5f; from the model alone %.4f\n",
        a, first, first_second, before, from_model);
    // The first sample's bias takes one temperature reading (the stream smooths them over 1 s
    // from then on), whose noise times the learned slope is added to what the state carries:
    // 0.3 mdps at 1σ on z, as much as the stream's whole error before the stop.
    const double one_reading = 3.0 * std::fabs(state.residual.axes[a].slope_dps_per_c) * kTemperatureNoiseC;
    EXPECT_LE(first, 2.0 * before + one_reading) << "axis " << a;
    EXPECT_LE(first_second, 2.0 * before + one_reading) << "axis " << a;
    EXPECT_LE(first, 0.01 * from_model) << "axis " << a;
  }

  // The recording says which state the stream started from, and `gyroctl filter --model`
  // recomputes its rate and bias bit for bit from it.
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(d.path() / "rec")) files.push_back(e.path());
  ASSERT_EQ(files.size(), 1u);
  const std::string header = readWholeFile(files.front()).substr(0, 4096);
  EXPECT_NE(header.find("# calibration-state still_samples = "), std::string::npos) << header;
  const auto offline = d.path() / "offline.csv";
  const auto r =
      runGyroctl("filter " + files.front().string() + " -o " + offline.string() + " --model " + warm.string() +
                     " --rate 50 --bias=0,0,0 --ar-phi 0.9 --kalman-q 0.0001 --kalman-r 0.01",
                 d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.err.find("the rate stream starts from the calibration state gyrod started from"), std::string::npos)
      << r.err;
  const auto recorded = gyrod::recording::readRecordingCsv(files.front().string());
  const std::vector<std::vector<std::string>> recomputed = csvFields(readWholeFile(offline));
  ASSERT_EQ(recomputed.size(), recorded.rate[0].size() + 1);  // the column line, then one row per sample
  for (std::size_t a = 0; a < 3; ++a) {
    const std::string axis = std::string("g") + "xyz"[a];
    const std::size_t rate_column = columnOf(recomputed.front(), axis + "_rate");
    const std::size_t bias_column = columnOf(recomputed.front(), axis + "_bias");
    for (std::size_t i = 0; i < recorded.rate[a].size(); ++i) {
      ASSERT_EQ(std::stod(recomputed[i + 1].at(bias_column)), recorded.bias[a][i]) << axis << " row " << i;
      ASSERT_EQ(std::stod(recomputed[i + 1].at(rate_column)), recorded.rate[a][i]) << axis << " row " << i;
    }
  }

  // Without the state, the same restart starts from the model's bias: 0.5 °/s exactly.
  std::filesystem::rename(d.path() / "state" / "calibration.toml", d.path() / "learned.toml");
  const FirstSample without = shortRun(d, warm, "run3.txt");
  for (std::size_t a = 0; a < 3; ++a) EXPECT_EQ(without.bias[a].at(0), kModelBiasDps) << "axis " << a;
}

TEST(GyrodCalibrationState, ACorruptOrForeignStateIsRefusedInOneLineAndGyrodStartsWithoutIt) {
  ScratchDir d;
  std::filesystem::create_directories(d.path() / "state");
  const auto model = d.write("model.toml", sensorModel(40.0, 40.0));
  const auto state_file = d.path() / "state" / "calibration.toml";
  gyrod::formats::CalibrationState foreign;
  foreign.model = "0123456789abcdef";  // learned with another bias model
  foreign.rate_hz = 50.0;
  foreign.residual.axes[0] = {0.3, 0.0, 1e-4, 0.0, 1e-6};
  struct Case {
    std::string name, text, says;
  };
  const std::vector<Case> cases = {
      {"corrupt", "format = \"gyrod-calibration-state\"\nversion = 1\nmodel = \x01\n", state_file.string() + ":3:"},
      {"foreign", gyrod::formats::calibrationStateToToml(foreign), "learned with another sensor model"},
      {"a directory", "", "not used"},
  };
  for (const Case& c : cases) {
    std::filesystem::remove_all(state_file);
    if (c.name == "a directory")
      std::filesystem::create_directories(state_file);
    else
      d.write("state/calibration.toml", c.text);
    const std::string log_name = "log-" + std::to_string(&c - cases.data()) + ".txt";
    const FirstSample first = shortRun(d, model, log_name);
    const std::string log = readWholeFile(d.path() / log_name);
    EXPECT_EQ(linesContaining(log, "calibration state: " + state_file.string()), 1u) << c.name << "\n" << log;
    EXPECT_EQ(linesContaining(log, c.says), 1u) << c.name << "\n" << log;
    for (std::size_t a = 0; a < 3; ++a) EXPECT_EQ(first.bias[a].at(0), kModelBiasDps) << c.name << " axis " << a;
    // What a refused file held is kept beside it, not overwritten by this run's state.
    const auto aside = state_file.string() + ".refused";
    if (c.name == "a directory") {
      EXPECT_FALSE(std::filesystem::exists(aside)) << c.name;
    } else {
      EXPECT_EQ(readWholeFile(aside), c.text) << c.name;
      EXPECT_NE(log.find("(kept as " + aside + ")"), std::string::npos) << c.name << "\n" << log;
      std::filesystem::remove(aside);
    }
  }
}
