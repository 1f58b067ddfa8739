// Hostile or broken input files: a line is bounded while it is read, and a bad value is
// quoted for the message bounded and with every terminal-active character escaped.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "formats/csv_fields.hpp"
#include "formats/motion_spec.hpp"
#include "formats/quoted_value.hpp"
#include "formats/recording_csv.hpp"

using namespace gyrod::recording;
using gyrod::formats::kQuotedValueMaxChars;
using gyrod::formats::quotedValue;
namespace fs = std::filesystem;

namespace {

class HostileTempFile {
 public:
  explicit HostileTempFile(const std::string& text) {
    path_ = (fs::temp_directory_path() / ("gyrod-hostile-test-" + std::to_string(::getpid()) + ".csv")).string();
    std::ofstream(path_, std::ios::binary) << text;
  }
  ~HostileTempFile() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

std::string hostileErrorOf(const std::string& text, std::string* path = nullptr) {
  HostileTempFile f(text);
  if (path) *path = f.path();
  try {
    (void)readRecordingCsv(f.path());
  } catch (const RecordingError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(QuotedValue, PlainValuesAreQuotedAsTheyAre) {
  EXPECT_EQ(quotedValue("abc"), "'abc'");
  EXPECT_EQ(quotedValue(""), "''");
  EXPECT_EQ(quotedValue("25 °C"), "'25 °C'");  // printable UTF-8 stays readable
}

TEST(QuotedValue, ControlAndBidirectionalCharactersAreEscaped) {
  EXPECT_EQ(quotedValue("a\x1b[31mred"), "'a\\x1B[31mred'");
  EXPECT_EQ(quotedValue(std::string("a\0b", 3)), "'a\\x00b'");
  EXPECT_EQ(quotedValue("a\x7f\tb\r\n"), "'a\\x7F\\x09b\\x0D\\x0A'");
  EXPECT_EQ(quotedValue("x\u202Ey"), "'x\\u{202E}y'");
  EXPECT_EQ(quotedValue("\u202A\u2066\u2069"), "'\\u{202A}\\u{2066}\\u{2069}'");
  EXPECT_EQ(quotedValue("\u0085"), "'\\u{0085}'");     // C1 control (NEL)
  EXPECT_EQ(quotedValue("\xff\xc3"), "'\\xFF\\xC3'");  // not UTF-8
  EXPECT_EQ(quotedValue("a\\x1B"), "'a\\\\x1B'");      // a literal backslash stays distinguishable
}

TEST(QuotedValue, LongValuesAreCutWithTheirLength) {
  const std::string big(50'000'000, '9');
  const std::string q = quotedValue(big);
  EXPECT_EQ(q, "'" + std::string(kQuotedValueMaxChars, '9') + "…' (50000000 bytes)");
  EXPECT_EQ(quotedValue(std::string(80, 'x')), "'" + std::string(80, 'x') + "'");
}

TEST(BoundedLineReader, StopsAtTheLimitWhileReading) {
  std::istringstream in("abcd\n\nabcdefghijkl\nnever read\n");
  BoundedLineReader r(in, 4);
  ASSERT_EQ(r.next(), BoundedLineReader::Result::Line);
  EXPECT_EQ(r.line(), "abcd");
  ASSERT_EQ(r.next(), BoundedLineReader::Result::Line);
  EXPECT_EQ(r.line(), "");
  EXPECT_EQ(r.next(), BoundedLineReader::Result::TooLong);
  // Only the limit and one byte were taken from the stream, not the whole line.
  EXPECT_EQ(in.gcount(), 5);
}

TEST(BoundedLineReader, LastLineWithoutNewlineAndNulBytes) {
  std::istringstream in(std::string("a\0b\nxyz", 7));
  BoundedLineReader r(in, 4);
  ASSERT_EQ(r.next(), BoundedLineReader::Result::Line);
  EXPECT_EQ(r.line(), std::string_view("a\0b", 3));
  ASSERT_EQ(r.next(), BoundedLineReader::Result::Line);
  EXPECT_EQ(r.line(), "xyz");
  EXPECT_EQ(r.next(), BoundedLineReader::Result::End);
  std::istringstream exact("abcde");
  BoundedLineReader e(exact, 4);
  EXPECT_EQ(e.next(), BoundedLineReader::Result::TooLong);
}

TEST(RecordingHostileInput, ALineLongerThanTheLimitIsRefusedWithItsLine) {
  std::string path;
  const std::string long_line = "0.04," + std::string(kMaxLineBytes, '1') + "\n";
  const auto e = hostileErrorOf("t,gx\n0,1\n0.02,2\n" + long_line + "0.06,3\n", &path);
  EXPECT_EQ(e, path + ":4: line longer than 65536 bytes (the limit for one line)");
  // Exactly the limit is still a line (here refused for its value, not its length).
  const auto at_limit = hostileErrorOf("t,gx\n0," + std::string(kMaxLineBytes - 2, '1') + "\n", &path);
  EXPECT_EQ(at_limit.rfind(path + ":2: column 'gx': non-finite value '111", 0), 0u) << at_limit.substr(0, 200);
  EXPECT_NE(at_limit.find("…' (65534 bytes)"), std::string::npos) << at_limit.substr(0, 200);
}

TEST(RecordingHostileInput, BadValuesAreEscapedAndCut) {
  std::string path;
  std::string e = hostileErrorOf("t,gx\n0,1\n0.02,\x1b]0;pwned\x07\n", &path);
  EXPECT_EQ(e, path + ":3: column 'gx': '\\x1B]0;pwned\\x07' is not a number");
  e = hostileErrorOf("t,gx\n0,1\u202E2\n", &path);
  EXPECT_EQ(e, path + ":2: column 'gx': '1\\u{202E}2' is not a number");
  const char with_nul[] = "t,gx\n0,1\0 trailing hidden\n";
  e = hostileErrorOf(std::string(with_nul, sizeof with_nul - 1), &path);
  EXPECT_EQ(e, path + ":2: column 'gx': '1\\x00 trailing hidden' is not a number");
  const std::string huge_number = "1" + std::string(20'000, '0');
  e = hostileErrorOf("t,gx\n0," + huge_number + "\n", &path);
  EXPECT_EQ(e, path + ":2: column 'gx': non-finite value '" + huge_number.substr(0, kQuotedValueMaxChars) +
                   "…' (20001 bytes)");
  e = hostileErrorOf("t,g\x1b[2J\n", &path);
  EXPECT_EQ(e, path + ":1: unknown column 'g\\x1B[2J' (expected any of t,gx,gy,gz,temp,wx,wy,wz,ax,ay,az)");
}

// A directory opens as a stream but reads nothing: it must not pass for an empty file, and is
// refused before it is opened (formats/input_file.hpp).
TEST(RecordingHostileInput, ADirectoryIsNotAnEmptyFile) {
  const fs::path dir = fs::temp_directory_path() / ("gyrod-hostile-dir-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string message;
  try {
    (void)readRecordingCsv(dir.string());
  } catch (const RecordingError& e) {
    message = e.what();
  }
  fs::remove(dir);
  EXPECT_EQ(message.rfind(dir.string() + ":", 0), 0u) << message;
  EXPECT_NE(message.find("cannot read: it is a directory, not a file"), std::string::npos) << message;
  EXPECT_EQ(message.find("empty file"), std::string::npos) << message;
}

// The motion CSV of `simulate --motion` is bounded like a recording.
TEST(RecordingHostileInput, AMotionCsvLineLongerThanTheLimitIsRefusedWithItsLine) {
  HostileTempFile f("t,wz\n0,1\n1," + std::string(kMaxLineBytes + 10, '2') + "\n2,3\n");
  std::string message;
  try {
    (void)readMotionCsv(f.path());
  } catch (const RecordingError& e) {
    message = e.what();
  }
  EXPECT_EQ(message, f.path() + ":3: line longer than 65536 bytes (the limit for one line)");
  HostileTempFile g("t,wz\n0,1\n1,2");  // no newline at the end: still read
  EXPECT_EQ(readMotionCsv(g.path()).rateAt(1.0)[2], 2.0);
}
