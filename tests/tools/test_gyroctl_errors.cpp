// Every bad input to gyroctl's offline commands: one line naming file, line and cause,
// exit status 2, no crash, and no existing output destroyed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "tools/run_command.hpp"

using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;

namespace {

std::string whiteNoiseCsv(std::size_t n, double rate_hz, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::string s = "t,gx,gy\n";
  char buf[96];
  for (std::size_t i = 0; i < n; ++i) {
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g\n", static_cast<double>(i) / rate_hz, noise(rng), noise(rng));
    s += buf;
  }
  return s;
}

// Bad input is EX_DATAERR (65) unless said otherwise: 66 for a file that cannot be opened, 64
// for a bad option value (README "Exit statuses").
void expectOneLineError(const gyrod::test::CommandResult& r, const std::string& must_contain, int status = 65) {
  EXPECT_EQ(r.exit_status, status) << r.err;
  EXPECT_NE(r.err.find(must_contain), std::string::npos) << "stderr was: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "stderr was: " << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// A name only a programmer knows, at the start of a message part: a camelCase or CamelCase
// identifier (yuleWalker, EventLoop), a qualified name (portable::log) or a call (f()), then ": ".
bool hasInternalName(const std::string& text) {
  static const std::regex name(
      R"(\b([a-z][a-z0-9_]*[A-Z]\w*|[A-Z][a-z0-9_]+[A-Z]\w*|[A-Za-z_]\w*(::\w+)+)(\(\))?: |\w\(\): )");
  return std::regex_search(text, name);
}

}  // namespace

TEST(GyroctlErrors, TheInternalNameCheckFindsNamesAndPassesWords) {
  EXPECT_TRUE(hasInternalName("gyroctl: yuleWalker: the series has zero variance"));
  EXPECT_TRUE(hasInternalName("x.csv: column 'gx': RollingOverlappingAllan::push: rate"));
  EXPECT_TRUE(hasInternalName("EventLoop: empty callback"));
  EXPECT_TRUE(hasInternalName("parse(): bad"));
  EXPECT_FALSE(hasInternalName("gyroctl: x.csv: column 'gx': the AR model fit needs a series that varies"));
  EXPECT_FALSE(hasInternalName("SIGHUP: keeping the running filter: /tmp/a.toml:8: key 'filter.model': "));
}

// A constant signal (a sensor stuck at one value) cannot be analysed: the message names the
// file, the column, the computation in a user's words and the value, and the exit status is 65.
TEST(GyroctlErrors, AConstantSignalIsRefusedInAUsersWords) {
  ScratchDir d;
  std::string text = "t,gx\n";
  for (int i = 0; i < 500; ++i) text += std::to_string(i * 0.02) + ",0.0123\n";
  const auto constant = d.write("stuck.csv", text);
  for (const std::string json : {"", " --json"}) {
    const auto r = runGyroctl("analyze " + constant.string() + json, d.path());
    expectOneLineError(r, constant.string() + ": column 'gx': ");
    EXPECT_NE(r.err.find("constant"), std::string::npos) << r.err;
    EXPECT_FALSE(hasInternalName(r.err)) << r.err;
  }
}

TEST(GyroctlErrors, MissingFile) {
  ScratchDir d;
  const auto missing = (d.path() / "nope.csv").string();
  expectOneLineError(runGyroctl("analyze " + missing, d.path()), missing + ": cannot open: No such file or directory",
                     66);
}

TEST(GyroctlErrors, EmptyFile) {
  ScratchDir d;
  const auto f = d.write("empty.csv", "");
  expectOneLineError(runGyroctl("analyze " + f.string(), d.path()), f.string() + ": empty file");
}

TEST(GyroctlErrors, HeaderWithoutSamples) {
  ScratchDir d;
  const auto f = d.write("h.csv", "t,gx\n");
  expectOneLineError(runGyroctl("analyze " + f.string(), d.path()), f.string() + ":1: no samples after the header");
}

TEST(GyroctlErrors, TextWhereANumberShouldBeNamesTheLine) {
  ScratchDir d;
  const auto f = d.write("t.csv", "t,gx\n0,0.1\n0.02,abc\n0.04,0.2\n");
  expectOneLineError(runGyroctl("analyze " + f.string(), d.path()),
                     f.string() + ":3: column 'gx': 'abc' is not a number");
}

TEST(GyroctlErrors, NaNAndInfAreRejectedWithTheirLine) {
  ScratchDir d;
  const auto nan_file = d.write("nan.csv", "t,gx\n0,0.1\n0.02,0.2\n0.04,nan\n");
  expectOneLineError(runGyroctl("analyze " + nan_file.string(), d.path()),
                     nan_file.string() + ":4: column 'gx': non-finite value 'nan'");
  const auto inf_file = d.write("inf.csv", "t,gx\n0,-inf\n");
  expectOneLineError(runGyroctl("filter " + inf_file.string() + " -o " + (d.path() / "o.csv").string(), d.path()),
                     inf_file.string() + ":2: column 'gx': non-finite value '-inf'");
  const auto huge_file = d.write("huge.csv", "gx\n1e999\n");
  expectOneLineError(runGyroctl("analyze " + huge_file.string(), d.path()),
                     ":2: column 'gx': non-finite value '1e999'");
}

// A finite value the statistics cannot carry, or a series they reject, is named by file
// (and line) before anything reaches stdout, never by an internal function's name.
TEST(GyroctlErrors, ValuesTheAnalysisCannotCarryAreRefusedBeforeAnyOutput) {
  ScratchDir d;
  std::string huge_text = "t,gx\n", constant_text = "t,gx\n";
  for (int i = 0; i < 200; ++i) {
    const std::string t = std::to_string(i * 0.02);
    huge_text += t + (i == 5 ? ",1e308\n" : i % 2 ? ",0.1\n" : ",-0.1\n");
    constant_text += t + ",0.5\n";
  }
  const auto huge = d.write("huge.csv", huge_text);
  const auto r = runGyroctl("analyze " + huge.string(), d.path());
  expectOneLineError(r, huge.string() + ":7: column 'gx': 1e+308 deg/s is beyond 1e+12 deg/s");
  const auto constant = d.write("constant.csv", constant_text);
  const auto c = runGyroctl("analyze " + constant.string() + " --json", d.path());
  expectOneLineError(c, constant.string() + ": column 'gx': ");
  EXPECT_EQ(c.err.find("yuleWalker"), std::string::npos) << c.err;
  EXPECT_EQ(c.err.find("Test:"), std::string::npos) << c.err;
}

// A misspelt option or axis: one line in gyroctl's style, with the nearest name, exit 64;
// the columns listed are every gyro and accelerometer column the file has.
TEST(GyroctlErrors, MisspeltOptionsAndAxesSuggestTheNearestName) {
  ScratchDir d;
  const auto f = d.write("a.csv", "t,gx,gy,gz,ax,ay,az\n0,1,2,3,0,0,1\n0.02,1,2,3,0,0,1\n");
  expectOneLineError(runGyroctl("analyze " + f.string() + " --axsi gx", d.path()),
                     "gyroctl: analyze: unknown option '--axsi'; did you mean '--axis'? (gyroctl analyze --help", 64);
  expectOneLineError(runGyroctl("filter " + f.string() + " -o x.csv --mean-windw 5", d.path()),
                     "gyroctl: filter: unknown option '--mean-windw'; did you mean '--mean-window'?", 64);
  expectOneLineError(runGyroctl("analyze " + f.string() + " --axis gq", d.path()),
                     "gyroctl: --axis 'gq': " + f.string() +
                         " has no column 'gq'; did you mean 'gx'? (the file has gx,gy,gz,ax,ay,az; or all)",
                     64);
  expectOneLineError(runGyroctl("analyze " + f.string() + " --rate abc", d.path()), "gyroctl: analyze: ", 64);
}

TEST(GyroctlErrors, MissingColumn) {
  ScratchDir d;
  const auto f = d.write("w.csv", whiteNoiseCsv(500, 50.0, 1));
  // A column the file lacks is a bad --axis value (64), named with what the file has.
  expectOneLineError(runGyroctl("analyze " + f.string() + " --axis gz", d.path()),
                     "--axis 'gz': " + f.string() + " has no column 'gz'", 64);
  const auto no_gyro = d.write("ng.csv", "t,temp\n0,25\n");
  expectOneLineError(runGyroctl("analyze " + no_gyro.string(), d.path()), ":1: no gyro column");
}

TEST(GyroctlErrors, UnknownAndDuplicateColumns) {
  ScratchDir d;
  // ax is the accelerometer now (issue 12); a magnetometer column is still unknown.
  const auto f = d.write("u.csv", "t,gx,mx\n0,1,2\n");
  expectOneLineError(runGyroctl("analyze " + f.string(), d.path()), ":1: unknown column 'mx'");
  const auto g = d.write("dup.csv", "t,gx,gx\n0,1,2\n");
  expectOneLineError(runGyroctl("analyze " + g.string(), d.path()), ":1: column 'gx' appears twice");
}

TEST(GyroctlErrors, WrongFieldCount) {
  ScratchDir d;
  const auto f = d.write("f.csv", "t,gx,gy\n0,1,2\n0.02,1\n");
  expectOneLineError(runGyroctl("analyze " + f.string(), d.path()), f.string() + ":3: expected 3 fields, found 2");
}

TEST(GyroctlErrors, RateThatDisagreesWithT) {
  ScratchDir d;
  const auto f = d.write("w.csv", whiteNoiseCsv(500, 50.0, 2));
  expectOneLineError(runGyroctl("analyze " + f.string() + " --rate 100", d.path()),
                     f.string() + ": --rate 100 Hz disagrees with column 't'");
}

TEST(GyroctlErrors, TimeGoingBackwardsNamesTheLine) {
  ScratchDir d;
  const auto f = d.write("b.csv", "t,gx\n0,1\n0.02,1\n0.01,1\n");
  expectOneLineError(runGyroctl("analyze " + f.string(), d.path()),
                     f.string() + ":4: column 't' is not strictly increasing");
}

TEST(GyroctlErrors, TooFewSamples) {
  ScratchDir d;
  const auto f = d.write("s.csv", whiteNoiseCsv(20, 50.0, 3));
  expectOneLineError(runGyroctl("analyze " + f.string(), d.path()), "20 samples are too few");
}

// A τ between two whole numbers of samples is taken at the nearest one and said on stderr;
// only a τ nearer to no sample at all than to one is refused.
TEST(GyroctlErrors, TauBetweenWholeSamplesIsRoundedAndSaid) {
  ScratchDir d;
  const auto f = d.write("w.csv", whiteNoiseCsv(2000, 50.0, 4));
  const auto r = runGyroctl("analyze " + f.string() + " --taus 0.1,0.026 --json", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.err.find("--taus 0.026 s is 1.3 samples at 50 Hz: using the nearest whole number, m = 1, tau = 0.02 s"),
            std::string::npos)
      << r.err;
  const auto allan = nlohmann::json::parse(r.out)["axes"]["gx"]["allan"];
  ASSERT_EQ(allan.size(), 2u);
  EXPECT_EQ(allan[1]["m"].get<int>(), 1);
  expectOneLineError(runGyroctl("analyze " + f.string() + " --taus 0.005", d.path()), "--taus", 64);
  expectOneLineError(runGyroctl("analyze " + f.string() + " --taus 1,x", d.path()),
                     "--taus: 'x' is not a positive number", 64);
}

// The real record's rate, 100.31 Hz, puts every round τ between two whole numbers of samples.
TEST(GyroctlErrors, RoundTausAtARealRecordsRateAreTakenAtTheNearestSample) {
  ScratchDir d;
  const std::string real =
      std::string(GYROD_TEST_DATA_DIR) + "/mpu6050-sensor-fusion-set1/unmoved-x-pointing-forward.csv";
  const auto r = runGyroctl("analyze " + real + " --axis gx --taus 1,10 --json", d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto doc = nlohmann::json::parse(r.out);
  const double rate = doc["rate_hz"].get<double>();
  const auto allan = doc["axes"]["gx"]["allan"];
  ASSERT_EQ(allan.size(), 2u);
  EXPECT_EQ(allan[0]["m"].get<double>(), std::round(1.0 * rate));
  EXPECT_EQ(allan[1]["m"].get<double>(), std::round(10.0 * rate));
  EXPECT_NEAR(allan[1]["tau_s"].get<double>(), std::round(10.0 * rate) / rate, 1e-12);
  EXPECT_NE(r.err.find("--taus 10 s is"), std::string::npos) << r.err;
}

TEST(GyroctlErrors, BadOptionValuesExitWithUsage64) {
  ScratchDir d;
  const auto f = d.write("w.csv", whiteNoiseCsv(500, 50.0, 5));
  EXPECT_EQ(runGyroctl("analyze " + f.string() + " --mean-window 0", d.path()).exit_status, 64);
  EXPECT_EQ(runGyroctl("analyze " + f.string() + " --rate -3", d.path()).exit_status, 64);
  EXPECT_EQ(runGyroctl("analyze " + f.string() + " --bogus", d.path()).exit_status, 64);
  EXPECT_EQ(runGyroctl("frobnicate", d.path()).exit_status, 64);
  EXPECT_EQ(runGyroctl("filter " + f.string() + " -o " + (d.path() / "o.csv").string() + " --kalman-r -1", d.path())
                .exit_status,
            64);
}

TEST(GyroctlErrors, FailedFilterLeavesAnExistingOutputUntouched) {
  ScratchDir d;
  const auto out = d.write("out.csv", "precious\n");
  const auto bad = d.write("bad.csv", "t,gx\n0,1\n0.02,oops\n");
  const auto r = runGyroctl("filter " + bad.string() + " -o " + out.string(), d.path());
  EXPECT_EQ(r.exit_status, 65);  // EX_DATAERR
  EXPECT_EQ(gyrod::test::readWholeFile(out), "precious\n");
}

TEST(GyroctlErrors, ImportOfAForeignFileThatIsNotImucal) {
  ScratchDir d;
  const auto f = d.write("x.csv", "hello,world\n1,2\n");
  expectOneLineError(runGyroctl("import " + f.string() + " -o " + (d.path() / "o.csv").string(), d.path()),
                     f.string() + ":1: not an imucal recording");
  const auto g = d.write("y.csv", "Fs,100\nLogging Type,1\nax,ay,az,gx,gy,gz\n1,2,3,4,5,6\n1,2,3,4,x,6\n");
  expectOneLineError(runGyroctl("import " + g.string() + " -o " + (d.path() / "o.csv").string(), d.path()),
                     g.string() + ":5: column 'gy': 'x' is not an integer count");
}

// The importer bounds its lines as the recording reader does and escapes what it echoes.
TEST(GyroctlErrors, ImportBoundsLinesAndEscapesEchoedValues) {
  ScratchDir d;
  const auto out = (d.path() / "o.csv").string();
  const auto long_line = d.write("long.csv", "Fs,100\nax,ay,az,gx,gy,gz\n1,2,3," + std::string(70'000, '4') + ",5,6\n");
  expectOneLineError(runGyroctl("import " + long_line.string() + " -o " + out, d.path()),
                     long_line.string() + ":3: line longer than 65536 bytes (the limit for one line)");
  const auto escape = d.write("esc.csv", "Fs,100\nax,ay,az,gx,gy,gz\n1,2,3,4,\x1b[2J\xe2\x80\xae,6\n");
  expectOneLineError(runGyroctl("import " + escape.string() + " -o " + out, d.path()),
                     escape.string() + ":3: column 'gy': '\\x1B[2J\\u{202E}' is not an integer count");
  const auto wide = d.write("wide.csv", "Fs," + std::string(5000, '7') + "x\n");
  const auto r = runGyroctl("import " + wide.string() + " -o " + out, d.path());
  expectOneLineError(r, wide.string() + ":1: sample rate '" + std::string(80, '7') + "…' (5001 bytes) is not");
  EXPECT_LT(r.err.size(), 400u) << r.err.size();
  EXPECT_FALSE(std::filesystem::exists(out));
}

// filter and model-check name the file and column (or line) too, never the processing
// function that met the value first (yuleWalker, fitNoiseTerms, solveNonNegativeLeastSquares).
TEST(GyroctlErrors, FilterAndModelCheckNameFileAndColumnNotFunctions) {
  ScratchDir d;
  std::string constant_text = "t,gx\n", huge_text = "t,gx\n";
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.1);
  for (int i = 0; i < 2500; ++i) {
    const std::string t = std::to_string(i * 0.02);
    constant_text += t + ",0.5\n";
    huge_text += t + "," + (i == 5 ? std::string("1e300") : std::to_string(noise(rng))) + "\n";
  }
  const auto constant = d.write("constant.csv", constant_text);
  const auto huge = d.write("huge.csv", huge_text);
  const std::string out = " -o " + (d.path() / "o.csv").string();
  for (const std::string& command : {std::string("filter"), std::string("model-check --replicas 8")}) {
    const std::string o = command == "filter" ? out : "";
    const auto c = runGyroctl(command + " " + constant.string() + o, d.path());
    expectOneLineError(c, constant.string() + ": column 'gx': ");
    for (const char* internal : {"yuleWalker", "fitNoiseTerms", "solveNonNegativeLeastSquares", "Test:"})
      EXPECT_EQ(c.err.find(internal), std::string::npos) << command << ": " << c.err;
    expectOneLineError(runGyroctl(command + " " + huge.string() + o, d.path()),
                       huge.string() + ":7: column 'gx': 1e+300 deg/s is beyond 1e+12 deg/s");
  }
  EXPECT_FALSE(std::filesystem::exists(d.path() / "o.csv"));
}

// A directory is said to be one by every command that reads a file.
TEST(GyroctlErrors, ADirectoryIsNamedAsOne) {
  ScratchDir d;
  const auto dir = d.path() / "folder";
  std::filesystem::create_directories(dir);
  const std::string out = " -o " + (d.path() / "o.csv").string();
  for (const std::string& command :
       {std::string("analyze "), std::string("filter "), std::string("model-check "), std::string("import ")}) {
    const std::string o = command == "filter " || command == "import " ? out : "";
    expectOneLineError(runGyroctl(command + dir.string() + o, d.path()),
                       dir.string() + ": cannot read: it is a directory, not a file", 66);
  }
}

// Why an axis got no calibration is written into the model file in the user's words too.
TEST(GyroctlErrors, ModelFileNotesNameNoFunction) {
  ScratchDir d;
  const auto f = d.write("short.csv", whiteNoiseCsv(200, 50.0, 12));  // 4 s: too short for 10 s blocks
  const auto model = d.path() / "m.toml";
  const auto r = runGyroctl("analyze " + f.string() + " --write-model " + model.string(), d.path());
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string text = gyrod::test::readWholeFile(model);
  EXPECT_NE(text.find("# gx: no calibration ("), std::string::npos) << text.substr(0, 400);
  EXPECT_EQ(text.find("fitTemperatureBias"), std::string::npos) << text.substr(0, 400);
}

// Each command's minimum number of samples is the one its README section states.
TEST(GyroctlErrors, MinimumSamplesAreTheDocumentedOnes) {
  std::ifstream in(std::string(GYROD_TEST_DATA_DIR) + "/../../README.md");
  ASSERT_TRUE(in);
  std::stringstream readme_text;
  readme_text << in.rdbuf();
  const std::string readme = readme_text.str();
  const auto section = [&readme](const std::string& title) {
    const std::size_t at = readme.find("### `gyroctl " + title + "`");
    return at == std::string::npos ? std::string() : readme.substr(at, readme.find("\n### ", at + 1) - at);
  };
  ScratchDir d;
  const std::string out = " -o " + (d.path() / "o.csv").string();
  const std::vector<std::tuple<std::string, std::string, std::size_t>> commands = {
      {"analyze", "analyze", 100}, {"filter", "filter", 100}, {"model-check", "model-check --replicas 8", 2000}};
  for (const auto& [title, command, minimum] : commands) {
    EXPECT_NE(section(title).find("at least " + std::to_string(minimum) + " samples"), std::string::npos) << title;
    const auto few = d.write(title + ".csv", whiteNoiseCsv(minimum - 1, 50.0, 13));
    const auto r = runGyroctl(command + " " + few.string() + (title == "filter" ? out : ""), d.path());
    expectOneLineError(r, few.string() + ": " + std::to_string(minimum - 1) + " samples are too few");
    EXPECT_NE(r.err.find("need at least " + std::to_string(minimum)), std::string::npos) << r.err;
    const auto enough = d.write(title + "-enough.csv", whiteNoiseCsv(minimum, 50.0, 13));
    EXPECT_EQ(runGyroctl(command + " " + enough.string() + (title == "filter" ? out : ""), d.path()).exit_status, 0)
        << title;
  }
}
