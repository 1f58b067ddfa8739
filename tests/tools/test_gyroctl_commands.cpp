// gyroctl analyze / filter / import on files whose truth is known.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <vector>

#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;
using nlohmann::json;

namespace {

std::vector<std::vector<double>> parseCsv(const std::string& text, std::vector<std::string>& header) {
  std::stringstream ss(text);
  std::string line;
  std::getline(ss, line);
  header.clear();
  {
    std::stringstream hs(line);
    std::string name;
    while (std::getline(hs, name, ',')) header.push_back(name);
  }
  std::vector<std::vector<double>> cols(header.size());
  while (std::getline(ss, line)) {
    std::stringstream ls(line);
    std::string field;
    for (std::size_t c = 0; c < header.size() && std::getline(ls, field, ','); ++c) cols[c].push_back(std::stod(field));
  }
  return cols;
}

}  // namespace

TEST(GyroctlAnalyze, WhiteNoiseJsonHasEveryTableAndTheRightArw) {
  ScratchDir d;
  const double rate = 50.0, sigma = 0.2;
  const std::size_t n = 30000;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, sigma);
  std::string csv = "t,gx,temp\n";
  char buf[96];
  for (std::size_t i = 0; i < n; ++i) {
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,25\n", static_cast<double>(i) / rate, 1.5 + noise(rng));
    csv += buf;
  }
  const auto f = d.write("white.csv", csv);
  const auto r = runGyroctl("analyze " + f.string() + " --json", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const json doc = json::parse(r.out);
  EXPECT_NEAR(doc["rate_hz"].get<double>(), rate, 1e-9 * rate);  // median spacing of t, rounded text
  EXPECT_EQ(doc["samples"].get<std::size_t>(), n);
  const auto& gx = doc["axes"]["gx"];
  EXPECT_NEAR(gx["tests"]["mean"].get<double>(), 1.5, 5 * sigma / std::sqrt(double(n)));
  EXPECT_FALSE(gx["tests"]["zero_mean"].get<bool>());
  for (const char* key : {"reverse_arrangements_u", "stationary", "chi2", "chi2_dof", "normal"})
    EXPECT_TRUE(gx["tests"].contains(key)) << key;
  ASSERT_GE(gx["allan"].size(), 10u);
  EXPECT_NEAR(gx["allan"][0]["tau_s"].get<double>(), 1.0 / rate, 1e-12);
  EXPECT_EQ(gx["allan"][0]["m"].get<int>(), 1);
  EXPECT_EQ(gx["allan"][0]["n"].get<std::size_t>(), n - 1);  // M − 2m + 1 with m = 1
  // White rate noise of σ at τ0: N = σ·√τ0 [°/√s] = 60·σ·√τ0 [°/√h].
  const double n_true = 60.0 * sigma * std::sqrt(1.0 / rate);
  EXPECT_NEAR(gx["noise"]["arw_deg_per_sqrt_h"].get<double>(), n_true, 0.05 * n_true);
  EXPECT_EQ(gx["ar"].size(), 3u);
  EXPECT_EQ(gx["ar"][2]["phi"].size(), 3u);
  EXPECT_GE(gx["ar_order_aic"].get<int>(), 1);
  const double var_raw = gx["variance"]["raw"].get<double>();
  EXPECT_NEAR(var_raw, sigma * sigma, 0.05 * sigma * sigma);
  EXPECT_LT(gx["variance"]["kalman"].get<double>(), gx["variance"]["mean"].get<double>());
  EXPECT_LT(gx["variance"]["mean"].get<double>(), var_raw);
  EXPECT_GT(gx["peak_ratio"].get<double>(), 0.0);
  EXPECT_LT(gx["peak_ratio"].get<double>(), 1.0);
  EXPECT_LT(gx["noise_after_kalman"]["arw_deg_per_sqrt_h"].get<double>(), n_true);
}

// With two cores the axes are analysed two at a time, each in a workspace of its own (one in
// the time column's memory, one in the temperature's): every axis must come out as it does
// analysed alone, with and without --write-model (which keeps the columns).
TEST(GyroctlAnalyze, AxesAnalysedTogetherAreTheSameAsEachAlone) {
  ScratchDir d;
  const double rate = 50.0;
  const std::size_t n = 20000;
  std::mt19937_64 rng(23);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::string csv = "t,gx,gy,gz,temp\n";
  char buf[160];
  double walk = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    walk += 0.002 * noise(rng);
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g,%.17g,%.6f\n", static_cast<double>(i) / rate,
                  0.5 + 0.1 * noise(rng), -0.2 + 0.3 * noise(rng) + walk, 0.05 * noise(rng),
                  30.0 + 1e-4 * static_cast<double>(i));
    csv += buf;
  }
  const auto f = d.write("three.csv", csv);
  const auto all = runGyroctl("analyze " + f.string() + " --json", d.path());
  ASSERT_EQ(all.exit_status, 0) << all.err;
  const auto kept =
      runGyroctl("analyze " + f.string() + " --json --write-model " + (d.path() / "m.toml").string(), d.path());
  ASSERT_EQ(kept.exit_status, 0) << kept.err;
  const json together = json::parse(all.out), together_kept = json::parse(kept.out);
  ASSERT_EQ(together["axes"].size(), 3u);
  for (const char* axis : {"gx", "gy", "gz"}) {
    const auto alone = runGyroctl("analyze " + f.string() + " --json --axis " + axis, d.path());
    ASSERT_EQ(alone.exit_status, 0) << alone.err;
    const json one = json::parse(alone.out)["axes"][axis];
    ASSERT_FALSE(one.is_null()) << axis;
    EXPECT_EQ(together["axes"][axis], one) << axis;
    EXPECT_EQ(together_kept["axes"][axis], one) << axis;
  }
  // The axes differ, so an axis's table put in another's place would show above.
  EXPECT_NE(together["axes"]["gx"], together["axes"]["gy"]);
}

TEST(GyroctlAnalyze, BareNumbersUseTheGivenRateAndExplicitTaus) {
  ScratchDir d;
  std::mt19937_64 rng(12);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::string csv;
  for (int i = 0; i < 2000; ++i) csv += std::to_string(noise(rng)) + "\n";
  const auto f = d.write("bare.txt", csv);
  const auto r = runGyroctl("analyze " + f.string() + " --rate 10 --taus 0.1,1,10 --json", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const json doc = json::parse(r.out);
  const auto& allan = doc["axes"]["x"]["allan"];
  ASSERT_EQ(allan.size(), 3u);
  EXPECT_EQ(allan[0]["m"].get<int>(), 1);
  EXPECT_EQ(allan[1]["m"].get<int>(), 10);
  EXPECT_EQ(allan[2]["m"].get<int>(), 100);
}

TEST(GyroctlAnalyze, NoDetrendLetsTheAllanCurveSeeARamp) {
  ScratchDir d;
  // A pure ramp of 0.001 °/s per s: R = 0.001·3600² °/h² = 12960 °/h².
  std::string csv = "t,gx\n";
  char buf[64];
  for (int i = 0; i < 5000; ++i) {
    std::snprintf(buf, sizeof buf, "%.17g,%.17g\n", i / 50.0, 0.001 * (i / 50.0));
    csv += buf;
  }
  const auto f = d.write("ramp.csv", csv);
  const auto raw = runGyroctl("analyze " + f.string() + " --json --no-detrend", d.path());
  ASSERT_EQ(raw.exit_status, 0) << raw.err;
  const double r_raw = json::parse(raw.out)["axes"]["gx"]["noise"]["rate_ramp_deg_per_h2"].get<double>();
  EXPECT_NEAR(r_raw, 12960.0, 0.02 * 12960.0);
  const auto detrended = runGyroctl("analyze " + f.string() + " --json", d.path());
  ASSERT_EQ(detrended.exit_status, 0) << detrended.err;
  EXPECT_LT(json::parse(detrended.out)["axes"]["gx"]["noise"]["rate_ramp_deg_per_h2"].get<double>(), 1e-3 * 12960.0);
}

TEST(GyroctlAnalyze, TextReportPrintsThePapersTables) {
  ScratchDir d;
  std::mt19937_64 rng(13);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::string csv = "gx,gy,gz\n";
  for (int i = 0; i < 3000; ++i)
    csv += std::to_string(noise(rng)) + "," + std::to_string(noise(rng)) + "," + std::to_string(noise(rng)) + "\n";
  const auto f = d.write("three.csv", csv);
  const auto r = runGyroctl("analyze " + f.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  for (const char* s : {"== gx ==", "== gy ==", "== gz ==", "Table 2", "Table 3", "Table 4", "reverse arrangements",
                        "Kalman on AR(1)", "Peak after Kalman"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
}

// The filter's output must be reproducible exactly by any other implementation: here a
// plain re-implementation of the mean filter and the Kalman recursion from their
// definitions, fed the output's own gx column, with A, Q, R given on the command line.
TEST(GyroctlFilter, OutputMatchesAPlainReimplementationExactly) {
  ScratchDir d;
  std::mt19937_64 rng(14);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::string csv = "t,gx,gy\n";
  char buf[96];
  for (int i = 0; i < 3000; ++i) {
    double x = noise(rng);
    if (u(rng) < 0.02) x += (u(rng) < 0.5 ? -1.0 : 1.0) * 2.0;  // gross errors
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g\n", i / 50.0, x + 0.3, noise(rng));
    csv += buf;
  }
  const auto in = d.write("in.csv", csv);
  const auto out = d.path() / "out.csv";
  const double A = -0.2855, Q = 0.0577, R = 0.0667;
  const std::size_t L = 20;
  const double thr = 0.3;
  const auto r =
      runGyroctl("filter " + in.string() + " -o " + out.string() +
                     " --mean-window 20 --mean-threshold 0.3 --ar-phi -0.2855 --kalman-q 0.0577 --kalman-r 0.0667",
                 d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::vector<std::string> header;
  const auto cols = parseCsv(readWholeFile(out), header);
  ASSERT_EQ(header, (std::vector<std::string>{"t", "gx", "gx_mean", "gx_kalman", "gy", "gy_mean", "gy_kalman"}));
  ASSERT_EQ(cols[0].size(), 3000u);
  for (std::size_t axis = 0; axis < 2; ++axis) {
    const auto& x = cols[1 + 3 * axis];
    const auto& mean_out = cols[2 + 3 * axis];
    const auto& kalman_out = cols[3 + 3 * axis];
    double xhat = 0.0, P = 0.0;
    std::size_t mismatches = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const std::size_t first = i + 1 >= L ? i + 1 - L : 0;
      double sum = 0.0;
      for (std::size_t j = first; j <= i; ++j) sum += x[j];
      const double m = sum / static_cast<double>(i + 1 - first);
      double kept = 0.0;
      std::size_t count = 0;
      for (std::size_t j = first; j <= i; ++j)
        if (std::abs(x[j] - m) <= thr) {
          kept += x[j];
          ++count;
        }
      const double y = count ? kept / static_cast<double>(count) : m;
      if (i == 0) {
        xhat = y;
        P = 0.0;
      } else {
        const double xp = A * xhat, Pp = A * P * A + Q, K = Pp / (Pp + R);
        xhat = xp + K * (y - xp);
        P = (1.0 - K) * Pp;
      }
      // Summation order may differ from the library's by an ulp or so.
      if (std::abs(mean_out[i] - y) > 1e-12 || std::abs(kalman_out[i] - xhat) > 1e-12) ++mismatches;
    }
    EXPECT_EQ(mismatches, 0u) << "axis " << axis;
    // Detrended by default: the column the chain saw has zero mean.
    double mean = 0.0;
    for (double v : x) mean += v;
    EXPECT_NEAR(mean / x.size(), 0.0, 1e-12);
  }
}

TEST(GyroctlFilter, NoDetrendPassesTheRawInputThrough) {
  ScratchDir d;
  const auto in = d.write("in.csv", "t,gx\n0,1.25\n0.02,1.5\n0.04,1.75\n0.06,2\n0.08,1.5\n0.1,1.25\n");
  const auto out = d.path() / "out.csv";
  const auto r = runGyroctl(
      "filter " + in.string() + " -o " + out.string() + " --no-detrend --ar-phi 0.5 --kalman-q 1 --kalman-r 1",
      d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::vector<std::string> header;
  const auto cols = parseCsv(readWholeFile(out), header);
  EXPECT_EQ(cols[1], (std::vector<double>{1.25, 1.5, 1.75, 2, 1.5, 1.25}));
  EXPECT_DOUBLE_EQ(cols[2][1], 1.375);  // mean of the first two, none rejected at r = 0.3
  EXPECT_DOUBLE_EQ(cols[3][0], 1.25);   // x̂0 = first mean-filter output
}

TEST(GyroctlImport, ConvertsTheRealImucalRecordingExactly) {
  ScratchDir d;
  const std::string src = std::string(GYROD_TEST_DATA_DIR) + "/mpu6050-arduino-100hz/imu_static_test.csv";
  const auto out = d.path() / "real.csv";
  const auto r = runGyroctl("import " + src + " -o " + out.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::vector<std::string> header;
  const auto cols = parseCsv(readWholeFile(out), header);
  EXPECT_EQ(header, (std::vector<std::string>{"t", "gx", "gy", "gz", "ax", "ay", "az"}));
  ASSERT_EQ(cols[0].size(), 9986u);
  // First data line of the source: 748,244,15708,-480,193,-83.
  EXPECT_EQ(cols[1][0], -480.0 / 131.0);
  EXPECT_EQ(cols[2][0], 193.0 / 131.0);
  EXPECT_EQ(cols[3][0], -83.0 / 131.0);
  // The accelerometer at ±2 g, 16384 LSB per g (exact in binary, so compared exactly).
  EXPECT_EQ(cols[4][0], 748.0 / 16384.0);
  EXPECT_EQ(cols[5][0], 244.0 / 16384.0);
  EXPECT_EQ(cols[6][0], 15708.0 / 16384.0);
  EXPECT_EQ(cols[0][1], 0.01);
  EXPECT_EQ(cols[0][9985], 9985.0 / 100.0);
  // And analyze reads it, finding the rate from t.
  const auto a = runGyroctl("analyze " + out.string() + " --json --axis gz", d.path());
  ASSERT_EQ(a.exit_status, 0) << a.err;
  EXPECT_NEAR(json::parse(a.out)["rate_hz"].get<double>(), 100.0, 1e-9);
}

// analyse → model → simulate: the model file carries the fitted terms and the bias, and
// `gyroctl simulate --model` accepts it.
TEST(GyroctlAnalyze, WriteModelRoundTripsThroughSimulate) {
  ScratchDir d;
  const auto sim = d.path() / "sim.csv";
  const auto model = d.path() / "model.toml";
  ASSERT_EQ(runGyroctl("simulate --arw 0.5 --bias-instability 30 --duration 1200 --seed 7 -o " + sim.string(), d.path())
                .exit_status,
            0);
  const auto a = runGyroctl("analyze " + sim.string() + " --json --write-model " + model.string(), d.path());
  ASSERT_EQ(a.exit_status, 0) << a.err;
  const json doc = json::parse(a.out);
  const std::string text = readWholeFile(model);
  for (const char* table : {"[x]", "[y]", "[z]"}) EXPECT_NE(text.find(table), std::string::npos) << table;
  // The file's x-axis ARW is the analysis' value (17 significant digits in the file).
  const double n_fit = doc["axes"]["gx"]["noise"]["arw_deg_per_sqrt_h"].get<double>();
  EXPECT_NEAR(n_fit, 0.5, 0.05);
  const auto pos = text.find("arw_deg_per_sqrt_h", text.find("[x]"));
  ASSERT_NE(pos, std::string::npos);
  EXPECT_NEAR(std::stod(text.substr(text.find('=', pos) + 1)), n_fit, 1e-12 * n_fit);
  const auto sim2 = d.path() / "sim2.csv";
  const auto r =
      runGyroctl("simulate --model " + model.string() + " --duration 600 --seed 8 -o " + sim2.string(), d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
}

TEST(GyroctlFilter, BiasSubtractsConstantsInsteadOfDetrending) {
  ScratchDir d;
  const auto in = d.write("in.csv", "t,gx,gy\n0,1.25,2\n0.02,1.5,2\n0.04,1.75,2.5\n");
  const auto out = d.path() / "out.csv";
  const auto r = runGyroctl(
      "filter " + in.string() + " -o " + out.string() + " --bias 1,2 --ar-phi 0.5 --kalman-q 1 --kalman-r 1", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::vector<std::string> header;
  const auto cols = parseCsv(readWholeFile(out), header);
  EXPECT_EQ(cols[1], (std::vector<double>{0.25, 0.5, 0.75}));
  EXPECT_EQ(cols[4], (std::vector<double>{0, 0, 0.5}));
  EXPECT_EQ(runGyroctl("filter " + in.string() + " -o " + out.string() + " --bias 1", d.path()).exit_status, 64);
  EXPECT_EQ(
      runGyroctl("filter " + in.string() + " -o " + out.string() + " --bias 1,2 --no-detrend", d.path()).exit_status,
      64);
}
