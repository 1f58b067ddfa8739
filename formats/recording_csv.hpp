#pragma once
// Recording files: CSV with a header naming any of the columns t,gx,gy,gz,temp
// (seconds, °/s, °/s, °/s, °C) and, in what `gyroctl simulate --motion` writes, the true
// rates wx,wy,wz (°/s), the accelerometer's ax,ay,az (g) when it was recorded, and in what
// gyrod records, the wall clock `time` and the rate stream gx_rate..gz_rate, gx_bias..gz_bias,
// still (recording_format.hpp, where an empty field is a value the sample did not have); or a
// file of bare numbers (one column, one axis). Lines
// starting with '#' are comments; the "# GAP" and "# DROPPED" lines gyrod writes
// (recording_format.hpp) are returned as LostSamples records, and a line that only looks
// like one (say "# GAP at 12 s") stays an ordinary comment, as every '#' line always was.
#include <array>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "formats/recording_format.hpp"

namespace gyrod::formats {
struct InputKind;  // formats/input_file.hpp
}

namespace gyrod::recording {

// A problem with an input file, already phrased for the user: "FILE:LINE: cause".
class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Recording {
  std::string path;
  std::vector<double> t;                  // empty when the file has no t column
  std::vector<std::string> axis_names;    // "gx", "gy", "gz" in file order (or "x" for bare numbers)
  std::vector<std::vector<double>> axes;  // one vector per axis_names entry
  std::vector<double> temp;               // empty when absent
  // The truth wx, wy, wz of a simulated recording with motion, per axis; empty when absent
  // (gyrod's recordings never have it: the chip cannot know it).
  std::array<std::vector<double>, 3> true_rate;
  // Accelerometer ax, ay, az [g] per axis; empty when absent.
  std::array<std::vector<double>, 3> accel_g;
  // gyrod's recordings: the wall clock [UTC epoch s] of each sample; empty when absent.
  std::vector<double> time;
  // gyrod's recordings: the rate stream as published, rate and bias [°/s] per axis and still
  // (1 still, 0 moving), NaN where the field is empty; each empty when its column is absent.
  std::array<std::vector<double>, 3> rate, bias;
  std::vector<double> still;
  // gyrod's recordings: the orientation RATE published, in kAttitudeColumns' order (qw, qx, qy,
  // qz, roll, pitch, heading, their 1σ), NaN where empty; each empty when its column is absent.
  std::array<std::vector<double>, 9> attitude;
  std::vector<std::size_t> line_numbers;  // file line of each sample (empty without ReadOptions::line_numbers)
  // The same lines, compactly: a run starts wherever a sample's line does not follow the
  // previous sample's (after the header, a comment, an empty line).
  struct LineRun {
    std::size_t first_sample = 0;
    std::size_t first_line = 0;
  };
  std::vector<LineRun> line_runs;
  std::vector<LostSamples> lost;  // the GAP and DROPPED lines, in file order
  std::size_t size() const { return axes.empty() ? 0 : axes.front().size(); }
  const std::vector<double>* axis(const std::string& name) const;
  // The file line of sample i, for messages (from line_numbers when kept, else line_runs).
  std::size_t lineOfSample(std::size_t i) const;
};

// The gyro columns in axis order: gx is the x axis (0), gy the y axis (1), gz the z axis (2).
inline constexpr std::array<std::string_view, 3> kGyroColumns = {"gx", "gy", "gz"};
// The truth columns in axis order (gyroctl simulate --motion).
inline constexpr std::array<std::string_view, 3> kTruthColumns = {"wx", "wy", "wz"};
// The accelerometer columns in axis order, in g.
inline constexpr std::array<std::string_view, 3> kAccelColumns = {"ax", "ay", "az"};
// The name Recording gives the one column of a file of bare numbers.
inline constexpr std::string_view kBareNumbersColumn = "x";
// The axis (0 = x, 1 = y, 2 = z) a recording column measures: gx, gy, gz, and the column
// of a file of bare numbers, which stands for x. nullopt for any other name.
std::optional<std::size_t> axisOfColumn(std::string_view column);

// Lines between two calls of ReadOptions::progress.
inline constexpr std::size_t kProgressLines = std::size_t{1} << 20;

struct ReadOptions {
  // Fill Recording::line_numbers (8 bytes a sample); lineOfSample() answers without it.
  bool line_numbers = true;
  // Called every kProgressLines lines with the lines and bytes read so far.
  std::function<void(std::size_t lines, std::uint64_t bytes)> progress;
  // What the file is read as (its size limit, formats/input_file.hpp); null: a recording
  // (formats::kRecordingInput).
  const formats::InputKind* input_kind = nullptr;
};

// Reads and validates the whole file in one pass (numbers by std::from_chars, no allocation
// per line), opened by formats::openInputFile. Throws RecordingError naming file, line and cause.
Recording readRecordingCsv(const std::string& path, const ReadOptions& options = {});
// The same from a stream already open; `path` names it in messages and in Recording::path.
Recording parseRecordingCsv(std::istream& in, const std::string& path);

// Sample rate implied by t: 1 / median spacing. Throws RecordingError if t is not
// strictly increasing (naming file and line).
double sampleRateFromTimes(const Recording& r);

}  // namespace gyrod::recording
