// gyroctl import: convert recordings made by other tools into the CSV that analyze reads.
//
// Format "imucal": the logger of github.com/tomisuarez2/ImuCalibration (MPU6050 on an
// Arduino). Header lines "Fs,<Hz>", "Logging Type,<n>", "Initialization time,<s>",
// "Waiting time,<s>", then the column names (ax,ay,az,gx,gy,gz), then one line per
// sample of raw signed 16-bit counts. No timestamps: t = i / Fs (the chip's sample clock).
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "formats/csv_fields.hpp"
#include "formats/output_file.hpp"
#include "formats/quoted_value.hpp"
#include "tools/gyroctl/commands.hpp"
#include "tools/gyroctl/input.hpp"

namespace gyrod::gyroctl {
namespace {

// Gyro sensitivity per FS_SEL (MPU-6050 product specification §6.1): LSB per °/s.
constexpr double kGyroLsbPerDps[4] = {131.0, 65.5, 32.8, 16.4};

struct ImportOptions {
  std::string file;
  std::string output;
  std::string format = "auto";
  int fs_sel = 0;
};

[[noreturn]] void fail(const std::string& path, std::size_t line, const std::string& cause) {
  std::ostringstream s;
  s << path << ':' << line << ": " << cause;
  throw recording::RecordingError(s.str());
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream ss(line);
  std::string item;
  while (std::getline(ss, item, ',')) {
    while (!item.empty() && (item.back() == '\r' || item.back() == ' ')) item.pop_back();
    while (!item.empty() && item.front() == ' ') item.erase(item.begin());
    f.push_back(item);
  }
  if (!line.empty() && line.back() == ',') f.emplace_back();
  return f;
}

bool parseLong(const std::string& s, long& v) {
  if (s.empty()) return false;
  std::size_t used = 0;
  try {
    v = std::stol(s, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used == s.size();
}

int runImport(const ImportOptions& opt) {
  formats::checkOutputTarget(opt.output, {opt.file});  // before the work, and again when writing
  requireNotADirectory(opt.file);
  std::ifstream in(opt.file);
  if (!in) throw recording::RecordingError(opt.file + ": cannot open: " + std::strerror(errno));
  recording::BoundedLineReader reader(in);
  std::string line;
  std::size_t line_no = 0;
  auto next = [&]() -> bool {
    const auto result = reader.next();
    if (result == recording::BoundedLineReader::Result::End) return false;
    ++line_no;
    if (result == recording::BoundedLineReader::Result::TooLong)
      fail(opt.file, line_no, recording::lineTooLongCause(reader.maxBytes()));
    line.assign(reader.line());
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  if (!next()) throw recording::RecordingError(opt.file + ": empty file");
  auto first = splitCsv(line);
  if (opt.format != "auto" && opt.format != "imucal")
    throw std::invalid_argument("--format '" + opt.format + "': known formats are imucal (or auto)");
  if (first.size() != 2 || first[0] != "Fs")
    fail(opt.file, line_no,
         "not an imucal recording: the first line should be 'Fs,<rate>' (found " + formats::quotedValue(line) + ")");
  char* end = nullptr;
  const double fs = std::strtod(first[1].c_str(), &end);
  if (end == first[1].c_str() || *end != '\0' || !(fs > 0.0) || !std::isfinite(fs))
    fail(opt.file, line_no, "sample rate " + formats::quotedValue(first[1]) + " is not a positive number");

  // Skip the remaining key,value header lines up to the column names.
  std::vector<std::string> columns;
  while (next()) {
    auto f = splitCsv(line);
    long dummy = 0;
    if (!f.empty() && !parseLong(f[0], dummy) && (f.size() != 2 || f[0] == "ax" || f[0] == "gx")) {
      columns = f;
      break;
    }
  }
  if (columns.empty()) fail(opt.file, line_no, "no column-name line (ax,ay,az,gx,gy,gz) found");
  int gcol[3] = {-1, -1, -1};
  const auto& names = recording::kGyroColumns;
  for (std::size_t c = 0; c < columns.size(); ++c)
    for (int a = 0; a < 3; ++a)
      if (columns[c] == names[a]) gcol[a] = static_cast<int>(c);
  std::vector<int> present;
  for (int a = 0; a < 3; ++a)
    if (gcol[a] >= 0) present.push_back(a);
  if (present.empty()) fail(opt.file, line_no, "no gyro column (gx, gy or gz) in " + formats::quotedValue(line));

  const double lsb = kGyroLsbPerDps[opt.fs_sel];
  std::string out = "t";
  for (int a : present) out += "," + std::string(names[a]);
  out += '\n';
  std::size_t samples = 0;
  char buf[40];
  while (next()) {
    if (line.empty()) continue;
    auto f = splitCsv(line);
    if (f.size() != columns.size()) {
      std::ostringstream s;
      s << "expected " << columns.size() << " fields, found " << f.size();
      fail(opt.file, line_no, s.str());
    }
    std::snprintf(buf, sizeof buf, "%.17g", static_cast<double>(samples) / fs);
    out += buf;
    for (int a : present) {
      long counts = 0;
      const auto& field = f[static_cast<std::size_t>(gcol[a])];
      const std::string_view column = names[a];
      if (!parseLong(field, counts))
        fail(opt.file, line_no,
             "column '" + std::string(column) + "': " + formats::quotedValue(field) + " is not an integer count");
      if (counts < -32768 || counts > 32767)
        fail(opt.file, line_no, "column '" + std::string(column) + "': " + field + " is outside the 16-bit range");
      std::snprintf(buf, sizeof buf, ",%.17g", static_cast<double>(counts) / lsb);
      out += buf;
    }
    out += '\n';
    ++samples;
  }
  if (samples == 0) fail(opt.file, line_no, "no samples after the header");
  formats::writeFileAtomically(opt.output, out, {opt.file});
  std::fprintf(stderr, "imported %zu samples at %g Hz (FS_SEL %d, %g LSB per deg/s) into %s\n", samples, fs, opt.fs_sel,
               lsb, opt.output.c_str());
  return kExitOk;
}

}  // namespace

void addImportCommand(CLI::App& app, CommandRunner& run) {
  auto opt = std::make_shared<ImportOptions>();
  auto* sub = app.add_subcommand("import", "Convert another tool's recording into gyrod's CSV (t,gx,gy,gz)");
  sub->add_option("FILE", opt->file, "the foreign recording")->required();
  sub->add_option("-o,--output", opt->output, "CSV to write")->required();
  sub->add_option("--format", opt->format, "imucal (ImuCalibration logger) or auto")->default_val("auto");
  sub->add_option("--fs-sel", opt->fs_sel, "gyro full scale the recording was made at (0 = +-250 deg/s)")
      ->default_val(0)
      ->check(CLI::Range(0, 3));
  sub->callback([&run, opt] { run = [opt] { return runImport(*opt); }; });
}

}  // namespace gyrod::gyroctl
