#include "tools/gyroctl/commands.hpp"

namespace gyrod::gyroctl {
void addAnalyzeCommand(CLI::App& app, CommandRunner& run) {
  auto* sub = app.add_subcommand("analyze", "(being written)");
  sub->callback([&run] { run = [] { return kExitFailure; }; });
}
}  // namespace gyrod::gyroctl
