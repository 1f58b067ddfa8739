# gyrod's configuration loader, command line and sample recorder (daemon/config.*,
# daemon/command_line.*, daemon/recorder.*).
# Included from daemon/CMakeLists.txt:  include(${CMAKE_CURRENT_SOURCE_DIR}/config_recorder.cmake)
find_package(Threads REQUIRED)
add_library(gyrod_daemon_config STATIC
  ${CMAKE_CURRENT_LIST_DIR}/command_line.cpp
  ${CMAKE_CURRENT_LIST_DIR}/config.cpp
  ${CMAKE_CURRENT_LIST_DIR}/memory_budget.cpp
  ${CMAKE_CURRENT_LIST_DIR}/recorder.cpp)
target_include_directories(gyrod_daemon_config PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(gyrod_daemon_config
  PUBLIC spdlog::spdlog gyrod_motion gyrod_formats Threads::Threads
  PRIVATE CLI11::CLI11)
target_compile_definitions(gyrod_daemon_config PRIVATE GYROD_VERSION="${PROJECT_VERSION}")
