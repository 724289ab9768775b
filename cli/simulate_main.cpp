// crowdrecon-simulate: the simulate command of crowdrecon alone, for machines
// that lack the project's packages (a GPU machine; issue 42, bench/gpu_whole_run.sh).
#include <CLI/CLI.hpp>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"crowdrecon-simulate: crowdrecon's simulate command alone (the lean build for GPU machines)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "crowdrecon-simulate 0.1.0");
  crowdrecon::cli::RegisterSimulateCommand(app);
  return crowdrecon::cli::RunCommandLine(app, argc, argv);
}
