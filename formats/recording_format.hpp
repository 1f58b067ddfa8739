#pragma once
// The lines of a recording file as gyrod writes them and readRecordingCsv reads them back
// (docs/recording-format.md is the reference):
//
//   t,gx,gy,gz,temp,time,ax,ay,az,gx_rate,gy_rate,gz_rate,gx_bias,gy_bias,gz_bias,still,
//   qw,qx,qy,qz,roll,pitch,heading,inclination_std,heading_std
//                                                            the columns, always the FIRST line
//   # gyrod recording, opened 2025-01-01T12:00:00Z          then comments
//   # continues gyro-20250101T115000Z-000003.csv            (a file after a rotation)
//   # <any comment the writer adds>
//   0.02,0.0123,-0.004,0.0071,25.5,1735732800.020000,...    one line per sample
//   # GAP seq=123 t=2.46 count=4 reason=fifo_overflow        samples the device lost
//   # DROPPED count=7 reason=ring_full                       samples the writer lost
//   # NONFINITE 0.04,nan,2,3,25,...                          a sample the reader would reject
//   #                                                        padding to the end of a page
//
// t,gx,gy,gz,temp (s, °/s, °/s, °/s, °C) come first and are in every file; the others are
// there when the writer has them (SampleColumns): the wall clock `time` (UTC epoch s, 6
// decimals), the accelerometer ax,ay,az [g], and the rate stream's rate and bias per axis
// [°/s] and still (1/0), and the orientation RATE published (quaternion, Z-Y-X angles [°] and
// their 1σ [°], docs/attitude.md). Values are in their shortest round-trip form, except `time`; a value
// the sample does not have (a rate during the start-up estimation) is an empty field.
// The column line comes first because numpy's genfromtxt(names=True) takes the first line
// for the names, even a comment; pandas' read_csv(comment='#') and genfromtxt(comments='#')
// skip every '#' line after it. The formatting functions write into a caller-owned
// RecordingLine, so the recorder formats sample after sample without allocating.
#include <array>
#include <cstddef>
#include <cstdint>
#include <ctime>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gyrod::recording {

// The five columns every file has, first; with nothing after them, the whole column line.
inline constexpr std::string_view kColumnsLine = "t,gx,gy,gz,temp\n";
// The columns after them, in this order, when the file has them.
inline constexpr std::string_view kTimeColumn = "time";  // wall clock, UTC epoch s
inline constexpr std::array<std::string_view, 3> kRateColumns = {"gx_rate", "gy_rate", "gz_rate"};  // °/s
inline constexpr std::array<std::string_view, 3> kBiasColumns = {"gx_bias", "gy_bias", "gz_bias"};  // °/s
inline constexpr std::string_view kStillColumn = "still";  // 1 still, 0 moving, empty: no detector
// The orientation, as `gyroctl attitude` names its output columns.
inline constexpr std::array<std::string_view, 9> kAttitudeColumns = {
    "qw", "qx", "qy", "qz", "roll", "pitch", "heading", "inclination_std", "heading_std"};
// Decimals of the `time` column: µs, as RATE's "time" (docs/protocol.md).
inline constexpr int kTimeDecimals = 6;

// Which optional columns a file has (after t,gx,gy,gz,temp, in the order of the fields).
struct SampleColumns {
  bool time = false;      // time
  bool accel = false;     // ax,ay,az (kAccelColumns)
  bool rate = false;      // gx_rate..gz_rate, gx_bias..gz_bias, still
  bool attitude = false;  // kAttitudeColumns
  bool operator==(const SampleColumns&) const = default;
};
// The column line, '\n' included.
std::string columnsLine(const SampleColumns& columns);

// One sample as a recording holds it. Plain data (a recorder's ring slot holds one).
struct SampleValues {
  double t_s = 0.0;  // CLOCK_MONOTONIC s of the data-ready edge
  double gx_dps = 0.0, gy_dps = 0.0, gz_dps = 0.0;
  double temp_c = 0.0;
  std::int64_t wall_ns = 0;  // CLOCK_REALTIME ns of the same edge; 0: unknown (empty field)
  std::array<double, 3> accel_g{kNoValue, kNoValue, kNoValue};
  std::array<double, 3> rate_dps{kNoValue, kNoValue, kNoValue};
  std::array<double, 3> bias_dps{kNoValue, kNoValue, kNoValue};
  std::int8_t still = -1;  // 1 still, 0 moving, -1 no verdict (empty field)
  // In kAttitudeColumns' order: qw, qx, qy, qz, roll, pitch, heading, their 1σ.
  std::array<double, 9> attitude{kNoValue, kNoValue, kNoValue, kNoValue, kNoValue,
                                 kNoValue, kNoValue, kNoValue, kNoValue};
  static constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();
};

// The UTC calendar time of `unix_seconds`, as gmtime_r gives it but without time_t, which is
// 32 bits on 32-bit Debian (armhf, bookworm): there gmtime_r cannot name a time after
// 2038-01-19T03:14:07Z. For strftime's date and time fields.
std::tm utcCalendarTime(std::int64_t unix_seconds);

// The comment lines that follow the column line at the top of a file. `previous_file` is
// the name of the file this one continues after a rotation; empty for none.
std::string recordingHeaderComments(std::int64_t opened_unix_seconds, std::string_view previous_file,
                                    const std::vector<std::string>& comments);

// One formatted line, '\n' included. 768 bytes hold the longest: "# NONFINITE " (12), 23
// doubles of at most 24 characters (552), `time` (at most 24: 17 digits, the point, 6
// decimals), `still` (1), 24 commas and the newline: 614; or a GAP line with its
// 23-character reason (about 110).
struct RecordingLine {
  std::array<char, 768> bytes{};
  std::size_t size = 0;
  std::string_view view() const { return {bytes.data(), size}; }
};

// The sample's line for a file of these columns. A sample whose t, gx, gy, gz or temp is not
// finite is written as a "# NONFINITE " comment instead, since the reader rejects such a
// sample and the file must stay readable; a non-finite optional value is an empty field.
std::string_view formatSampleLine(RecordingLine& line, const SampleColumns& columns, const SampleValues& sample);
// "t,gx,gy,gz,temp\n" alone (a file of kColumnsLine).
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
