// gyroctl: offline analysis of gyro recordings and the gyrod client.
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "formats/recording_csv.hpp"
#include "tools/gyroctl/commands.hpp"

int main(int argc, char** argv) {
  using namespace gyrod::gyroctl;
  CLI::App app{"gyroctl: analyse MPU6050 gyro recordings and talk to gyrod"};
  app.require_subcommand(1);
  CommandRunner run;
  addAnalyzeCommand(app, run);
  addFilterCommand(app, run);
  addImportCommand(app, run);
  addSimulateCommand(app, run);
  addClientCommands(app, run);
  addModelCheckCommand(app, run);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  try {
    return run ? run() : kExitUsage;
  } catch (const gyrod::recording::RecordingError& e) {
    std::cerr << "gyroctl: " << e.what() << '\n';
    return kExitUsage;
  } catch (const std::invalid_argument& e) {
    std::cerr << "gyroctl: " << e.what() << '\n';
    return kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << "gyroctl: " << e.what() << '\n';
    return kExitFailure;
  }
}
