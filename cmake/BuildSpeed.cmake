# Build time (docs/testing.md, "CI time"): most of a TU's compile time here is the third-party headers
# (GoogleTest, nlohmann-json, CLI11, spdlog, toml++, Eigen) parsed again in every file.
#
# GYROD_PCH: each heavy target precompiles the headers most of its files include, once per target
# (target_precompile_headers; the compiler force-includes the result into each of its files).
# Sources whose own compile options differ from their target's (the -ffp-contract=off files of
# processing/simulation, base/) get no precompiled header: a header precompiled under other
# code-generation options is not the same input.
#
# GYROD_UNITY_TESTS: the test executables are compiled as unity batches (CMake's UNITY_BUILD, a
# few test files included into one TU), which parses the headers and instantiates GoogleTest's
# templates once a batch instead of once a file. The product targets are unity-built only when
# CMAKE_UNITY_BUILD is given on the command line (the sanitized tree in .ci/run does).
option(GYROD_PCH "Precompile the heavy third-party and standard headers of the slowest targets" ON)
option(GYROD_UNITY_TESTS "Compile the test executables as unity batches" ON)
set(GYROD_UNITY_TEST_BATCH_SIZE 8 CACHE STRING "Test files a unity batch includes")

# gyrod_precompile(TARGET HEADER...): HEADER as <name> for a system header.
function(gyrod_precompile target)
  if(NOT GYROD_PCH OR NOT TARGET ${target})
    return()
  endif()
  target_precompile_headers(${target} PRIVATE ${ARGN})
  get_target_property(sources ${target} SOURCES)
  get_target_property(dir ${target} SOURCE_DIR)
  foreach(source IN LISTS sources)
    get_source_file_property(options ${source} DIRECTORY ${dir} COMPILE_OPTIONS)
    if(options)
      set_source_files_properties(${source} DIRECTORY ${dir} PROPERTIES SKIP_PRECOMPILE_HEADERS ON)
    endif()
  endforeach()
endfunction()

# The standard headers most files of the tree include.
set(GYROD_PCH_STD <algorithm> <array> <cmath> <cstdint> <cstdio> <cstring> <filesystem> <fstream>
    <functional> <memory> <optional> <sstream> <stdexcept> <string> <string_view> <vector>)
