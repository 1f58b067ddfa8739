// libFuzzer target: the recording CSV reader (formats/recording_csv.hpp), the reader of
// every file `gyroctl analyze`, `filter`, `model-check` and gyrod's replay mock take.
#include <cmath>
#include <sstream>

#include "formats/recording_csv.hpp"
#include "fuzz/fuzz_check.hpp"

namespace {

using gyrod::fuzz::fuzzCheck;

bool allFinite(const std::vector<double>& values) {
  for (const double v : values)
    if (!std::isfinite(v)) return false;
  return true;
}

// A column is absent (empty) or has one value per sample.
bool absentOrFull(const std::vector<double>& column, std::size_t samples) {
  return column.empty() || column.size() == samples;
}

void checkAccepted(const gyrod::recording::Recording& rec) {
  const std::size_t n = rec.size();
  fuzzCheck(n > 0, "an accepted recording has samples");
  fuzzCheck(rec.axes.size() == rec.axis_names.size(), "one vector per axis name");
  for (const auto& axis : rec.axes) fuzzCheck(axis.size() == n && allFinite(axis), "every axis full and finite");
  fuzzCheck(absentOrFull(rec.t, n) && allFinite(rec.t), "t absent or full and finite");
  fuzzCheck(absentOrFull(rec.temp, n) && allFinite(rec.temp), "temp absent or full and finite");
  for (const auto& truth : rec.true_rate)
    fuzzCheck(absentOrFull(truth, n) && allFinite(truth), "truth absent or full and finite");
  fuzzCheck(rec.line_numbers.size() == n, "one line number per sample");
  for (const auto& lost : rec.lost) fuzzCheck(lost.before_sample <= n, "a lost-samples record before a sample");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(gyrod::fuzz::inputText(data, size));
  try {
    const auto rec = gyrod::recording::parseRecordingCsv(in, "fuzz.csv");
    checkAccepted(rec);
    if (rec.t.size() >= 2) {
      const double rate_hz = gyrod::recording::sampleRateFromTimes(rec);
      fuzzCheck(rate_hz > 0.0 && std::isfinite(rate_hz), "a rate from strictly increasing t is positive and finite");
    }
  } catch (const gyrod::recording::RecordingError&) {}
  return 0;
}
