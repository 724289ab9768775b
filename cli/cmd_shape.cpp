// Placeholder until the shape commands land (being written now).
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace crowdrecon::cli {
void RegisterShapeCommands(CLI::App& app) { (void)app.add_subcommand("shape", "Build a body from an outline"); }
}  // namespace crowdrecon::cli
