// `crowdrecon calibrate CALIBRATION.json -o DIR`: scenario values (Γ, λ, ε,
// ...) fitted to observation files with Ceres, with their uncertainty
// (calibrate/, docs/calibration.md).
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/calibrate/calibrate.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/scoped_signals.hpp"
#include "crowdrecon/sweep/sweep_runner.hpp"

namespace crowdrecon::cli {

namespace {

struct CalibrateArgs {
  std::string calibration_file;
  std::string output;
  int jobs = 0;
  bool quiet = false;
  bool force = false;
};

int RunCalibrateCommand(const CalibrateArgs& args) {
  // Under mpirun rank 0 alone checks, and every rank follows it (sweep::CheckedOnRankZero).
  if (!sweep::CheckedOnRankZero([&] {
        CheckOutputs({{"-o", args.output, calibrate::CalibrationFolderOutput()}},
                     {{"the calibration file", args.calibration_file}}, args.force);
      }))
    return 2;  // rank 0 said why
  calibrate::Options options;
  options.calibration_file = args.calibration_file;
  options.output_dir = args.output;
  options.jobs = args.jobs;
  options.show_progress = !args.quiet && isatty(STDERR_FILENO);
  options.show_stages = !args.quiet;
  const calibrate::Summary s = calibrate::Calibrate(options);
  // MPI ranks other than 0 say nothing, but exit as rank 0 does (every rank
  // learns from it whether the calibration was interrupted).
  if (s.coordinator) std::printf("%s", s.BriefReport().c_str());
  return s.interrupted ? StoppedExitStatus() : 0;  // 143 after SIGTERM, 130 after Ctrl-C
}

}  // namespace

void RegisterCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Fit scenario values (by default back force, torsion stiffness and restitution) to observation files with "
      "Ceres: K seeds per parameter set run through the sweep machinery (cached, resumable, MPI), the best fit "
      "with intervals and correlations, profiles and pictures in DIR (docs/calibration.md)");
  cmd->add_option("CALIBRATION", args->calibration_file, "Calibration file (JSON, docs/calibration.md)")->required();
  cmd->add_option("-o,--output", args->output,
                  "Output folder DIR (calibration.json, report.txt, evaluations.csv, pictures, cache/ of the runs' "
                  "observations); run again on it to continue")
      ->required();
  cmd->add_option("--jobs", args->jobs,
                  "Runs at a time (default: all cores; under MPI: 1 per rank); results do not depend on it")
      ->check(IntegerIn(0, 4096));
  AddForceFlag(cmd, &args->force);
  cmd->add_flag("-q,--quiet", args->quiet, "No progress lines");
  cmd->callback([args] {
    const int rc = RunCalibrateCommand(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace crowdrecon::cli
