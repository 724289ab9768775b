// Registration of the subcommands of the `crowdrecon` program. Each group lives
// in its own file and adds itself to the application; errors are thrown as
// crowdrecon::InputError and reported by main().
#pragma once

#include <string>

namespace CLI {
class App;
}

namespace crowdrecon::cli {

void RegisterShapeCommands(CLI::App& app);  // shape, population, body reference
void RegisterVenueCommands(CLI::App& app);  // venue check, venue import
void RegisterSimulateCommand(CLI::App& app);  // simulate
void RegisterRenderCommand(CLI::App& app);  // render (pictures and video of a run)
void RegisterAnalyzeCommand(CLI::App& app);  // analyze (metrics and regime of a run)
void RegisterSweepCommand(CLI::App& app);  // sweep (grids of runs, local or MPI)
void RegisterPhaseCommand(CLI::App& app);  // phase (phase diagrams and heat maps of a sweep)
void RegisterTimelineCommand(CLI::App& app);  // timeline (the figure of an incident timeline's run)
void RegisterReportCommand(CLI::App& app);  // report (injury risk of runs: HTML, PDF, CSV)
void RegisterObserveCommands(CLI::App& app);  // observe trajectories / footage (observations)
void RegisterExportCommand(CLI::App& app);  // export (a run's trajectories for tools unaware of periodic boxes)
void RegisterCalibrateCommand(CLI::App& app);  // calibrate (scenario values fitted to observations)
void RegisterValidateCommand(CLI::App& app);  // validate (the validation suite on model profiles: report)

// The command line as given (for the records of reports), set by RunCommandLine.
const std::string& CommandLine();
void SetCommandLine(int argc, char** argv);
// Parses and runs the command line with the commands registered in `app`, and
// returns the exit status (README, "Exit status"; cli/run_app.cpp): the one
// way of crowdrecon and of the lean crowdrecon-simulate.
int RunCommandLine(CLI::App& app, int argc, char** argv);

// The --force flag of every command that writes: replace a file, or write into
// a folder, that is not a previous output of the command (see
// common/output_path.hpp; inputs and folders are never overwritten).
void AddForceFlag(CLI::App* cmd, bool* force);

}  // namespace crowdrecon::cli
