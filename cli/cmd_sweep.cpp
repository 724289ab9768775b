// `crowdrecon sweep SWEEP.json -o DIR`: a grid of runs over scenario
// parameters, on the local cores or spread over MPI ranks (sweep/, docs/sweeps.md).
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/sweep/results.hpp"
#include "crowdrecon/sweep/sweep_runner.hpp"

namespace crowdrecon::cli {

namespace {

struct SweepArgs {
  std::string sweep_file;
  std::string output;
  int jobs = 0;
  bool quiet = false;
  double log_every_s = kLogEveryDefaultS;  // --log-every
  bool force = false;
  long long stop_after_runs = -1;
};

int RunSweepCommand(const SweepArgs& args) {
  // Under mpirun rank 0 alone checks, and every rank follows it (sweep::CheckedOnRankZero).
  if (!sweep::CheckedOnRankZero([&] {
        CheckOutputs({{"-o", args.output, sweep::SweepFolderOutput()}}, {{"the sweep file", args.sweep_file}}, args.force);
      }))
    return 2;  // rank 0 said why
  sweep::SweepOptions options;
  options.sweep_file = args.sweep_file;
  options.output_dir = args.output;
  options.jobs = args.jobs;
  options.show_progress = !args.quiet && isatty(STDERR_FILENO);
  options.log_progress_every_s = LogProgressEvery(args.log_every_s, args.quiet);
  options.stop_after_runs = args.stop_after_runs;
  const sweep::SweepSummary s = sweep::RunSweep(options);
  // MPI ranks other than 0 say nothing, but exit as rank 0 does.
  if (s.coordinator) std::printf("%s", s.BriefReport().c_str());
  return s.ExitStatus();
}

}  // namespace

void RegisterSweepCommand(CLI::App& app) {
  auto args = std::make_shared<SweepArgs>();
  CLI::App* cmd = app.add_subcommand(
      "sweep",
      "Run a grid of scenarios (density, counter-flow, body shape, model parameters, seeds, ...) and tabulate each "
      "run's metrics and regime in DIR/results.sqlite and DIR/results.csv; run again to continue an interrupted "
      "sweep; under mpirun the runs are spread over the ranks (docs/sweeps.md)");
  cmd->add_option("SWEEP", args->sweep_file, "Sweep file (JSON, docs/sweeps.md)")->required();
  cmd->add_option("-o,--output", args->output, "Output folder DIR (results.sqlite, results.csv, runs/)")->required();
  cmd->add_option("--jobs", args->jobs,
                  "Runs at a time (default: all cores; under MPI: 1 per rank); results do not depend on it")
      ->check(IntegerIn(0, 4096));

  AddForceFlag(cmd, &args->force);
  cmd->add_flag("-q,--quiet", args->quiet, "No progress line");
  AddLogEveryOption(cmd, &args->log_every_s);
  cmd->add_option("--stop-after-runs", args->stop_after_runs,
                  "Stop as if interrupted once this many runs have been written (for testing resumption)")
      ->check(IntegerIn(0, 1LL << 40));
  cmd->callback([args] {
    const int rc = RunSweepCommand(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace crowdrecon::cli
