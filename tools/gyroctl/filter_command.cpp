#include "tools/gyroctl/commands.hpp"

namespace gyrod::gyroctl {
void addFilterCommand(CLI::App& app, CommandRunner& run) {
  auto* sub = app.add_subcommand("filter", "(being written)");
  sub->callback([&run] { run = [] { return kExitFailure; }; });
}
}  // namespace gyrod::gyroctl
