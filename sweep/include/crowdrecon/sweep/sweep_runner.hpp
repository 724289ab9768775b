// Running a sweep: every run of a sweep file (sweep_file.hpp) simulated
// (scenario::RunScenario, one engine thread per run but the last; see
// docs/sweeps.md), analysed
// (analysis::AnalyzeRun) and written as one row of DIR/results.* (results.hpp).
//
// Local: `jobs` runs at a time on worker threads of this process; a progress
// line (runs done / total, elapsed, time left) on a terminal.
//
// MPI: when started by mpirun (or srun) as an MPI rank, the runs are spread
// over the ranks. Rank 0 coordinates: it hands out run indices one at a time
// to whichever rank asks (each rank runs `jobs` runs at a time, rank 0
// included), receives the rows and alone writes DIR/results.*. Other ranks
// write only their runs' files in DIR/runs/. A run's row depends on its
// parameters only, so the tables equal the local run's.
//
// Resume: a row is committed once its run has been analysed. Started again
// on the same DIR, the sweep checks that DIR belongs to the same sweep and
// skips the runs that have rows. A run that was interrupted (Ctrl-C,
// SIGTERM: its checkpoint is written) continues from its checkpoint; one that
// was killed outright starts over.
//
// Interruption: SIGINT / SIGTERM (and SweepOptions::stop_after_runs) stop the
// runs in progress at their next frame, without rows; the summary says how
// many runs are left.
//
// Thread safety of what the workers call: RunScenario and AnalyzeRun keep no
// shared state (each opens its own SQLite connection; SQLite is built
// thread-safe), and the engine's OpenMP regions run with one thread. The one
// process-wide state, the interrupt flag of scenario::InstallInterruptHandlers,
// is cleared by every RunScenario that starts, so a sweep installs its own
// handlers and hands each run its flag (RunOptions::stop_flag).
#pragma once

#include "crowdrecon/common/scoped_signals.hpp"

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "crowdrecon/sweep/sweep_file.hpp"

namespace crowdrecon::sweep {

struct SweepOptions {
  std::filesystem::path sweep_file;
  std::filesystem::path output_dir;  // DIR: results.sqlite, results.csv, runs/
  // Runs at a time in this process; 0 = the number of cores (locally) or 1
  // (per MPI rank: mpirun starts one rank per core).
  int jobs = 0;
  bool show_progress = false;  // a progress line on stderr (rank 0)
  // > 0 (and no progress line): a line of its own on stderr this often, in
  // wall seconds, with the runs done and how far each running run has got
  // (rank 0's own runs): the progress of a long sweep whose stderr is a log.
  double log_progress_every_s = 0.0;
  // For tests of resumption: stop as if interrupted once this many rows have
  // been written by this invocation (< 0: never).
  long long stop_after_runs = -1;
  // Called for every run that got a row, on the worker (and MPI rank) that
  // ran it, after its analysis and before its run file is removed, with the
  // row's status ("complete" or "failed: ..."): what a caller measures from
  // the run file itself (the calibration observes it, calibrate/). It runs on
  // worker threads at once, so it must be thread-safe; an exception from it
  // stops the sweep as an error. Every rank must be given the same hook;
  // under MPI, RunSweep returns on any rank only once every rank's calls
  // have returned.
  std::function<void(const RunPlan& run, const std::filesystem::path& run_file, const std::string& status)> after_run;
};

struct SweepSummary {
  std::string name;
  std::size_t total = 0;         // runs in the sweep
  std::size_t already_done = 0;  // rows found at the start (resumed sweep)
  std::size_t completed = 0;     // rows written now (failed runs included)
  std::size_t failed = 0;        // of those, runs whose status is "failed: ..."
  std::size_t remaining = 0;     // runs without a row at the end
  bool interrupted = false;      // runs left by a stop, or SIGINT/SIGTERM received (even with none left)
  double wall_s = 0.0;
  int ranks = 1;   // MPI ranks (1 = local)
  int jobs = 1;    // runs at a time per rank
  std::vector<std::size_t> runs_per_rank;  // rows computed by each rank in this invocation (rank 0 only)
  bool coordinator = true;  // false on MPI ranks other than 0 (which print nothing)
  int exit_code = 0;        // of a rank other than 0: 2 if the sweep could not start
  std::filesystem::path results_sqlite, results_csv;

  std::string BriefReport() const;
  // The command's exit status, the same on every MPI rank: exit_code when
  // the sweep could not start or failed, when interrupted 143 after SIGTERM
  // and 130 otherwise (StoppedExitStatus), else 0.
  int ExitStatus() const { return exit_code != 0 ? exit_code : (interrupted ? StoppedExitStatus() : 0); }
};

// Runs (or continues) the sweep. Throws InputError for a bad sweep file, a
// run whose overrides make the scenario invalid (before any run starts), or
// a DIR that holds another sweep. A run that cannot be placed or goes
// numerically wrong is a row with status "failed: ...", not an error.
SweepSummary RunSweep(const SweepOptions& options);

// Removes the partial runs a killed sweep left in DIR/runs: run files of
// runs that were in progress (status "running" or "interrupted", or
// unreadable) with their SQLite logs and checkpoints, and such sidecars left
// without their run file. Only continuing that very sweep would resume them;
// a caller that will not (a calibration whose batch is no longer asked for)
// removes them. A failed run's file stays, for its diagnosis. Returns the
// run files (or lone sidecars) removed.
std::vector<std::filesystem::path> RemovePartialRuns(const std::filesystem::path& sweep_dir);

// A check made once per job (of the outputs, before anything is written):
// started by mpirun, rank 0 alone runs `check` and every rank follows its
// verdict (a worker rank that checked too could find rank 0's output folder
// half made and refuse it). Returns true to go on; what `check` throws on
// rank 0 passes on there, and the other ranks return false (rank 0 says
// why). Not under mpirun: `check` runs here and true is returned.
bool CheckedOnRankZero(const std::function<void()>& check);

}  // namespace crowdrecon::sweep
