// gyrod: the MPU6050 gyro daemon. See README.md and docs/protocol.md.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/sinks/systemd_sink.h>
#include <spdlog/spdlog.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>

#include "daemon/command_line.hpp"
#include "daemon/config.hpp"
#include "daemon/event_loop.hpp"
#include "daemon/gyrod.hpp"

namespace {

// Under systemd (JOURNAL_STREAM set) log straight to the journal with priorities and
// without our own timestamps (journald adds them); otherwise timestamped lines on stderr.
// Thread-safe sinks: the sample thread, the client thread and the workers all log.
void setUpLogging(spdlog::level::level_enum level) {
  std::shared_ptr<spdlog::logger> logger;
  if (std::getenv("JOURNAL_STREAM") != nullptr) {
    logger = std::make_shared<spdlog::logger>("gyrod", std::make_shared<spdlog::sinks::systemd_sink_mt>("gyrod"));
    logger->set_pattern("%v");
  } else {
    logger = spdlog::stderr_color_mt("gyrod");
    logger->set_pattern("%Y-%m-%d %H:%M:%S.%e %^%l%$ %v");
  }
  logger->set_level(level);
  spdlog::set_default_logger(logger);
}

int runGyrod(int argc, char** argv) {
  using namespace gyrod::daemon;
  // Before any thread starts (the recorder's writer), so that signals reach only the
  // loop's signalfd. SIGPIPE: writes to a vanished client fail with EPIPE instead.
  EventLoop::blockSignals({SIGTERM, SIGINT, SIGHUP});
  std::signal(SIGPIPE, SIG_IGN);

  GyrodCommandLine command_line;
  try {
    command_line = parseGyrodCommandLine(argc, argv);
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "gyrod: %s\n", e.what());
    return kExitConfigError;
  }
  if (command_line.exit_code) {
    std::fputs(command_line.message.c_str(), *command_line.exit_code == 0 ? stdout : stderr);
    if (!command_line.message.empty() && command_line.message.back() != '\n')
      std::fputc('\n', *command_line.exit_code == 0 ? stdout : stderr);
    return *command_line.exit_code;
  }
  setUpLogging(command_line.config.log.level);
  try {
    Gyrod gyrod(command_line.config, command_line.config_file);
    return gyrod.run();
  } catch (const ConfigError& e) {  // e.g. a model file named by filter.model that is not one
    spdlog::critical("{}", e.what());
    return kExitConfigError;
  } catch (const std::bad_alloc&) {
    throw;  // main's one line, printed without allocating
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return runGyrod(argc, argv);
  } catch (const std::bad_alloc&) {
    std::fputs(gyrod::daemon::kOutOfMemoryMessage, stderr);
    std::fputc('\n', stderr);
    return gyrod::daemon::kExitOutOfMemory;
  }
}
