// libFuzzer target: the sensor model file (formats/model_toml.hpp), which gyrod's
// filter.model, `gyroctl simulate --model` and `filter --model` read. An accepted model
// written back must read back to the same file.
#include "formats/model_toml.hpp"
#include "fuzz/fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using gyrod::fuzz::fuzzCheck;
  gyrod::recording::SensorModel model;
  try {
    model = gyrod::recording::parseSensorModelToml(gyrod::fuzz::inputText(data, size), "fuzz.toml");
  } catch (const gyrod::recording::RecordingError&) {
    return 0;
  }
  const std::string written = gyrod::recording::sensorModelToToml(model);
  try {
    const auto again = gyrod::recording::parseSensorModelToml(written, "written.toml");
    const std::string rewritten = gyrod::recording::sensorModelToToml(again);
    if (rewritten != written)
      std::fprintf(stderr, "written:\n%s\nread back and written:\n%s\n", written.c_str(), rewritten.c_str());
    fuzzCheck(rewritten == written, "a written model reads back the same");
  } catch (const gyrod::recording::RecordingError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    fuzzCheck(false, "the model reader accepts what the model writer writes");
  }
  return 0;
}
