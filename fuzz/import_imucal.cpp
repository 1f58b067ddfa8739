// libFuzzer target: `gyroctl import`'s reader of the ImuCalibration logger's files
// (formats/imucal_recording.hpp). What it converts must be a recording that analyze reads.
#include <sstream>

#include "formats/imucal_recording.hpp"
#include "formats/recording_csv.hpp"
#include "fuzz/fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using gyrod::fuzz::fuzzCheck;
  std::istringstream in(gyrod::fuzz::inputText(data, size));
  const int fs_sel = static_cast<int>(size % 4);  // every full scale, without spending input bytes
  gyrod::recording::ImucalConversion converted;
  try {
    converted = gyrod::recording::convertImucal(in, "fuzz.txt", fs_sel);
  } catch (const gyrod::recording::RecordingError&) {
    return 0;
  }
  fuzzCheck(converted.samples > 0, "an accepted file has samples");
  std::istringstream csv(converted.csv);
  try {
    const auto rec = gyrod::recording::parseRecordingCsv(csv, "imported.csv");
    fuzzCheck(rec.size() == converted.samples, "the imported CSV holds every sample");
  } catch (const gyrod::recording::RecordingError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    fuzzCheck(false, "the recording reader accepts what the importer writes");
  }
  return 0;
}
