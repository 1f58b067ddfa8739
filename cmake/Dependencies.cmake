# Every dependency is a Debian bookworm package. When one is missing, stop with a
# message that names the package to install, not a CMake stack trace.
include(FindPkgConfig)

macro(gyrod_require found debian_package what)
  if(NOT ${found})
    message(FATAL_ERROR
      "gyrod needs ${what}: install it with\n"
      "    apt-get install ${debian_package}\n")
  endif()
endmacro()

find_package(Eigen3 3.3 QUIET NO_MODULE)
gyrod_require(Eigen3_FOUND libeigen3-dev "Eigen 3 (linear algebra)")

find_package(Boost 1.74 QUIET)
gyrod_require(Boost_FOUND libboost-math-dev "Boost.Math (chi-square and normal distributions)")

find_package(nlohmann_json 3.10 QUIET)
gyrod_require(nlohmann_json_FOUND nlohmann-json3-dev "nlohmann-json (JSON output)")

find_package(CLI11 2.1 QUIET)
gyrod_require(CLI11_FOUND libcli11-dev "CLI11 (command-line parsing)")

find_package(tomlplusplus 3 QUIET)
gyrod_require(tomlplusplus_FOUND libtomlplusplus-dev "toml++ (simulation model files)")

if(GYROD_BUILD_TESTS)
  find_package(GTest QUIET)
  gyrod_require(GTest_FOUND libgtest-dev "GoogleTest (unit tests)")
endif()

if(GYROD_BUILD_BENCHMARKS)
  find_package(benchmark QUIET)
  gyrod_require(benchmark_FOUND libbenchmark-dev "Google Benchmark (benchmarks)")
endif()

find_package(tomlplusplus 3 QUIET)
gyrod_require(tomlplusplus_FOUND libtomlplusplus-dev "toml++ (configuration and model files)")

find_package(spdlog 1.9 QUIET)
gyrod_require(spdlog_FOUND libspdlog-dev "spdlog (daemon logging)")

pkg_check_modules(LIBSYSTEMD QUIET IMPORTED_TARGET libsystemd)
gyrod_require(LIBSYSTEMD_FOUND libsystemd-dev "libsystemd (socket activation, sd_notify)")

# The MQTT publisher (daemon/mqtt_publisher.*): Eclipse Mosquitto's client library, whose own
# thread does the network (connect, reconnect with backoff, send) off gyrod's sample loop.
pkg_check_modules(LIBMOSQUITTO QUIET IMPORTED_TARGET libmosquitto>=2.0)
gyrod_require(LIBMOSQUITTO_FOUND libmosquitto-dev "libmosquitto 2.0 (publishing to an MQTT broker)")

# driver/: libi2c (i2c-tools' SMBus helpers) for /dev/i2c-N, libgpiod v1 for the INT line.
find_path(I2C_INCLUDE_DIR i2c/smbus.h)
find_library(I2C_LIBRARY i2c)
if(I2C_INCLUDE_DIR AND I2C_LIBRARY)
  set(GYROD_I2C_FOUND TRUE)
endif()
gyrod_require(GYROD_I2C_FOUND libi2c-dev "libi2c (i2c/smbus.h, SMBus access to /dev/i2c-N)")
if(NOT TARGET gyrod::i2c)
  add_library(gyrod::i2c UNKNOWN IMPORTED)
  set_target_properties(gyrod::i2c PROPERTIES
    IMPORTED_LOCATION ${I2C_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${I2C_INCLUDE_DIR})
endif()

# libgpiod's v1 API (gpiod_chip_open_lookup, gpiod_line_request_*_events): 1.6.x is what
# Debian bookworm and Raspberry Pi OS ship. v2 changed the API completely.
pkg_check_modules(LIBGPIOD QUIET IMPORTED_TARGET libgpiod>=1.6)
gyrod_require(LIBGPIOD_FOUND libgpiod-dev "libgpiod 1.6 (GPIO line events for the MPU6050 INT pin)")
if(LIBGPIOD_VERSION VERSION_GREATER_EQUAL 2)
  message(FATAL_ERROR
    "gyrod needs the libgpiod v1 API (1.6.x, Debian bookworm); found libgpiod ${LIBGPIOD_VERSION}.\n"
    "    apt-get install libgpiod-dev   (on bookworm this is 1.6.3)\n")
endif()
