#include "crowdrecon/sweep/sweep_runner.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <deque>
#include <exception>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/scenario/runner.hpp"
#include "crowdrecon/sweep/results.hpp"
#include "crowdrecon/sweep/sweep_file.hpp"
#include "mpi_transport.hpp"

namespace crowdrecon::sweep {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

// Set by SIGINT / SIGTERM, by --stop-after-runs, by a fatal error and by rank
// 0's interrupt message; every run in progress polls it after each frame.
std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

extern "C" void OnSweepSignal(int) { g_stop.store(true); }

// Control codes from rank 0 besides run indices (>= 0).
constexpr std::int64_t kStopSlot = -1;   // no more work for the slot that asked
constexpr std::int64_t kInterrupt = -2;  // stop the runs in progress (sweep interrupted)

// What a worker thread hands back: the run's row, nothing (the run was
// interrupted), or an error that ends the sweep.
struct Outcome {
  std::size_t index = 0;
  std::optional<ResultRow> row;
  std::exception_ptr fatal;
};

// `threads` worker threads, each running one whole run at a time.
class WorkerPool {
 public:
  WorkerPool(int threads, std::function<Outcome(std::size_t)> work) : work_(std::move(work)) {
    for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { Loop(); });
  }
  ~WorkerPool() {
    {
      std::lock_guard lock(mutex_);
      closing_ = true;
      tasks_.clear();
    }
    task_cv_.notify_all();
    for (std::thread& t : threads_) t.join();
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  void Submit(std::size_t index) {
    {
      std::lock_guard lock(mutex_);
      tasks_.push_back(index);
      ++outstanding_;
    }
    task_cv_.notify_one();
  }
  // Runs submitted whose outcome has not been taken yet.
  std::size_t outstanding() const {
    std::lock_guard lock(mutex_);
    return outstanding_;
  }
  bool TryPop(Outcome* out) {
    std::lock_guard lock(mutex_);
    if (results_.empty()) return false;
    *out = std::move(results_.front());
    results_.pop_front();
    --outstanding_;
    return true;
  }
  // Waits until an outcome is ready or `timeout` has passed.
  void WaitFor(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    result_cv_.wait_for(lock, timeout, [&] { return !results_.empty(); });
  }

 private:
  void Loop() {
    while (true) {
      std::size_t index = 0;
      {
        std::unique_lock lock(mutex_);
        task_cv_.wait(lock, [&] { return closing_ || !tasks_.empty(); });
        if (tasks_.empty()) return;
        index = tasks_.front();
        tasks_.pop_front();
      }
      Outcome outcome = work_(index);
      {
        std::lock_guard lock(mutex_);
        results_.push_back(std::move(outcome));
      }
      result_cv_.notify_all();
    }
  }

  std::function<Outcome(std::size_t)> work_;
  mutable std::mutex mutex_;
  std::condition_variable task_cv_, result_cv_;
  std::deque<std::size_t> tasks_;
  std::deque<Outcome> results_;
  std::size_t outstanding_ = 0;
  bool closing_ = false;
  std::vector<std::thread> threads_;
};

// Sets the stop flag when the scope is left by an exception, before the
// worker pool declared earlier joins its threads: the runs in progress then
// end at their next frame instead of running to completion.
struct StopRunsOnError {
  int exceptions = std::uncaught_exceptions();
  ~StopRunsOnError() {
    if (std::uncaught_exceptions() > exceptions) g_stop.store(true);
  }
};

void RemoveRunFiles(const fs::path& file) {
  std::error_code ec;
  for (const char* suffix : {"", "-journal", "-wal", "-shm", ".checkpoint", ".checkpoint.tmp", ".failed-state",
                             ".failed-state.tmp"})
    fs::remove(file.string() + suffix, ec);
}

std::string ReplaceAll(std::string text, const std::string& from, const std::string& to) {
  if (from.empty()) return text;
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

struct Context {
  const SweepSpec& spec;
  const std::vector<RunPlan>& runs;
  fs::path dir;
  fs::path runs_dir;
  analysis::AnalysisOptions analysis;
};

ResultRow RowOf(const RunPlan& run, const analysis::RunAnalysis& a) {
  static const std::map<std::string, std::size_t> column_of = [] {
    std::map<std::string, std::size_t> m;
    for (std::size_t i = 0; i < MetricColumns().size(); ++i) m[MetricColumns()[i]] = i;
    return m;
  }();
  ResultRow row;
  row.run_index = run.index;
  row.status = "complete";
  row.regime = analysis::ToString(a.regime.regime);
  row.regime_reason = a.regime.reason;
  row.metrics.assign(MetricColumns().size(), std::numeric_limits<double>::quiet_NaN());
  for (const analysis::SummaryValue& v : a.SummaryTable()) {
    const auto it = column_of.find(v.name);
    if (it == column_of.end())
      throw std::logic_error("sweep: the analysis reports \"" + v.name + "\", which has no results column");
    row.metrics[it->second] = v.value;
  }
  return row;
}

// Simulates and analyses one run. No row (nullopt) if it was interrupted: its
// run file and checkpoint stay for the next attempt.
std::optional<ResultRow> ExecuteRun(const Context& ctx, const RunPlan& run) {
  const auto start = Clock::now();
  const fs::path file = ctx.runs_dir / (run.id + ".sqlite");
  const scenario::Scenario sc = RunScenarioOf(ctx.spec, run);  // checked before the sweep started
  scenario::RunOptions options;
  options.output = file;
  options.threads = 1;  // parallel over runs, not within one
  options.stop_flag = &g_stop;
  const bool resume = fs::exists(file) && fs::exists(scenario::CheckpointPath(file));
  if (!resume) RemoveRunFiles(file);  // a run killed outright starts over

  ResultRow row;
  bool failed = false;
  try {
    scenario::RunSummary summary;
    if (resume) {
      options.resume = true;
      try {
        summary = scenario::RunScenario(sc, options);
      } catch (const InputError&) {
        // An unusable checkpoint (or a failure after it, which then repeats
        // identically from the start): start over.
        if (g_stop.load()) return std::nullopt;
        RemoveRunFiles(file);
        options.resume = false;
        summary = scenario::RunScenario(sc, options);
      }
    } else {
      summary = scenario::RunScenario(sc, options);
    }
    if (summary.status != "complete") return std::nullopt;
    row = RowOf(run, analysis::AnalyzeRun(file, ctx.analysis));
  } catch (const InputError& e) {
    // The crowd cannot be placed, or the run went numerically wrong: a result
    // of these parameters, recorded as such. Messages name run files as
    // runs/..., so that they do not depend on where DIR is.
    failed = true;
    row = ResultRow{};
    row.run_index = run.index;
    row.status = "failed: " + ReplaceAll(e.what(), ctx.runs_dir.string(), "runs");
    row.metrics.assign(MetricColumns().size(), std::numeric_limits<double>::quiet_NaN());
  }
  // A failed run keeps its file (and saved state) for inspection.
  if (!ctx.spec.keep_runs && !failed) RemoveRunFiles(file);
  row.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return row;
}

// Messages from worker ranks to rank 0: [had_run][stopping][has_row] row.
std::string EncodeWorkerMessage(bool had_run, bool stopping, const std::optional<ResultRow>& row) {
  std::string bytes;
  bytes += static_cast<char>(had_run);
  bytes += static_cast<char>(stopping);
  bytes += static_cast<char>(row.has_value());
  if (row) bytes += SerializeRow(*row);
  return bytes;
}

struct WorkerMessage {
  bool had_run = false, stopping = false;
  std::optional<ResultRow> row;
};

WorkerMessage DecodeWorkerMessage(const std::string& bytes) {
  if (bytes.size() < 3) throw std::runtime_error("sweep: short message from an MPI rank");
  WorkerMessage m;
  m.had_run = bytes[0] != 0;
  m.stopping = bytes[1] != 0;
  if (bytes[2] != 0) m.row = DeserializeRow(bytes.substr(3));
  return m;
}

class ProgressLine {
 public:
  explicit ProgressLine(bool enabled) : enabled_(enabled) {}
  void Show(std::size_t done, std::size_t total, std::size_t done_now, std::size_t failed, std::size_t running,
            double elapsed_s, bool force) {
    if (!enabled_) return;
    const auto now = Clock::now();
    if (!force && now - last_ < std::chrono::milliseconds(500)) return;
    last_ = now;
    const double rate = elapsed_s > 0 ? static_cast<double>(done_now) / elapsed_s : 0.0;
    const double left = rate > 0 ? static_cast<double>(total - done) / rate : std::numeric_limits<double>::infinity();
    std::fprintf(stderr, "\r  sweep: %zu / %zu runs (%zu failed), %zu running, %s elapsed, %s left      ", done, total,
                 failed, running, FormatDuration(elapsed_s).c_str(), done == total ? "0s" : FormatDuration(left).c_str());
    std::fflush(stderr);
    shown_ = true;
  }
  void End() {
    if (shown_) std::fprintf(stderr, "\n");
    shown_ = false;
  }

 private:
  bool enabled_;
  bool shown_ = false;
  Clock::time_point last_{};
};

}  // namespace

std::string SweepSummary::BriefReport() const {
  std::string r = "sweep: " + name + "\n";
  r += "runs: " + std::to_string(total) + " in all; " + std::to_string(already_done) + " done before, " +
       std::to_string(completed) + " now (" + std::to_string(failed) + " failed), " + std::to_string(remaining) +
       " left\n";
  r += "wall time: " + FormatDuration(wall_s) + ", " + std::to_string(jobs) + " run(s) at a time" +
       (ranks > 1 ? " on each of " + std::to_string(ranks) + " MPI ranks" : std::string()) + "\n";
  if (ranks > 1 && runs_per_rank.size() == static_cast<std::size_t>(ranks)) {
    r += "runs per rank:";
    for (std::size_t i = 0; i < runs_per_rank.size(); ++i)
      r += (i ? ", " : " ") + std::to_string(i) + ": " + std::to_string(runs_per_rank[i]);
    r += "\n";
  }
  r += "results: " + results_sqlite.string() + ", " + results_csv.string() + "\n";
  if (interrupted) r += "interrupted: run the same command again to continue\n";
  return r;
}

SweepSummary RunSweep(const SweepOptions& options) {
  const auto start = Clock::now();
  g_stop.store(false);
  const bool mpi = LaunchedAsMpiRank();
  std::unique_ptr<MpiTransport> transport;
  if (mpi) transport = std::make_unique<MpiTransport>();
  const int rank = mpi ? transport->rank() : 0;
  const int ranks = mpi ? transport->size() : 1;
  const int jobs = options.jobs > 0 ? options.jobs
                                    : (mpi ? 1 : static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));

  // Set-up, on every rank: the sweep, its runs, every run's scenario (so that
  // a bad override stops the sweep before any run); rank 0 opens the results.
  SweepSpec spec;
  std::vector<RunPlan> runs;
  std::unique_ptr<ResultsStore> store;
  std::exception_ptr setup_error;
  const fs::path runs_dir = options.output_dir / "runs";
  try {
    spec = LoadSweep(options.sweep_file);
    runs = ExpandRuns(spec);
    ValidateRuns(spec, runs);
    std::error_code ec;
    fs::create_directories(runs_dir, ec);
    if (!fs::is_directory(runs_dir))
      throw InputError(runs_dir.string() + ": cannot create the output folder" + (ec ? ": " + ec.message() : ""));
    if (rank == 0) store = std::make_unique<ResultsStore>(options.output_dir, spec, runs, analysis::OptionsToJson({}));
  } catch (...) {
    setup_error = std::current_exception();
  }
  SweepSummary s;
  s.name = spec.name;
  s.ranks = ranks;
  s.jobs = jobs;
  s.coordinator = rank == 0;
  s.total = runs.size();
  if (mpi && !transport->AllOk(!setup_error)) {
    // Every rank reads the same files, so they usually fail alike: rank 0
    // reports, the others stay quiet unless only they failed.
    const bool root_ok = transport->RootOk(!setup_error);
    if (setup_error && rank == 0) std::rethrow_exception(setup_error);
    if (setup_error && root_ok) {
      try {
        std::rethrow_exception(setup_error);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "crowdrecon: MPI rank %d: %s\n", rank, e.what());
      }
    }
    if (rank == 0) throw InputError("another MPI rank could not start the sweep (its message is above)");
    s.exit_code = 2;
    return s;
  }
  if (setup_error) std::rethrow_exception(setup_error);

  const Context ctx{spec, runs, options.output_dir, runs_dir, {}};
  const auto work = [&ctx](std::size_t index) {
    Outcome o;
    o.index = index;
    try {
      o.row = ExecuteRun(ctx, ctx.runs[index]);
    } catch (...) {
      o.fatal = std::current_exception();
    }
    return o;
  };
  const auto previous_int = std::signal(SIGINT, OnSweepSignal);
  const auto previous_term = std::signal(SIGTERM, OnSweepSignal);
  struct RestoreSignals {
    decltype(previous_int) int_handler, term_handler;
    ~RestoreSignals() {
      std::signal(SIGINT, int_handler);
      std::signal(SIGTERM, term_handler);
    }
  } restore{previous_int, previous_term};

  if (rank != 0) {
    // A worker rank: ask for a run per slot, run what comes, send the rows.
    WorkerPool pool(jobs, work);
    StopRunsOnError stop_on_error;
    for (int slot = 0; slot < jobs; ++slot) transport->SendToRoot(EncodeWorkerMessage(false, false, std::nullopt));
    int active_slots = jobs;
    while (active_slots > 0) {
      bool acted = false;
      std::int64_t code = 0;
      while (transport->PollControl(&code)) {
        acted = true;
        if (code == kInterrupt) g_stop.store(true);
        else if (code == kStopSlot) --active_slots;
        else if (g_stop.load()) transport->SendToRoot(EncodeWorkerMessage(true, true, std::nullopt));  // declined
        else pool.Submit(static_cast<std::size_t>(code));
      }
      Outcome o;
      while (pool.TryPop(&o)) {
        if (o.fatal) {
          try {
            std::rethrow_exception(o.fatal);
          } catch (const std::exception& e) {
            std::fprintf(stderr, "crowdrecon: error on MPI rank %d, run %zu: %s\n", rank, o.index, e.what());
          }
          transport->Abort(3);
        }
        acted = true;
        transport->SendToRoot(EncodeWorkerMessage(true, g_stop.load(), o.row));
      }
      if (!acted) pool.WaitFor(std::chrono::milliseconds(2));
    }
    s.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
    return s;
  }

  // Rank 0 (or the only process): hand out runs, write rows.
  s.already_done = store->done().size();
  s.results_sqlite = store->sqlite_file();
  s.results_csv = store->csv_file();
  std::deque<std::size_t> pending;
  for (const RunPlan& r : runs)
    if (!store->done().contains(r.index)) pending.push_back(r.index);
  const int remote_slots = (ranks - 1) * jobs;
  int remote_stopped = 0;
  std::size_t remote_in_flight = 0;
  bool stopping = false;
  bool interrupt_sent = false;
  std::exception_ptr fatal;
  auto last_csv = Clock::now();
  ProgressLine progress(options.show_progress);

  s.runs_per_rank.assign(static_cast<std::size_t>(ranks), 0);
  const auto commit = [&](const ResultRow& row, int from_rank) {
    store->Commit(row);
    ++s.runs_per_rank[static_cast<std::size_t>(from_rank)];
    ++s.completed;
    if (row.status != "complete") ++s.failed;
    if (options.stop_after_runs >= 0 && static_cast<long long>(s.completed) >= options.stop_after_runs) {
      stopping = true;
      g_stop.store(true);
    }
    // The CSV follows the table every few seconds, and at the end.
    if (Clock::now() - last_csv > std::chrono::seconds(10)) {
      store->WriteCsv();
      last_csv = Clock::now();
    }
  };

  {
    WorkerPool pool(jobs, work);
    StopRunsOnError stop_on_error;
    if (options.stop_after_runs == 0) stopping = true;
    while (true) {
      bool acted = false;  // something happened: look again before waiting
      if (g_stop.load()) stopping = true;
      if (stopping) g_stop.store(true);
      if (stopping && mpi && !interrupt_sent) {
        for (int r = 1; r < ranks; ++r) transport->SendControl(r, kInterrupt);
        interrupt_sent = true;
      }
      while (!stopping && !pending.empty() && pool.outstanding() < static_cast<std::size_t>(jobs)) {
        pool.Submit(pending.front());
        pending.pop_front();
        acted = true;
      }
      if (mpi) {
        int source = 0;
        std::string bytes;
        while (transport->PollFromWorkers(&source, &bytes)) {
          acted = true;
          const WorkerMessage m = DecodeWorkerMessage(bytes);
          if (m.had_run) --remote_in_flight;
          if (m.row) commit(*m.row, source);
          if (m.stopping) stopping = true;
          if (!stopping && !pending.empty()) {
            transport->SendControl(source, static_cast<std::int64_t>(pending.front()));
            pending.pop_front();
            ++remote_in_flight;
          } else {
            transport->SendControl(source, kStopSlot);
            ++remote_stopped;
          }
        }
      }
      Outcome o;
      while (pool.TryPop(&o)) {
        acted = true;
        if (o.fatal) {
          if (!fatal) fatal = o.fatal;
          stopping = true;
          g_stop.store(true);
        } else if (o.row) {
          commit(*o.row, 0);
        }
      }
      const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
      progress.Show(store->done().size(), s.total, s.completed, s.failed, pool.outstanding() + remote_in_flight, elapsed,
                    false);
      if (pool.outstanding() == 0 && (pending.empty() || stopping) && remote_stopped == remote_slots) break;
      if (!acted) pool.WaitFor(std::chrono::milliseconds(mpi ? 2 : 200));
    }
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  progress.Show(store->done().size(), s.total, s.completed, s.failed, 0, elapsed, true);
  progress.End();
  store->WriteCsv();
  if (fatal) std::rethrow_exception(fatal);
  s.remaining = s.total - store->done().size();
  s.interrupted = s.remaining > 0;
  s.wall_s = elapsed;
  return s;
}

}  // namespace crowdrecon::sweep
