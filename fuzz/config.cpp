// libFuzzer target: gyrod's configuration (daemon/config.hpp's parseConfig on TOML text;
// the reference checks, which read other files, stay off).
#include "daemon/config.hpp"
#include "fuzz/fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)gyrod::daemon::parseConfig(gyrod::fuzz::inputText(data, size), "fuzz.toml");
  } catch (const gyrod::daemon::ConfigError&) {}
  return 0;
}
