// One run of a sweep (internal to sweep; run_of_sweep.cpp): simulated,
// analysed into its results row, its files handled. sweep_runner.cpp hands
// runs out to threads and MPI ranks.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/sweep/results.hpp"
#include "crowdrecon/sweep/sweep_file.hpp"

namespace crowdrecon::sweep::detail {

namespace fs = std::filesystem;

// What a run file in runs/ may have beside it.
inline constexpr const char* kRunFileSidecars[] = {"-journal", "-wal", "-shm", ".checkpoint", ".checkpoint.tmp",
                                                   ".failed-state", ".failed-state.tmp", ".lock"};

// Removes a run file and what it has beside it.
void RemoveRunFiles(const fs::path& file);

// A run file's status ("complete", "running", ...; "" if unreadable).
std::string StatusOf(const fs::path& file);

struct RunContext {
  const SweepSpec& spec;
  const std::vector<RunPlan>& runs;
  fs::path dir;
  fs::path runs_dir;
  analysis::AnalysisOptions analysis;
  const std::function<void(const RunPlan&, const fs::path&, const std::string&)>* after_run = nullptr;
  // The engine threads each run may use, by run index (1 unless set by the
  // coordinator before it hands the run out; see Coordinator::Run).
  const std::vector<int>* threads_of_run = nullptr;
  // Each run's simulated time so far, by run index (< 0: not started here).
  std::atomic<double>* simulated_s = nullptr;
  // The sweep's stop flag, which the run polls after each frame.
  std::atomic<bool>* stop = nullptr;
};

// Simulates and analyses one run. No row (nullopt) if it was interrupted: its
// run file and checkpoint stay for the next attempt.
std::optional<ResultRow> ExecuteRun(const RunContext& ctx, const RunPlan& run);

}  // namespace crowdrecon::sweep::detail
