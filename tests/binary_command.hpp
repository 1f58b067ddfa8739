#pragma once
// How a test starts one of the project's binaries (gyrod, gyroctl). A cross build runs its tests
// under qemu-user and cannot count on binfmt_misc, so the binary must be started through the same
// emulator: GYROD_TEST_LAUNCHER is CMake's CMAKE_CROSSCOMPILING_EMULATOR (tests/CMakeLists.txt),
// its words separated by spaces (its first an absolute path: execv does not search PATH), and
// empty in a native build.
#include <cstdlib>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#ifndef GYROD_TEST_LAUNCHER
#define GYROD_TEST_LAUNCHER ""
#endif

namespace gyrod::test {

// The argv (argv[0] is the file to exec) that runs `name` from the build's bin folder.
inline std::vector<std::string> binaryArgv(const std::string& name) {
  std::vector<std::string> argv;
  std::istringstream launcher(GYROD_TEST_LAUNCHER);
  for (std::string word; launcher >> word;) argv.push_back(word);
  std::string path = GYROD_BIN_DIR;  // appended, not a + b + c: gcc 12 warns falsely (-Warray-bounds) at -O2
  path += '/';
  path += name;
  argv.push_back(std::move(path));
  return argv;
}

// The same as a shell command prefix, each word single-quoted.
inline std::string binaryShellCommand(const std::string& name) {
  std::string command;
  for (const auto& word : binaryArgv(name)) {
    std::string quoted = "'";
    for (const char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    command += (command.empty() ? "" : " ") + quoted + "'";
  }
  return command;
}

// True when the test runs under qemu-user (cross-test.sh and a cross build's ctest set
// GYROD_TEST_EMULATOR): a test that meets a known emulator gap says so and skips.
inline bool underEmulator() {
  const char* emulator = std::getenv("GYROD_TEST_EMULATOR");
  return emulator != nullptr && *emulator != '\0';
}

}  // namespace gyrod::test
