// crowdrecon: forensic reconstruction of crowd-crush incidents.
#include <CLI/CLI.hpp>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "crowdrecon: forensic reconstruction of crowd-crush incidents with spheropolygon "
      "pedestrians"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "crowdrecon 0.1.0");
  crowdrecon::cli::RegisterShapeCommands(app);
  crowdrecon::cli::RegisterVenueCommands(app);
  crowdrecon::cli::RegisterSimulateCommand(app);
  crowdrecon::cli::RegisterRenderCommand(app);
  crowdrecon::cli::RegisterAnalyzeCommand(app);
  crowdrecon::cli::RegisterSweepCommand(app);
  crowdrecon::cli::RegisterPhaseCommand(app);
  crowdrecon::cli::RegisterTimelineCommand(app);
  crowdrecon::cli::RegisterReportCommand(app);
  crowdrecon::cli::RegisterObserveCommands(app);
  crowdrecon::cli::RegisterExportCommand(app);
  crowdrecon::cli::RegisterCalibrateCommand(app);
  crowdrecon::cli::RegisterValidateCommand(app);
  return crowdrecon::cli::RunCommandLine(app, argc, argv);
}
