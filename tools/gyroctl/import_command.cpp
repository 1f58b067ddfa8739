// gyroctl import: convert recordings made by other tools into the CSV that analyze reads.
//
// Format "imucal": the logger of github.com/tomisuarez2/ImuCalibration (MPU6050 on an
// Arduino), read by formats/imucal_recording.hpp: gyro in °/s, accelerometer in g.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

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
};

int runImport(const ImportOptions& opt) {
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
  sub->callback([&run, opt] { run = [opt] { return runImport(*opt); }; });
}

}  // namespace gyrod::gyroctl
