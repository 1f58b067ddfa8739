#pragma once
// The lines of a recording file as gyrod writes them and readRecordingCsv reads them back:
//
//   # gyrod recording, opened 2025-01-01T12:00:00Z          header comments
//   # continues gyro-20250101T115000Z-000003.csv            (a file after a rotation)
//   # <any comment the writer adds>
//   t,gx,gy,gz,temp                                          the columns (s, °/s, °/s, °/s, °C)
//   0.02,0.0123,-0.004,0.0071,25.5                           one line per sample, each value in
//                                                            its shortest round-trip form
//   # GAP seq=123 t=2.46 count=4 reason=fifo_overflow        samples the device lost
//   # DROPPED count=7 reason=ring_full                       samples the writer lost
//   # NONFINITE 0.04,nan,2,3,25                              a sample the reader would reject
//
// Every other '#' line is a comment. The formatting functions write into a caller-owned
// RecordingLine, so the recorder formats sample after sample without allocating.
#include <array>
#include <cstddef>
#include <cstdint>
#include <ctime>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gyrod::recording {

// The column line of every file gyrod writes.
inline constexpr std::string_view kColumnsLine = "t,gx,gy,gz,temp\n";

// The UTC calendar time of `unix_seconds`, as gmtime_r gives it but without time_t, which is
// 32 bits on 32-bit Debian (armhf, bookworm): there gmtime_r cannot name a time after
// 2038-01-19T03:14:07Z. For strftime's date and time fields.
std::tm utcCalendarTime(std::int64_t unix_seconds);

// The comment lines that start a file, up to (not including) kColumnsLine. `previous_file`
// is the name of the file this one continues after a rotation; empty for none.
std::string recordingHeaderComments(std::int64_t opened_unix_seconds, std::string_view previous_file,
                                    const std::vector<std::string>& comments);

// One formatted line, '\n' included. 256 bytes hold the longest: "# NONFINITE " and five
// doubles of at most 24 characters each, or a GAP line with its 23-character reason.
struct RecordingLine {
  std::array<char, 256> bytes{};
  std::size_t size = 0;
  std::string_view view() const { return {bytes.data(), size}; }
};

// "t,gx,gy,gz,temp\n"; a sample holding a non-finite value is written as a "# NONFINITE "
// comment instead, since the reader rejects such a sample and the file must stay readable.
std::string_view formatSampleLine(RecordingLine& line, double t_s, double gx_dps, double gy_dps, double gz_dps,
                                  double temp_c);
// "# GAP seq=S t=T count=N reason=R\n"; an empty reason is written as "unknown".
std::string_view formatGapLine(RecordingLine& line, std::uint64_t seq, double t_s, std::uint64_t count,
                               std::string_view reason);
// "# DROPPED count=N reason=R\n".
std::string_view formatDroppedLine(RecordingLine& line, std::uint64_t count, std::string_view reason);

// A reason is one token: characters other than [A-Za-z0-9_.-] are written as '_'.
char reasonCharacter(char c);

// A "# GAP" line (samples the device lost) or a "# DROPPED" line (samples the writer lost).
struct LostSamples {
  enum class Kind { Gap, Dropped };
  Kind kind = Kind::Gap;
  std::uint64_t count = 0;
  std::string reason;
  std::uint64_t seq = 0;          // Gap: sequence number of the first missing sample
  double t_s = 0.0;               // Gap: time of the first missing sample
  std::size_t line = 0;           // file line (set by the reader)
  std::size_t before_sample = 0;  // index of the first sample after the line (set by the reader)
  bool operator==(const LostSamples&) const = default;
};

// The GAP or DROPPED record of a (trimmed) line exactly as format*Line writes it; nullopt
// for any other line, a malformed "# GAP ..." included (that is an ordinary comment).
std::optional<LostSamples> parseLostSamplesLine(std::string_view line);

}  // namespace gyrod::recording
