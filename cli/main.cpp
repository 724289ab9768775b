// crowdrecon: forensic reconstruction of crowd-crush incidents.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "crowdrecon/common/error.hpp"

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
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const crowdrecon::InputError& e) {
    std::fprintf(stderr, "crowdrecon: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crowdrecon: internal error: %s\n", e.what());
    return 3;
  }
  return 0;
}
