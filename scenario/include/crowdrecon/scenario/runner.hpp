// Running a scenario: builds the world, writes the run file frame by frame,
// writes checkpoints, survives interruption (Ctrl-C, SIGTERM: a checkpoint is
// written before stopping; a killed run resumes from its last checkpoint), and
// stops with a clear message and its state saved when the run goes
// numerically wrong. Progress (simulated time, real-time factor, time left) is
// shown on a terminal only.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <string>

#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/scenario/scenario.hpp"

namespace crowdrecon::scenario {

struct RunOptions {
  std::filesystem::path output;  // RUN.sqlite
  int threads = 1;
  // With more than one thread: true lets engine::ThreadGovernor use fewer
  // while they are faster (a busy core); false keeps `threads` throughout
  // (benchmarks). Results are the same either way.
  bool adapt_threads = true;
  // Where the force computation of person pairs runs (engine::WorldDef::device);
  // results are the same on either.
  engine::ComputeDevice device = engine::ComputeDevice::kCpu;
  bool resume = false;           // continue from output + ".checkpoint"
  bool show_progress = false;    // a progress line on stderr
  // > 0 (and no progress line): a line of its own on stderr this often, in
  // wall seconds (the wall clock, the simulated time, the time left): the
  // progress of a long run whose stderr is a log, not a terminal.
  double log_progress_every_s = 0.0;
  // If set: the simulated time reached, updated at every frame (a sweep
  // reports its runs' progress from it).
  std::atomic<double>* simulated_s = nullptr;
  // Stop (as if interrupted) once the simulated time reaches this; < 0 never.
  // For tests of interruption and resume.
  double stop_after_s = -1.0;
  // Also stop (as if interrupted: a checkpoint is written) once this flag is
  // true; may be null. For callers that run several scenarios at once (a
  // sweep): the flag of InstallInterruptHandlers is cleared by every
  // RunScenario that starts, so it cannot stop concurrent runs reliably.
  const std::atomic<bool>* stop_flag = nullptr;
};

struct RunSummary {
  std::string status;           // "complete" or "interrupted"
  double simulated_s = 0.0;
  double started_at_s = 0.0;    // the simulated time this invocation began at (a resumed run's checkpoint)
  double wall_s = 0.0;           // this invocation
  double total_wall_s = 0.0;     // over all the run's invocations (run value wall_s; to the checkpoint each resumed from)
  double time_step_s = 0.0;
  std::size_t people = 0;       // at the start
  std::size_t slots = 0;        // a timeline's engine slots (people of the start and places for arrivals); 0 without
  std::int64_t frames = 0;      // frames in the run file
  double real_time_factor = 0.0;  // simulated / wall seconds (this invocation)
  engine::Profile profile;         // time per engine stage (this invocation)
  std::string device_fallback;     // why and when the GPU failed, if it did (engine::Simulation)
  std::string threads_report;      // the thread governor's brief report (engine::ThreadChoice::Summary)
  std::string systems_report;      // wall time of the engine steps and of each run-loop system (RunLoop::Summary)
};

// Path of the checkpoint that belongs to a run file.
std::filesystem::path CheckpointPath(const std::filesystem::path& run_file);

// The wall time a run's frames took over all its invocations, as RunScenario
// records it with every checkpoint and at the end (run value wall_s); 0 for a
// run written before it was kept.
double RecordedWallSeconds(const std::filesystem::path& run_file);

// Installs SIGINT/SIGTERM handlers that ask running scenarios to stop at the
// next step (after writing a checkpoint).
void InstallInterruptHandlers();
// The exit status of a command those handlers stopped: 143 after SIGTERM,
// 130 after SIGINT or a stop asked for otherwise (--stop-after: as Ctrl-C).
int InterruptedExitStatus();

RunSummary RunScenario(const Scenario& scenario, const RunOptions& options);

// A run branched at the checkpoint of another (a what-if from a moment of a
// long run: "and if at 22:15 people fell there"): writes `output` and its
// checkpoint as the run `from` stood at its checkpoint, now belonging to
// `scenario`, so that RunScenario with `resume` continues it under
// `scenario`. The scenario may differ from the one `from` was written for
// only in its name, its notes and the timeline's events at or after the
// checkpoint's time (file paths compared as resolved against each
// scenario's folder, so it may live elsewhere); the world, the population, the model, the run's
// duration and every event before that time must be the same (else the
// state would not be the one `scenario` gives; the engine's state also
// checks the time step and the people). Throws InputError naming the run,
// the checkpoint or the first JSON path that differs, before anything is
// written; then replaces `output` and its checkpoint (the caller has checked
// that it may: CheckOutputs). Returns the checkpoint's time (s).
double BranchRun(const Scenario& scenario, const std::filesystem::path& from, const std::filesystem::path& output);

// A run continued into a new file (issue 66: a long run in segments, each
// on whatever machine and day): writes `output` as the next segment of the
// run `from` (runfile::RunFileWriter::StartSegment: its header, no frame,
// run value continues naming `from`) with `from`'s checkpoint, so that
// RunScenario with `resume` writes the frames after it there; readers read
// the chain as one run, the same run as made in one go. `from` must be a
// segment stopped at its checkpoint (status "interrupted", its last frame
// the checkpoint's) of this very scenario (the checkpoint's fingerprint).
// Returns the checkpoint's time (s).
double ContinueRun(const Scenario& scenario, const std::filesystem::path& from, const std::filesystem::path& output);

// The engine's world and its state at the checkpoint of an interrupted run
// (CheckpointPath(run_file)), built as RunScenario builds them (the same
// world, time step and state a resumed run continues from), with `threads`.
// For benchmarks on machines that cannot build worlds from scenarios (see
// bench/README.md: a dense moment of a real run on a GPU machine). Throws
// InputError naming the checkpoint if it is missing, damaged or belongs to
// another scenario.
struct EngineAtCheckpoint {
  engine::WorldDef world;
  std::string state;  // engine::Simulation::SaveState
  double time_s = 0.0;
};
EngineAtCheckpoint ReadEngineAtCheckpoint(const Scenario& scenario, const std::filesystem::path& run_file, int threads);

}  // namespace crowdrecon::scenario
