#include "tools/gyroctl/commands.hpp"

namespace gyrod::gyroctl {
void addImportCommand(CLI::App& app, CommandRunner& run) {
  auto* sub = app.add_subcommand("import", "(being written)");
  sub->callback([&run] { run = [] { return kExitFailure; }; });
}
}  // namespace gyrod::gyroctl
