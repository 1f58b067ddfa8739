// gyroctl model-check: the JSON document, the report folder, and errors. The recording comes
// from the hidden-effect generator (a sinusoid on one axis), written as the CSV analyze reads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "processing/model_check/hidden_effect_generator.hpp"
#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

std::string recordingCsv(const gyrod::processing::GeneratedRecording& g) {
  std::string out = "t,gx,gy,gz,temp\n";
  char line[256];
  for (std::size_t i = 0; i < g.t.size(); ++i) {
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g,%.17g\n", g.t[i], g.axes[0][i], g.axes[1][i],
                  g.axes[2][i], g.temp[i]);
    out += line;
  }
  return out;
}

}  // namespace

TEST(GyroctlModelCheck, JsonNamesTheHiddenSinusoidOnItsAxisOnly) {
  ScratchDir d;
  const auto g =
      gyrod::processing::HiddenEffectGenerator(7).generate(300.0, 50.0, {gyrod::processing::ModelEffect::Sinusoid});
  const auto csv = d.write("rec.csv", recordingCsv(g));
  const auto r = runGyroctl("model-check " + csv.string() + " --json --replicas 16 --seed 3 --threads 2", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto doc = nlohmann::json::parse(r.out);
  const char* names[3] = {"gx", "gy", "gz"};
  for (std::size_t a = 0; a < 3; ++a) {
    const auto& axis = doc.at("axes").at(names[a]);
    for (const char* key :
         {"adev_log_error_base", "adev_log_error_extended", "innovation_var_base", "innovation_var_extended",
          "ljung_box_p_base", "ljung_box_p_extended", "in_band_base", "in_band_extended"})
      EXPECT_TRUE(axis.at("gain").at(key).is_number()) << key;
    const auto& effects = axis.at("effects");
    ASSERT_TRUE(effects.is_array());
    if (a != g.hidden[0].axis) {
      EXPECT_TRUE(effects.empty()) << effects.dump();
      continue;
    }
    ASSERT_EQ(effects.size(), 1u) << effects.dump();
    EXPECT_EQ(effects[0].at("effect"), "sinusoid");
    EXPECT_NEAR(effects[0].at("params").at("freq_hz").get<double>(), g.hidden[0].freq_hz, 0.5 / 300.0);
    EXPECT_NEAR(effects[0].at("params").at("amp_dps").get<double>(), g.hidden[0].amp_dps, 0.1 * g.hidden[0].amp_dps);
    EXPECT_FALSE(effects[0].at("evidence").get<std::string>().empty());
    // Its stated 95 % interval (docs/model-check.md, "Intervals"): [lo, hi] around the estimate.
    const auto& amp95 = effects[0].at("params").at("amp_dps_95");
    ASSERT_EQ(amp95.size(), 2u) << amp95.dump();
    const double amp = effects[0].at("params").at("amp_dps").get<double>();
    EXPECT_LT(amp95[0].get<double>(), amp);
    EXPECT_GT(amp95[1].get<double>(), amp);
  }
}

TEST(GyroctlModelCheck, ReportFolderHasMarkdownAndPlotScripts) {
  ScratchDir d;
  const auto g = gyrod::processing::HiddenEffectGenerator(5).generate(200.0, 50.0, {});
  const auto csv = d.write("rec.csv", recordingCsv(g));
  const auto dir = d.path() / "report";
  const auto r =
      runGyroctl("model-check " + csv.string() + " --axis gy --replicas 8 --report " + dir.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("checked in"), std::string::npos);
  const std::string md = readWholeFile(dir / "report.md");
  EXPECT_NE(md.find("## gy"), std::string::npos);
  EXPECT_EQ(md.find("## gx"), std::string::npos);
  for (const char* f : {"allan_gy.gp", "allan_gy.dat", "spectrum_gy.gp", "temperature_gy.gp"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    EXPECT_TRUE(std::filesystem::exists(dir / "allan_gy.png"));
  }
}

TEST(GyroctlModelCheck, TooShortOrMissingFilesAreUsageErrors) {
  ScratchDir d;
  const auto csv = d.write("short.csv", "t,gx\n0,0.1\n0.02,0.2\n0.04,0.1\n");
  auto r = runGyroctl("model-check " + csv.string(), d.path());
  EXPECT_EQ(r.exit_status, 65);  // EX_DATAERR
  EXPECT_NE(r.err.find("too few"), std::string::npos) << r.err;
  r = runGyroctl("model-check " + (d.path() / "missing.csv").string(), d.path());
  EXPECT_EQ(r.exit_status, 66);  // EX_NOINPUT
  r = runGyroctl("model-check " + csv.string() + " --replicas 2", d.path());
  EXPECT_EQ(r.exit_status, 64);  // EX_USAGE
}

// ---- the model file's optional [x.extra] tables ------------------------------------------

#include "formats/model_toml.hpp"

TEST(ModelTomlExtra, ExtraEffectsReadBackIdentically) {
  gyrod::processing::SimulationModel m;
  auto& e = m.axes[1].extra;
  e.temperature_coefficient_dps_per_c = -0.0123;
  e.temperature_reference_c = 31.5;
  e.gauss_markov_tau_s = 17.25;
  e.gauss_markov_sigma_dps = 0.0021;
  e.outlier_count = 7;
  e.outlier_amplitude_dps = 1.5;
  e.sinusoids = {{1.08, 0.07, 0.3}, {12.5, 0.01, -2.0}};
  e.bias_steps = {{600.0, 0.02}};
  const auto back = gyrod::recording::parseModelToml(gyrod::recording::modelToToml(m), "m.toml");
  const auto& b = back.axes[1].extra;
  EXPECT_EQ(b.temperature_coefficient_dps_per_c, e.temperature_coefficient_dps_per_c);
  EXPECT_EQ(b.temperature_reference_c, e.temperature_reference_c);
  EXPECT_EQ(b.gauss_markov_tau_s, e.gauss_markov_tau_s);
  EXPECT_EQ(b.gauss_markov_sigma_dps, e.gauss_markov_sigma_dps);
  EXPECT_EQ(b.outlier_count, e.outlier_count);
  EXPECT_EQ(b.outlier_amplitude_dps, e.outlier_amplitude_dps);
  ASSERT_EQ(b.sinusoids.size(), 2u);
  EXPECT_EQ(b.sinusoids[1].freq_hz, 12.5);
  EXPECT_EQ(b.sinusoids[1].phase_rad, -2.0);
  ASSERT_EQ(b.bias_steps.size(), 1u);
  EXPECT_EQ(b.bias_steps[0].size_dps, 0.02);
  EXPECT_TRUE(back.axes[0].extra.empty());
  // A model without extras writes no [x.extra] table (files stay as they were).
  EXPECT_EQ(gyrod::recording::modelToToml(gyrod::processing::SimulationModel{}).find("extra"), std::string::npos);
}

TEST(ModelTomlExtra, BadExtraKeysNameTheLine) {
  try {
    gyrod::recording::parseModelToml("[x]\narw_deg_per_sqrt_h = 1.0\n[x.extra]\nsinusoid = []\n", "m.toml");
    FAIL();
  } catch (const gyrod::recording::RecordingError& err) {
    EXPECT_NE(std::string(err.what()).find("m.toml:4"), std::string::npos) << err.what();
  }
  EXPECT_THROW(gyrod::recording::parseModelToml("[z.extra]\nsinusoids = [{freq_hz = -1.0}]\n", "m.toml"),
               gyrod::recording::RecordingError);
}

// ---- gyroctl model-check --write-model ---------------------------------------------------
//
// End to end: `gyroctl simulate` from a model file with a hidden sinusoid on x and a warm-up
// temperature → `model-check --write-model` → the written file names the sinusoid on x only,
// with its frequency, amplitude and phase within five standard errors of the least-squares
// estimator, and `gyroctl simulate --model` accepts it.

namespace {

// The hidden model: white rate noise only (ARW), so the noise at the sinusoid's frequency
// is white with a known per-sample std σ = N/60·√rate (N in °/√h → °/√s), and the
// estimator's errors have closed forms (below).
constexpr double kSimRate = 50.0, kSimDuration = 300.0, kArw = 0.5;
constexpr double kSinFreq = 1.7, kSinAmp = 0.03, kSinPhase = 0.4, kBiasX = 0.3;
constexpr double kTempStart = 24.0, kTempFinal = 34.0, kTempTau = 120.0, kTempNoise = 0.02;

std::string hiddenSinusoidModel() {
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "rate_hz = %g\n[temperature]\nstart_c = %g\nfinal_c = %g\ntime_constant_s = %g\nnoise_std_c = %g\n"
                "[x]\narw_deg_per_sqrt_h = %g\nbias_dps = %g\n"
                "[x.extra]\nsinusoids = [{freq_hz = %g, amp_dps = %g, phase_rad = %g}]\n"
                "[y]\narw_deg_per_sqrt_h = %g\n[z]\narw_deg_per_sqrt_h = %g\n",
                kSimRate, kTempStart, kTempFinal, kTempTau, kTempNoise, kArw, kBiasX, kSinFreq, kSinAmp, kSinPhase,
                kArw, kArw);
  return buf;
}

}  // namespace

TEST(GyroctlModelCheckWriteModel, NamesTheHiddenSinusoidAndSimulateAcceptsTheFile) {
  ScratchDir d;
  const auto hidden = d.write("hidden.toml", hiddenSinusoidModel());
  const auto rec = d.path() / "rec.csv";
  auto r = runGyroctl("simulate --model " + hidden.string() + " --duration 300 --seed 9 -o " + rec.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto out = d.path() / "extended.toml";
  r = runGyroctl("model-check " + rec.string() + " --replicas 16 --seed 3 --threads 2 --write-model " + out.string(),
                 d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("extended model written to " + out.string()), std::string::npos) << r.out;
  const std::string text = readWholeFile(out);
  const gyrod::processing::SimulationModel m = gyrod::recording::parseModelToml(text, out.string());

  // Standard errors of the least-squares sinusoid in white noise of std σ over n samples
  // (Kay, Fundamentals of Statistical Signal Processing I, §3.10; SNR η = A²/(2σ²)):
  // sd(A) = σ·√(2/n); sd(f) = rate·√(12/((2π)²·η·n·(n²−1))); sd(φ) at t = 0 ≈ √(4/(η·n))
  // (phase and frequency estimated jointly, origin at the first sample).
  const double n = kSimRate * kSimDuration;
  const double sigma = kArw / 60.0 * std::sqrt(kSimRate);
  const double eta = kSinAmp * kSinAmp / (2.0 * sigma * sigma);
  const double sd_amp = sigma * std::sqrt(2.0 / n);
  const double sd_freq =
      kSimRate * std::sqrt(12.0 / (4.0 * std::numbers::pi * std::numbers::pi * eta * n * (n * n - 1.0)));
  const double sd_phase = std::sqrt(4.0 / (eta * n));
  const auto& x = m.axes[0].extra;
  ASSERT_EQ(x.sinusoids.size(), 1u) << text;
  EXPECT_NEAR(x.sinusoids[0].freq_hz, kSinFreq, 5.0 * sd_freq);
  EXPECT_NEAR(x.sinusoids[0].amp_dps, kSinAmp, 5.0 * sd_amp);
  EXPECT_NEAR(std::remainder(x.sinusoids[0].phase_rad - kSinPhase, 2.0 * std::numbers::pi), 0.0, 5.0 * sd_phase);
  // Nothing else named on x; nothing at all on y and z (no temperature coupling was hidden,
  // though the temperature moves).
  EXPECT_EQ(x.temperature_coefficient_dps_per_c, 0.0);
  EXPECT_EQ(x.gauss_markov_sigma_dps, 0.0);
  EXPECT_TRUE(x.bias_steps.empty());
  EXPECT_EQ(x.outlier_count, 0u);
  EXPECT_TRUE(m.axes[1].extra.empty()) << text;
  EXPECT_TRUE(m.axes[2].extra.empty()) << text;
  // The terms: ARW within 5 % on every axis (the fit's relative error at this length is
  // ≈ 1 %), and the bias within 5 standard errors σ/√n of the mean.
  for (std::size_t a = 0; a < 3; ++a)
    EXPECT_NEAR(m.axes[a].terms.arw_deg_per_sqrt_h, kArw, 0.05 * kArw) << "axis " << a;
  EXPECT_NEAR(m.axes[0].bias_dps, kBiasX, 5.0 * sigma / std::sqrt(n));
  EXPECT_NEAR(m.rate_hz, kSimRate, 1e-9 * kSimRate);  // from the t column (1/median spacing)
  // The warm-up curve fitted to the recording's temperature: 15 000 samples of 0.02 °C
  // noise pin start and final to ~1e-3 °C and T to ~0.2 %; the noise std from first
  // differences has relative sd ≈ 1/√n·√1.5 ≈ 1 %.
  EXPECT_NEAR(m.temperature.start_c, kTempStart, 0.02);
  EXPECT_NEAR(m.temperature.final_c, kTempFinal, 0.02);
  EXPECT_NEAR(m.temperature.time_constant_s, kTempTau, 0.02 * kTempTau);
  EXPECT_NEAR(m.temperature.noise_std_c, kTempNoise, 0.05 * kTempNoise);
  // And the simulator takes the file as it is.
  const auto again = d.path() / "again.csv";
  r = runGyroctl("simulate --model " + out.string() + " --duration 60 --seed 4 -o " + again.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string csv = readWholeFile(again);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 60 * 50);
}

// The acquisition chain the check modelled goes into the written model (dlpf, fs_sel, the
// rate), so that `gyroctl simulate --model` makes the noise through the same DLPF and rounding;
// the rounding's white noise, which the fitted white term holds, is taken out of it.
TEST(GyroctlModelCheckWriteModel, WritesTheAcquisitionChain) {
  ScratchDir d;
  const auto rec = d.path() / "rec.csv";
  auto r =
      runGyroctl("simulate --arw 0.5 --bias-instability 5 --duration 300 --rate 50 --dlpf 4 --fs-sel 0 --seed 5 -o " +
                     rec.string(),
                 d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto out = d.path() / "m.toml";
  r = runGyroctl(
      "model-check " + rec.string() + " --dlpf 4 --fs-sel 0 --replicas 8 --threads 2 --write-model " + out.string(),
      d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string text = readWholeFile(out);
  EXPECT_NE(text.find("dlpf = 4\n"), std::string::npos) << text;
  EXPECT_NE(text.find("fs_sel = 0\n"), std::string::npos) << text;
  const gyrod::processing::SimulationModel m = gyrod::recording::parseModelToml(text, out.string());
  EXPECT_EQ(m.dlpf_cfg, 4);
  EXPECT_EQ(m.fs_sel, 0);
  EXPECT_NEAR(m.rate_hz, 50.0, 1e-9);
  // 0.5 °/√h less the rounding's share (LSB²·τ0/12 against N²: 0.2 % of it). Through DLPF_CFG
  // 4 the white and flicker terms are told apart by their short-τ shapes in 300 s: measured
  // 0.540–0.545 on the three axes (seed 5), so within 12 %.
  for (std::size_t a = 0; a < 3; ++a) EXPECT_NEAR(m.axes[a].terms.arw_deg_per_sqrt_h, 0.5, 0.06) << "axis " << a;
  const auto again = d.path() / "again.csv";
  r = runGyroctl("simulate --model " + out.string() + " --duration 60 --seed 4 -o " + again.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE((r.out + r.err).find("DLPF_CFG 4, FS_SEL 0"), std::string::npos) << r.out << r.err;
}

TEST(GyroctlModelCheckWriteModel, SampleGapsAreACommentNotAnEffect) {
  ScratchDir d;
  const auto g =
      gyrod::processing::HiddenEffectGenerator(13).generate(200.0, 50.0, {gyrod::processing::ModelEffect::SampleGaps});
  const auto csv = d.write("rec.csv", recordingCsv(g));
  const auto out = d.path() / "m.toml";
  const auto r = runGyroctl(
      "model-check " + csv.string() + " --axis gx --replicas 8 --json --write-model " + out.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string text = readWholeFile(out);
  const std::string note = "# gx: sample_gaps found (" + std::to_string(g.hidden[0].count) + " gaps, " +
                           std::to_string(g.hidden[0].lost) + " samples lost): not modelled";
  EXPECT_NE(text.find(note), std::string::npos) << text;
  const auto m = gyrod::recording::parseModelToml(text, out.string());
  EXPECT_TRUE(m.axes[0].extra.empty()) << text;
  EXPECT_GT(m.axes[0].terms.arw_deg_per_sqrt_h, 0.0);
  // Only gx was checked: y and z are written as zero axes.
  EXPECT_EQ(m.axes[1].terms.arw_deg_per_sqrt_h, 0.0);
  EXPECT_NE(text.find("# Axes checked: gx."), std::string::npos) << text;
}

TEST(GyroctlModelCheckWriteModel, UnwritablePathFailsBeforeTheCheckAndKeepsAnExistingFile) {
  ScratchDir d;
  const auto g = gyrod::processing::HiddenEffectGenerator(5).generate(100.0, 50.0, {});
  const auto csv = d.write("rec.csv", recordingCsv(g));
  // A missing folder: exit 73 (EX_CANTCREAT) as for every output that cannot be created,
  // one line naming the path, and no check output (it failed before the check ran).
  const auto missing = d.path() / "no-such-folder" / "m.toml";
  auto r = runGyroctl("model-check " + csv.string() + " --replicas 8 --write-model " + missing.string(), d.path());
  EXPECT_EQ(r.exit_status, 73);
  EXPECT_NE(r.err.find(missing.string() + ": cannot write the model: " + missing.parent_path().string() +
                       ": folder does not exist"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.out.find("checked in"), std::string::npos) << r.out;
  // A folder in the way.
  r = runGyroctl("model-check " + csv.string() + " --replicas 8 --write-model " + d.path().string(), d.path());
  EXPECT_EQ(r.exit_status, 73);
  EXPECT_NE(r.err.find("it is a folder"), std::string::npos) << r.err;
  // A check that fails (too short a recording) leaves an existing model file as it was.
  const auto existing = d.write("keep.toml", "precious\n");
  const auto short_csv = d.write("short.csv", "t,gx\n0,0.1\n0.02,0.2\n0.04,0.1\n");
  r = runGyroctl("model-check " + short_csv.string() + " --write-model " + existing.string(), d.path());
  EXPECT_EQ(r.exit_status, 65);
  EXPECT_EQ(readWholeFile(existing), "precious\n");
}

// Outliers are judged by a measure that sees them (docs/model-check.md, "Outliers are judged by
// what sees them"): the JSON lists the measures counted (without the Allan ones when outliers
// are the only effect named) and the held-out tail's figures; the text says the same.
TEST(GyroctlModelCheck, OutliersAreJudgedByTheHeldOutTailAndSaySo) {
  ScratchDir d;
  gyrod::processing::HiddenEffectGenerator gen(1);
  gen.outlier_count_lo = gen.outlier_count_hi = 50;
  const auto g = gen.generate(600.0, 50.0, {gyrod::processing::ModelEffect::Outliers});
  const auto csv = d.write("rec.csv", recordingCsv(g));
  const char* names[3] = {"gx", "gy", "gz"};
  const std::string axis_name = names[g.hidden[0].axis];
  const std::string args = "model-check " + csv.string() + " --axis " + axis_name + " --seed 3 --threads 2";
  const auto r = runGyroctl(args + " --json", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto doc = nlohmann::json::parse(r.out);
  const auto& axis = doc.at("axes").at(axis_name);
  bool alone = !axis.at("effects").empty();
  for (const auto& e : axis.at("effects")) alone = alone && e.at("effect") == "outliers";
  const auto& judged_by = axis.at("extension").at("judged_by");
  auto lists = [&](const char* m) { return std::find(judged_by.begin(), judged_by.end(), m) != judged_by.end(); };
  EXPECT_TRUE(lists("innovation_tail_held_out")) << judged_by.dump();
  EXPECT_TRUE(lists("innovation_var_held_out")) << judged_by.dump();
  EXPECT_EQ(lists("adev_log_error"), !alone) << axis.at("effects").dump();
  const auto& tail = axis.at("gain").at("innovation_tail_held_out");
  EXPECT_GE(tail.at("count").get<double>(), 1.0) << tail.dump();
  EXPECT_GT(tail.at("log_likelihood_extended").get<double>(), tail.at("log_likelihood_base").get<double>() + 3.0)
      << tail.dump();
  const auto& better = axis.at("extension").at("better");
  EXPECT_NE(std::find(better.begin(), better.end(), "innovation_tail_held_out"), better.end()) << better.dump();
  const auto text = runGyroctl(args, d.path());
  ASSERT_EQ(text.exit_status, 0) << text.err;
  EXPECT_NE(text.out.find("held out tail (innovations beyond 5 sigma): "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("(judged by "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("innovation_tail_held_out"), std::string::npos) << text.out;
}
