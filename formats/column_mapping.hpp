#pragma once
// `gyroctl import --columns`: any delimited text recording whose columns are named in a
// header line, converted into gyrod's CSV by a mapping such as gx=gx_dps,ax=ax_g,temp=temp_C.
// Lines before the header (a logger's preamble) are skipped: the header is the first line
// that names every mapped column.
#include <cstddef>
#include <iosfwd>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace gyrod::recording {

// The units a foreign file may store each sensor in. Lsb is the chip's raw signed 16-bit
// count, converted at the full scale the recording was made at (FS_SEL, AFS_SEL).
enum class GyroUnit { DegPerS, RadPerS, Lsb };
enum class AccelUnit { G, MetrePerS2, Lsb };

// The gyrod columns a mapping may fill, in the order the output has them.
inline constexpr const char* kImportTargets[] = {"gx", "gy", "gz", "temp", "ax", "ay", "az"};

struct ColumnMapping {
  // (gyrod column, the file's column), e.g. ("gx", "gx_dps"); at least one gyro column.
  std::vector<std::pair<std::string, std::string>> columns;
  std::optional<std::string> time_column;  // seconds; exactly one of time_column and rate_hz
  std::optional<double> rate_hz;           // t = i / rate_hz
  GyroUnit gyro_unit = GyroUnit::DegPerS;
  AccelUnit accel_unit = AccelUnit::G;
  int fs_sel = 0;   // for GyroUnit::Lsb
  int afs_sel = 0;  // for AccelUnit::Lsb
  char delimiter = ',';
};

// Parses --columns "gx=gx_dps,gy=gy_dps,..." into ColumnMapping::columns. Throws
// std::invalid_argument naming the entry (an unknown gyrod column gets the nearest one).
std::vector<std::pair<std::string, std::string>> parseColumnMapping(const std::string& spec);
// "deg/s", "rad/s", "lsb" (and "g", "m/s2", "lsb"); std::invalid_argument otherwise.
GyroUnit parseGyroUnit(const std::string& text);
AccelUnit parseAccelUnit(const std::string& text);
// ",", ";", "tab" (or a tab character); std::invalid_argument otherwise.
char parseDelimiter(const std::string& text);

struct MappedConversion {
  std::string csv;  // header t and the mapped columns in kImportTargets order, then the samples
  std::size_t samples = 0;
  std::size_t header_line = 0;  // the file line that named the columns
  double rate_hz = 0.0;         // the given rate, or from the median spacing of the time column
};

// Reads the whole file from `in` (`path` names it in messages). Throws RecordingError
// "FILE:LINE: cause" naming the column and quoting the value.
MappedConversion convertMappedColumns(std::istream& in, const std::string& path, const ColumnMapping& mapping);

}  // namespace gyrod::recording
