// `crowdrecon phase DIR`: phase diagrams (the paper's Figure 5) and metric heat
// maps of a sweep's results (sweep/phase_diagram.hpp, docs/sweeps.md).
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/sweep/phase_diagram.hpp"

namespace crowdrecon::cli {

namespace {

struct PhaseArgs {
  std::string results;
  std::string output;
  bool no_heat_maps = false;
  bool heat_maps_png_only = false;
  bool single_release = false;
  bool force = false;
};

void RunPhase(const PhaseArgs& args) {
  sweep::PhaseOptions options;
  options.results = args.results;
  options.output_dir = args.output;
  options.heat_maps = !args.no_heat_maps;
  options.heat_map_svg = !args.heat_maps_png_only;
  options.single_release_reading = args.single_release;
  CheckOutputs({{"-o", sweep::PhaseOutputFolder(options), sweep::PhaseFolderOutput()}},
               {{"the sweep results", args.results}}, args.force);
  const sweep::PhaseSummary s = sweep::DrawPhaseDiagrams(options);
  std::printf("%s", s.BriefReport().c_str());
}

}  // namespace

void RegisterPhaseCommand(CLI::App& app) {
  auto args = std::make_shared<PhaseArgs>();
  CLI::App* cmd = app.add_subcommand(
      "phase",
      "Draw a sweep's phase diagrams (regime per grid point, majority over seeds, disagreement shown, as the paper's "
      "Figure 5) and heat maps of its metrics, as PNG and SVG with an index.html");
  cmd->add_option("DIR", args->results, "Sweep output folder (or its results.sqlite)")->required();
  cmd->add_option("-o,--output", args->output, "Folder for the pictures (default: DIR/phase)");
  AddForceFlag(cmd, &args->force);
  cmd->add_flag("--no-heat-maps", args->no_heat_maps, "Phase diagrams only");
  cmd->add_flag("--heat-maps-png-only", args->heat_maps_png_only,
                "Heat maps as PNG only (about 200 kB each as SVG); index.html then links each to its PNG");
  cmd->add_flag("--single-release", args->single_release,
                "Read each run's regime as a single release: one clog of at least 5 s that releases is the avalanche "
                "regime (results column regime_code_single_release; docs/analysis.md)");
  cmd->callback([args] { RunPhase(*args); });
}

}  // namespace crowdrecon::cli
