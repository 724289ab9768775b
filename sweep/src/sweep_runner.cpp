// Running a sweep (sweep_runner.hpp): its runs handed out to worker threads
// and MPI ranks, their rows gathered, progress, interruption. One run:
// run_of_sweep.cpp.
#include "crowdrecon/common/output_path.hpp"
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
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/scoped_signals.hpp"
#include "crowdrecon/common/wall_clock.hpp"
#include "crowdrecon/scenario/runner.hpp"
#include "crowdrecon/reports/risk.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/sweep/results.hpp"
#include "crowdrecon/sweep/sweep_file.hpp"
#include "mpi_transport.hpp"
#include "run_of_sweep.hpp"

namespace crowdrecon::sweep {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using namespace detail;  // one run of a sweep (run_of_sweep.hpp)

namespace {

// Set by SIGINT / SIGTERM, by --stop-after-runs, by a fatal error and by rank
// 0's interrupt message; every run in progress polls it after each frame.
std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

// Set by SIGINT / SIGTERM alone: the sweep then reports itself interrupted
// even when no run was left (the signal came as the last one finished, or
// while there was nothing to run), so that the caller stops too instead of
// losing the request (a calibration would go on to its next batch).
std::atomic<bool> g_signalled{false};

extern "C" void OnSweepSignal(int signal) {
  RecordStopSignal(signal);
  g_signalled.store(true);
  g_stop.store(true);
}

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

namespace {

using Work = std::function<Outcome(std::size_t)>;

// What every rank sets up before any run: the sweep, its runs, every run's
// scenario checked (so that a bad override stops the sweep before any run),
// the runs folder; rank 0 also opens the results.
struct SweepSetup {
  SweepSpec spec;
  std::vector<RunPlan> runs;
  std::unique_ptr<ResultsStore> store;  // rank 0 only
  fs::path runs_dir;
  std::exception_ptr error;
};

// 1. Set-up (its error kept, so that MPI ranks can agree on it first).
SweepSetup SetUpSweep(const SweepOptions& options, int rank) {
  SweepSetup setup;
  setup.runs_dir = options.output_dir / "runs";
  try {
    setup.spec = LoadSweep(options.sweep_file);
    setup.runs = ExpandRuns(setup.spec);
    const std::vector<std::string> notes = ValidateRuns(setup.spec, setup.runs);
    if (rank == 0)
      for (const std::string& note : notes) std::fprintf(stderr, "crowdrecon: note: %s\n", note.c_str());
    CreateOutputFolder(setup.runs_dir);
    if (rank == 0)
      setup.store = std::make_unique<ResultsStore>(options.output_dir, setup.spec, setup.runs, analysis::OptionsToJson({}));
  } catch (...) {
    setup.error = std::current_exception();
  }
  return setup;
}

// 2. Under MPI, every rank learns whether all could set up. Every rank reads
//    the same files, so they usually fail alike: rank 0 reports, the others
//    stay quiet unless only they failed. False: this rank stops with `s`.
bool AgreeOnSetUp(MpiTransport& transport, int rank, const std::exception_ptr& error, SweepSummary* s) {
  if (transport.AllOk(!error)) return true;
  const bool root_ok = transport.RootOk(!error);
  if (error && rank == 0) std::rethrow_exception(error);
  if (error && root_ok) {
    try {
      std::rethrow_exception(error);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "crowdrecon: MPI rank %d: %s\n", rank, e.what());
    }
  }
  if (rank == 0) throw InputError("another MPI rank could not start the sweep (its message is above)");
  s->exit_code = 2;
  return false;
}

// 3a. A worker rank: asks for a run per slot, runs what comes, sends the rows.
void RunWorkerRank(MpiTransport& transport, int rank, int jobs, const Work& work) {
  WorkerPool pool(jobs, work);
  StopRunsOnError stop_on_error;
  for (int slot = 0; slot < jobs; ++slot) transport.SendToRoot(EncodeWorkerMessage(false, false, std::nullopt));
  int active_slots = jobs;
  while (active_slots > 0) {
    bool acted = false;
    std::int64_t code = 0;
    while (transport.PollControl(&code)) {
      acted = true;
      if (code == kInterrupt) g_stop.store(true);
      else if (code == kStopSlot) --active_slots;
      else if (g_stop.load()) transport.SendToRoot(EncodeWorkerMessage(true, true, std::nullopt));  // declined
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
        transport.Abort(3);
      }
      acted = true;
      transport.SendToRoot(EncodeWorkerMessage(true, g_stop.load(), o.row));
    }
    if (!acted) pool.WaitFor(std::chrono::milliseconds(2));
  }
}

// 3b. Rank 0, or the only process: hands out the runs not yet done (to its
//     own worker threads and to the worker ranks' slots), commits each row as
//     it comes, keeps the CSV and the progress line up to date, and stops
//     everyone on a signal, on --stop-after or on an error.
class Coordinator {
 public:
  Coordinator(const SweepOptions& options, const SweepSetup& setup, MpiTransport* transport, int ranks, int jobs,
              Clock::time_point start, std::vector<int>* threads_of_run, std::atomic<double>* simulated_s,
              SweepSummary* s)
      : options_(options), spec_(setup.spec), runs_(setup.runs), store_(*setup.store), transport_(transport),
        ranks_(ranks), jobs_(jobs), start_(start), threads_of_run_(*threads_of_run), simulated_s_(simulated_s), s_(*s),
        progress_(options.show_progress) {
    s_.already_done = store_.done().size();
    s_.results_sqlite = store_.sqlite_file();
    s_.results_csv = store_.csv_file();
    s_.runs_per_rank.assign(static_cast<std::size_t>(ranks), 0);
    for (const RunPlan& r : setup.runs)
      if (!store_.done().contains(r.index)) pending_.push_back(r.index);
  }

  void Run(const Work& work) {
    {
      WorkerPool pool(jobs_, work);
      StopRunsOnError stop_on_error;
      if (options_.stop_after_runs == 0) stopping_ = true;
      const int remote_slots = (ranks_ - 1) * jobs_;
      for (;;) {
        bool acted = false;  // something happened: look again before waiting
        StopIfAsked();
        while (!stopping_ && !pending_.empty() && pool.outstanding() < static_cast<std::size_t>(jobs_)) {
          const std::size_t index = pending_.front();
          pending_.pop_front();
          threads_of_run_.at(index) = TailThreads();
          in_flight_.insert(index);
          pool.Submit(index);
          acted = true;
        }
        if (transport_) acted |= ServeWorkerRanks();
        Outcome o;
        while (pool.TryPop(&o)) {
          acted = true;
          in_flight_.erase(o.index);
          if (o.fatal) {
            if (!fatal_) fatal_ = o.fatal;
            stopping_ = true;
            g_stop.store(true);
          } else if (o.row) {
            Commit(*o.row, 0);
          }
        }
        progress_.Show(store_.done().size(), s_.total, s_.completed, s_.failed, pool.outstanding() + remote_in_flight_,
                       Elapsed(), false);
        LogProgress(pool.outstanding() + remote_in_flight_);
        if (pool.outstanding() == 0 && (pending_.empty() || stopping_) && remote_stopped_ == remote_slots) break;
        if (!acted) pool.WaitFor(std::chrono::milliseconds(transport_ ? 2 : 200));
      }
    }
    const double elapsed = Elapsed();
    progress_.Show(store_.done().size(), s_.total, s_.completed, s_.failed, 0, elapsed, true);
    progress_.End();
    store_.WriteCsv();
    if (fatal_) std::rethrow_exception(fatal_);
    s_.remaining = s_.total - store_.done().size();
    s_.interrupted = s_.remaining > 0 || g_signalled.load();
    s_.wall_s = elapsed;
  }

 private:
  double Elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

  // The engine threads of the run being handed out: 1 while others are left
  // to start (the cores go to runs); the sweep's last run gets up to one per
  // worker (at most the cores), so that it does not run on one core for
  // hours after the others have ended. A long ensemble's last seed is the
  // case. Locally only: an MPI rank's other slots are not this process's to
  // count. The results do not depend on it (the engine's results do not
  // depend on its thread count).
  int TailThreads() const {
    if (transport_ || !pending_.empty()) return 1;
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    return std::max(1, std::min(jobs_, cores));
  }

  // Now and then, for a log (SweepOptions::log_progress_every_s): the runs
  // done, and how far each of this process's running runs has got.
  void LogProgress(std::size_t running) {
    if (options_.show_progress || !(options_.log_progress_every_s > 0)) return;
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - last_log_).count() < options_.log_progress_every_s) return;
    last_log_ = now;
    std::string line = "  " + WallClockNow() + "  sweep: " + std::to_string(store_.done().size()) + " / " +
                       std::to_string(s_.total) + " runs (" + std::to_string(s_.failed) + " failed), " +
                       std::to_string(running) + " running, " + FormatDuration(Elapsed()) + " elapsed";
    for (const std::size_t index : in_flight_) {
      const double t = simulated_s_[index].load(std::memory_order_relaxed);
      if (t < 0) continue;  // not started yet
      if (!duration_s_.contains(index)) duration_s_[index] = RunScenarioOf(spec_, runs_[index]).run.duration_s;
      line += "; " + runs_[index].id + " at " + FormatFixed(t, 1) + " / " + FormatNumber(duration_s_[index]) + " s";
    }
    std::fprintf(stderr, "%s\n", line.c_str());
    std::fflush(stderr);
  }

  // A signal or a stop anywhere stops everyone (the worker ranks once).
  void StopIfAsked() {
    if (g_stop.load()) stopping_ = true;
    if (stopping_) g_stop.store(true);
    if (stopping_ && transport_ && !interrupt_sent_) {
      for (int r = 1; r < ranks_; ++r) transport_->SendControl(r, kInterrupt);
      interrupt_sent_ = true;
    }
  }

  // The worker ranks' messages: rows to commit, and a free slot each, which
  // gets the next run or is told to stop.
  bool ServeWorkerRanks() {
    bool acted = false;
    int source = 0;
    std::string bytes;
    while (transport_->PollFromWorkers(&source, &bytes)) {
      acted = true;
      const WorkerMessage m = DecodeWorkerMessage(bytes);
      if (m.had_run) --remote_in_flight_;
      if (m.row) Commit(*m.row, source);
      if (m.stopping) stopping_ = true;
      if (!stopping_ && !pending_.empty()) {
        transport_->SendControl(source, static_cast<std::int64_t>(pending_.front()));
        pending_.pop_front();
        ++remote_in_flight_;
      } else {
        transport_->SendControl(source, kStopSlot);
        ++remote_stopped_;
      }
    }
    return acted;
  }

  void Commit(const ResultRow& row, int from_rank) {
    store_.Commit(row);
    ++s_.runs_per_rank[static_cast<std::size_t>(from_rank)];
    ++s_.completed;
    if (row.status != "complete") ++s_.failed;
    if (options_.stop_after_runs >= 0 && static_cast<long long>(s_.completed) >= options_.stop_after_runs) {
      stopping_ = true;
      g_stop.store(true);
    }
    // The CSV follows the table every few seconds, and at the end.
    if (Clock::now() - last_csv_ > std::chrono::seconds(10)) {
      store_.WriteCsv();
      last_csv_ = Clock::now();
    }
  }

  const SweepOptions& options_;
  const SweepSpec& spec_;
  const std::vector<RunPlan>& runs_;
  ResultsStore& store_;
  MpiTransport* transport_;  // null without MPI
  int ranks_, jobs_;
  Clock::time_point start_;
  std::vector<int>& threads_of_run_;
  std::atomic<double>* simulated_s_;
  SweepSummary& s_;
  ProgressLine progress_;
  std::deque<std::size_t> pending_;
  int remote_stopped_ = 0;
  std::size_t remote_in_flight_ = 0;
  bool stopping_ = false;
  bool interrupt_sent_ = false;
  std::exception_ptr fatal_;
  Clock::time_point last_csv_ = Clock::now();
  std::set<std::size_t> in_flight_;            // this process's runs handed out, not yet back
  std::map<std::size_t, double> duration_s_;   // their scenarios' durations, once asked
  Clock::time_point last_log_ = Clock::now();
};

}  // namespace

SweepSummary RunSweep(const SweepOptions& options) {
  const auto start = Clock::now();
  g_stop.store(false);
  g_signalled.store(false);
  const bool mpi = LaunchedAsMpiRank();
  std::unique_ptr<MpiTransport> transport;
  if (mpi) transport = std::make_unique<MpiTransport>();
  const int rank = mpi ? transport->rank() : 0;
  const int ranks = mpi ? transport->size() : 1;
  const int jobs = options.jobs > 0 ? options.jobs
                                    : (mpi ? 1 : static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));

  SweepSetup setup = SetUpSweep(options, rank);
  SweepSummary s;
  s.name = setup.spec.name;
  s.ranks = ranks;
  s.jobs = jobs;
  s.coordinator = rank == 0;
  s.total = setup.runs.size();
  if (mpi && !AgreeOnSetUp(*transport, rank, setup.error, &s)) return s;
  if (setup.error) std::rethrow_exception(setup.error);

  std::vector<int> threads_of_run(setup.runs.size(), 1);  // set by rank 0's coordinator before each hand-out
  const std::unique_ptr<std::atomic<double>[]> simulated_s(new std::atomic<double>[setup.runs.size()]);
  for (std::size_t i = 0; i < setup.runs.size(); ++i) simulated_s[i].store(-1.0);
  const RunContext ctx{setup.spec, setup.runs, options.output_dir, setup.runs_dir, {}, &options.after_run,
                       &threads_of_run, simulated_s.get(), &g_stop};
  const Work work = [&ctx](std::size_t index) {
    Outcome o;
    o.index = index;
    try {
      o.row = ExecuteRun(ctx, ctx.runs[index]);
    } catch (...) {
      o.fatal = std::current_exception();
    }
    return o;
  };
  // SIGINT and SIGTERM stop the sweep after the runs in progress checkpoint;
  // the previous handlers come back when the sweep ends.
  const ScopedSignals signals(OnSweepSignal);
  // Under MPI every rank returns only when every run's row has reached rank
  // 0, so that what the runs left behind (their after_run files) is complete
  // on every rank when RunSweep returns there (a calibration reads it next),
  // and knows what rank 0 knows: failed, done, or interrupted (a worker rank
  // that went on as if its sweep were complete would look for runs never made),
  // and by which signal, so that every rank exits with rank 0's status (143
  // after SIGTERM, 130 otherwise).
  enum RootStatus { kFailed = 0, kDone = 1, kInterrupted = 2, kTerminated = 3 };
  if (rank != 0) {
    RunWorkerRank(*transport, rank, jobs, work);
    const int status = transport->RootStatus(kDone);
    if (status == kFailed) s.exit_code = 2;
    s.interrupted = status == kInterrupted || status == kTerminated;
    if (status == kTerminated) RecordStopSignal(SIGTERM);
    s.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
    return s;
  }
  try {
    Coordinator(options, setup, transport.get(), ranks, jobs, start, &threads_of_run, simulated_s.get(), &s).Run(work);
  } catch (...) {
    if (mpi) transport->RootStatus(kFailed);
    throw;
  }
  if (mpi)
    transport->RootStatus(!s.interrupted ? kDone : StopSignal().load() == SIGTERM ? kTerminated : kInterrupted);
  return s;
}


bool CheckedOnRankZero(const std::function<void()>& check) {
  if (!LaunchedAsMpiRank()) {
    check();
    return true;
  }
  MpiTransport mpi;
  if (mpi.rank() != 0) return mpi.RootOk(true);
  try {
    check();
  } catch (...) {
    mpi.RootOk(false);
    throw;
  }
  return mpi.RootOk(true);
}

}  // namespace crowdrecon::sweep
