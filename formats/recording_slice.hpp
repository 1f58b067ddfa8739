#pragma once
// Inside the recording reader (recording_csv.cpp): the rules of the sample lines and what a
// slice of them yields. Slices are parsed apart, on both cores, and appended in file order.
#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "formats/csv_fields.hpp"
#include "formats/recording_csv.hpp"
#include "formats/recording_format.hpp"

namespace gyrod::recording::slice_detail {

constexpr std::array<std::string_view, 11> kKnownColumns = {"t",  "gx", "gy", "gz", "temp", "wx",
                                                            "wy", "wz", "ax", "ay", "az"};
// gyrod's columns a sample may leave empty (recording_format.hpp): read as NaN then.
constexpr std::array<std::string_view, 17> kStreamColumns = {
    "time", "gx_rate", "gy_rate", "gz_rate", "gx_bias", "gy_bias", "gz_bias",         "still",      "qw",
    "qx",   "qy",      "qz",      "roll",    "pitch",   "heading", "inclination_std", "heading_std"};

inline bool isSkippable(std::string_view line) { return line.empty() || line.front() == '#'; }

// What a slice of the sample lines yields, numbered from the slice: its first line is 1 and
// its first sample 0. Slices are parsed apart (on both cores) and appended in file order.
struct SliceResult {
  std::vector<std::vector<double>> columns;   // one per field of the header, when stored here
  std::vector<std::vector<double>*> store;    // where the values go: `columns`, or the recording's
  std::vector<Recording::LineRun> line_runs;  // runs within the slice
  std::vector<std::size_t> sample_lines;      // each sample's line (only with ReadOptions::line_numbers)
  std::vector<LostSamples> lost;              // GAP and DROPPED lines
  std::size_t lines = 0;                      // lines read (up to and including an error's)
  std::size_t samples = 0;
  std::string error;  // the cause of the first bad line (the slice's last), empty when none

  // Empty again, keeping the columns' memory for the next slice; the values go to `targets`
  // (the recording's columns) when given, else to this slice's own columns.
  void clear(std::size_t column_count, const std::vector<std::vector<double>*>* targets = nullptr) {
    columns.resize(targets ? 0 : column_count);
    store.clear();
    for (std::size_t c = 0; c < column_count; ++c) {
      if (targets) {
        store.push_back((*targets)[c]);
      } else {
        columns[c].clear();
        store.push_back(&columns[c]);
      }
    }
    line_runs.clear();
    sample_lines.clear();
    lost.clear();
    lines = samples = 0;
    error.clear();
  }
};

// The sample lines' rules, the same for every slice: field count, numbers, comments and
// GAP/DROPPED records, the line length limit, one column for bare numbers.
struct SliceParser {
  std::vector<std::string> column_names;  // for messages ("value" for bare numbers)
  std::vector<bool> may_be_empty;         // gyrod's stream columns: an empty field is NaN
  bool bare_numbers = false;
  bool line_numbers = false;
  std::size_t max_bytes = kMaxLineBytes;

  // Parses the lines of `text` (each ending in '\n' but maybe the last) into `out`,
  // stopping at the first bad line.
  void parse(std::string_view text, SliceResult& out) const;

 private:
  std::size_t parsePlainLine(std::string_view text, std::size_t start, SliceResult& out) const;
  void recordSample(SliceResult& out) const;
  bool consume(std::string_view line, std::span<std::string_view> fields, SliceResult& out) const;
};

}  // namespace gyrod::recording::slice_detail
