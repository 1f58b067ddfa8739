// gyroctl: offline analysis of gyro recordings and the gyrod client.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <exception>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "formats/edit_distance.hpp"
#include "formats/input_file.hpp"
#include "formats/output_file.hpp"
#include "formats/recording_csv.hpp"
#include "formats/toml_document.hpp"
#include "tools/gyroctl/commands.hpp"
#include "tools/gyroctl/daemon_client.hpp"
#include "tools/gyroctl/exit_codes.hpp"

#ifndef GYROD_VERSION
#define GYROD_VERSION "unknown"
#endif

namespace {

using namespace gyrod::gyroctl;
using gyrod::formats::editDistance;

// The first word that is not an option must name a subcommand (gyroctl has no global option
// taking a value). CLI11 would only say the argument was "not expected"; this names the word
// and the nearest command. Returns the message for an unknown command, nullopt otherwise.
std::optional<std::string> unknownCommandMessage(CLI::App& app, int argc, char** argv) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
  for (int i = 1; i < argc; ++i) {
    const std::string_view word = argv[i];
    if (word.empty() || word.front() == '-') continue;
    if (std::find(names.begin(), names.end(), word) != names.end()) return std::nullopt;
    std::string message = "gyroctl: unknown command '" + std::string(word) + "'";
    const auto nearest = std::min_element(names.begin(), names.end(), [&](const auto& x, const auto& y) {
      return editDistance(word, x) < editDistance(word, y);
    });
    // Only a near miss is a suggestion: at most a third of the word's letters differ.
    if (nearest != names.end() && editDistance(word, *nearest) <= std::max<std::size_t>(2, word.size() / 3))
      message += "; did you mean '" + *nearest + "'?";
    std::string all;
    for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
    return message + " (commands: " + all + ")";
  }
  return std::nullopt;
}

// CLI11's errors in gyroctl's style: one line "gyroctl: ...", and for an option the command
// does not have, its name and the nearest one when it is a near miss (CLI11 would print
// "The following arguments were not expected" and a second line). Returns the exit status.
int reportParseError(CLI::App& app, const CLI::ParseError& e, int argc, char** argv) {
  if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help, --version
  const auto parsed = app.get_subcommands();
  const CLI::App* command = parsed.empty() ? &app : parsed.front();
  const std::string where = parsed.empty() ? "" : command->get_name() + ": ";
  std::vector<std::string> known;
  for (const CLI::Option* opt : command->get_options()) {
    for (const auto& n : opt->get_lnames()) known.push_back("--" + n);
    for (const auto& n : opt->get_snames()) known.push_back("-" + n);
  }
  if (dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr) {
    for (int i = 1; i < argc; ++i) {
      std::string word = argv[i];
      // An option word: "--name", "--name=value" or "-x"; "-0.5" is a value.
      if (word.size() < 2 || word[0] != '-' || !(std::isalpha(static_cast<unsigned char>(word[1])) || word[1] == '-'))
        continue;
      word = word.substr(0, word.find('='));
      if (word == "--" || std::find(known.begin(), known.end(), word) != known.end()) continue;
      std::string message = "gyroctl: " + where + "unknown option '" + word + "'";
      const auto nearest = std::min_element(known.begin(), known.end(), [&](const auto& x, const auto& y) {
        return editDistance(word, x) < editDistance(word, y);
      });
      if (nearest != known.end() && editDistance(word, *nearest) <= std::max<std::size_t>(2, word.size() / 3))
        message += "; did you mean '" + *nearest + "'?";
      std::cerr << message << " (gyroctl " << (parsed.empty() ? "" : command->get_name() + " ")
                << "--help lists them)\n";
      return kExitUsage;
    }
  }
  std::cerr << "gyroctl: " << where << e.what() << '\n';
  return kExitUsage;
}

// Prints the error in flight and returns its exit status (tools/gyroctl/exit_codes.hpp).
int reportError() {
  auto fail = [](ExitCode code, const std::exception& e) {
    std::cerr << "gyroctl: " << e.what() << '\n';
    return toInt(code);
  };
  try {
    throw;
  } catch (const ExitError& e) {
    return fail(e.code(), e);
  } catch (const gyrod::formats::InputFileError& e) {  // missing, unreadable, not a file, or too large
    return fail(e.unreadable() ? ExitCode::NoInput : ExitCode::DataError, e);
  } catch (const gyrod::recording::RecordingError& e) {  // a recording that cannot be used
    return fail(ExitCode::DataError, e);
  } catch (const gyrod::formats::TomlError& e) {  // a model or motion file that cannot be used
    return fail(ExitCode::DataError, e);
  } catch (const gyrod::formats::OutputTargetError& e) {
    return fail(ExitCode::CantCreate, e);
  } catch (const DaemonConnectionError& e) {
    return fail(ExitCode::Unavailable, e);
  } catch (const std::invalid_argument& e) {  // an option value the command cannot use
    return fail(ExitCode::Usage, e);
  } catch (const std::exception& e) {
    return fail(ExitCode::Failure, e);
  }
}

}  // namespace

int main(int argc, char** argv) {
  // The name is given, so help and errors say "gyroctl" whatever path it was started by.
  CLI::App app{"gyroctl: analyse MPU6050 gyro recordings and talk to gyrod", "gyroctl"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("gyroctl ") + GYROD_VERSION);
  CommandRunner run;
  addAnalyzeCommand(app, run);
  addFilterCommand(app, run);
  addAttitudeCommand(app, run);
  addImportCommand(app, run);
  addSimulateCommand(app, run);
  addClientCommands(app, run);
  addModelCheckCommand(app, run);
  addLiveCheckCommand(app, run);
  addModelCommand(app, run);
  addFleetCommand(app, run);
  if (const auto message = unknownCommandMessage(app, argc, argv)) {
    std::cerr << *message << '\n';
    return kExitUsage;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return reportParseError(app, e, argc, argv);
  }
  try {
    return run ? run() : kExitUsage;
  } catch (...) {
    return reportError();
  }
}
