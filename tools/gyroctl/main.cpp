// gyroctl: offline analysis of gyro recordings and (later) the gyrod client.
#include <CLI/CLI.hpp>
#include <iostream>

int main(int argc, char** argv) {
  CLI::App app{"gyroctl: analyse MPU6050 gyro recordings and talk to gyrod"};
  app.require_subcommand(1);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  return 0;
}
