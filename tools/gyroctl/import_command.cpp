// gyroctl import: convert recordings made by other tools into the CSV that analyze reads.
//
// Format "imucal": the logger of github.com/tomisuarez2/ImuCalibration (MPU6050 on an
// Arduino), read by formats/imucal_recording.hpp: gyro in °/s, accelerometer in g.
// --columns: any delimited file with a header line, by a mapping of its columns onto gyrod's
// (formats/column_mapping.hpp).
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "formats/column_mapping.hpp"
#include "formats/imucal_recording.hpp"
#include "formats/input_file.hpp"
#include "formats/output_file.hpp"
#include "tools/gyroctl/commands.hpp"
#include "tools/gyroctl/input.hpp"

namespace gyrod::gyroctl {
namespace {

struct ImportOptions {
  std::string file;
  std::string output;
  std::string format = "auto";
  int fs_sel = 0;
  int afs_sel = 0;
  std::string columns;  // --columns TARGET=COLUMN,...; empty: a known format
  std::optional<std::string> time_column;
  std::optional<double> rate_hz;
  std::string gyro_unit = "deg/s";
  std::string accel_unit = "g";
  std::string delimiter = ",";
};

int runMappedImport(const ImportOptions& opt) {
  recording::ColumnMapping mapping;
  mapping.columns = recording::parseColumnMapping(opt.columns);
  mapping.time_column = opt.time_column;
  mapping.rate_hz = opt.rate_hz;
  mapping.gyro_unit = recording::parseGyroUnit(opt.gyro_unit);
  mapping.accel_unit = recording::parseAccelUnit(opt.accel_unit);
  mapping.delimiter = recording::parseDelimiter(opt.delimiter);
  mapping.fs_sel = opt.fs_sel;
  mapping.afs_sel = opt.afs_sel;
  if (!mapping.time_column && !mapping.rate_hz)
    throw std::invalid_argument(
        "import --columns: give the time column (--time COLUMN) or the sample rate (--rate HZ)");
  formats::checkOutputTarget(opt.output, {opt.file});  // before the work, and again when writing
  std::istringstream in(formats::readInputFile(opt.file, formats::kImportInput));
  const auto converted = recording::convertMappedColumns(in, opt.file, mapping);
  formats::writeFileAtomically(opt.output, converted.csv, {opt.file});
  const std::string time_source =
      mapping.time_column ? "t from column '" + *mapping.time_column + "'" : "t = i / --rate";
  std::fprintf(stderr, "imported %zu samples at %g Hz (%s; header on line %zu) into %s\n", converted.samples,
               converted.rate_hz, time_source.c_str(), converted.header_line, opt.output.c_str());
  return kExitOk;
}

int runImport(const ImportOptions& opt) {
  if (!opt.columns.empty()) {
    if (opt.format != "auto")
      throw std::invalid_argument("--format " + opt.format + " and --columns: give one (--columns reads any header)");
    return runMappedImport(opt);
  }
  if (opt.time_column || opt.rate_hz)
    throw std::invalid_argument(std::string(opt.time_column ? "--time" : "--rate") +
                                " applies to --columns only (a known format carries its own rate)");
  if (opt.format != "auto" && opt.format != "imucal")
    throw std::invalid_argument("--format '" + opt.format + "': known formats are imucal (or auto)");
  formats::checkOutputTarget(opt.output, {opt.file});  // before the work, and again when writing
  std::istringstream in(formats::readInputFile(opt.file, formats::kImportInput));
  const auto converted = recording::convertImucal(in, opt.file, opt.fs_sel, opt.afs_sel);
  formats::writeFileAtomically(opt.output, converted.csv, {opt.file});
  std::fprintf(stderr, "imported %zu samples at %g Hz (FS_SEL %d, %g LSB per deg/s", converted.samples,
               converted.rate_hz, opt.fs_sel, converted.lsb_per_dps);
  if (converted.accel_columns > 0)
    std::fprintf(stderr, "; %zu accelerometer columns, AFS_SEL %d, %g LSB per g", converted.accel_columns, opt.afs_sel,
                 converted.lsb_per_g);
  std::fprintf(stderr, ") into %s\n", opt.output.c_str());
  return kExitOk;
}

}  // namespace

void addImportCommand(CLI::App& app, CommandRunner& run) {
  auto opt = std::make_shared<ImportOptions>();
  auto* sub =
      app.add_subcommand("import", "Convert another tool's recording into gyrod's CSV (t,gx,gy,gz and ax,ay,az)");
  sub->add_option("FILE", opt->file, "the foreign recording")->required();
  sub->add_option("-o,--output", opt->output, "CSV to write")->required();
  sub->add_option("--format", opt->format, "imucal (ImuCalibration logger) or auto")->default_val("auto");
  sub->add_option("--fs-sel", opt->fs_sel, "gyro full scale the recording was made at (0 = +-250 deg/s)")
      ->default_val(0)
      ->check(CLI::Range(0, 3));
  sub->add_option("--afs-sel", opt->afs_sel, "accelerometer full scale the recording was made at (0 = +-2 g)")
      ->default_val(0)
      ->check(CLI::Range(0, 3));
  sub->add_option("--columns", opt->columns,
                  "map the file's columns onto gyrod's: gx=COL,gy=COL,gz=COL[,ax=..,ay=..,az=..][,temp=COL]");
  auto* time = sub->add_option("--time", opt->time_column, "with --columns: the column of time stamps in seconds");
  sub->add_option("--rate", opt->rate_hz, "with --columns: the sample rate in Hz (t = i / rate)")->excludes(time);
  sub->add_option("--gyro-unit", opt->gyro_unit, "with --columns: deg/s, rad/s or lsb (at --fs-sel)")
      ->default_val("deg/s");
  sub->add_option("--accel-unit", opt->accel_unit, "with --columns: g, m/s2 or lsb (at --afs-sel)")->default_val("g");
  sub->add_option("--delimiter", opt->delimiter, "with --columns: the field separator, ',', ';' or tab")
      ->default_val(",");
  sub->callback([&run, opt] { run = [opt] { return runImport(*opt); }; });
}

}  // namespace gyrod::gyroctl
