#pragma once
// Each gyroctl subcommand lives in its own file and registers itself here: it adds a
// CLI11 subcommand to `app` and, when that subcommand is parsed, sets `run` to the
// function that executes it and returns the process exit status.
#include <CLI/CLI.hpp>
#include <functional>

#include "tools/gyroctl/exit_codes.hpp"

namespace gyrod::gyroctl {

using CommandRunner = std::function<int()>;

// Exit statuses shared by all subcommands (the whole table: tools/gyroctl/exit_codes.hpp).
inline constexpr int kExitOk = toInt(ExitCode::Ok);
inline constexpr int kExitUsage = toInt(ExitCode::Usage);      // bad command line, bad option value
inline constexpr int kExitFailure = toInt(ExitCode::Failure);  // anything else

void addAnalyzeCommand(CLI::App& app, CommandRunner& run);
void addFilterCommand(CLI::App& app, CommandRunner& run);
void addAttitudeCommand(CLI::App& app, CommandRunner& run);
void addImportCommand(CLI::App& app, CommandRunner& run);
void addSimulateCommand(CLI::App& app, CommandRunner& run);
// watch, allan, status, effects: talk to a running gyrod over its socket.
void addClientCommands(CLI::App& app, CommandRunner& run);
void addModelCheckCommand(CLI::App& app, CommandRunner& run);
// model: a sensor model's calibration, with what a board learned on top of it.
void addModelCommand(CLI::App& app, CommandRunner& run);
// fleet: every gyrod on an MQTT broker.
void addFleetCommand(CLI::App& app, CommandRunner& run);
// live-check: the live check over a recording (docs/live-check.md).
void addLiveCheckCommand(CLI::App& app, CommandRunner& run);

}  // namespace gyrod::gyroctl
