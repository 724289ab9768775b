// Placeholder until the venue commands land (being written now).
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace crowdrecon::cli {
void RegisterVenueCommands(CLI::App& app) { (void)app.add_subcommand("venue", "Venues"); }
}  // namespace crowdrecon::cli
