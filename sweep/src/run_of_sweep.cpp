// One run of a sweep (run_of_sweep.hpp), and the runs folder's partial runs (sweep_runner.hpp).
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
#include "crowdrecon/common/wall_clock.hpp"
#include "crowdrecon/reports/ensemble.hpp"
#include "crowdrecon/reports/risk.hpp"
#include "crowdrecon/scenario/runner.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/sweep/results.hpp"
#include "crowdrecon/sweep/sweep_file.hpp"
#include "run_of_sweep.hpp"

namespace crowdrecon::sweep {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace detail {

namespace {

std::string ReplaceAll(std::string text, const std::string& from, const std::string& to) {
  if (from.empty()) return text;
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

// Each metric's position in ResultRow::metrics, by name.
const std::map<std::string, std::size_t>& MetricColumnOf() {
  static const std::map<std::string, std::size_t> column_of = [] {
    std::map<std::string, std::size_t> m;
    for (std::size_t i = 0; i < MetricColumns().size(); ++i) m[MetricColumns()[i]] = i;
    return m;
  }();
  return column_of;
}

// The group a per-group metric belongs to ("mean_speed_g2_m_per_s",
// "passages_g2": 2), or -1 for a metric of the whole run.
int GroupOfMetric(const std::string& name) {
  for (std::size_t at = name.find("_g"); at != std::string::npos; at = name.find("_g", at + 1)) {
    std::size_t end = at + 2;
    while (end < name.size() && name[end] >= '0' && name[end] <= '9') ++end;
    if (end > at + 2 && (end == name.size() || name[end] == '_')) return std::stoi(name.substr(at + 2, end - at - 2));
  }
  return -1;
}

ResultRow RowOf(const RunPlan& run, const analysis::RunAnalysis& a) {
  const std::map<std::string, std::size_t>& column_of = MetricColumnOf();
  ResultRow row;
  row.run_index = run.index;
  row.status = "complete";
  row.regime = analysis::ToString(a.regime.regime);
  row.regime_reason = a.regime.reason;
  row.metrics.assign(MetricColumns().size(), std::numeric_limits<double>::quiet_NaN());
  for (const analysis::SummaryValue& v : a.SummaryTable()) {
    const auto it = column_of.find(v.name);
    // The table holds the main flow's and the counter-flow's columns (groups
    // 0 and 1); a scenario's further groups (an inflow's own) are in the
    // run's own analysis, not here.
    if (it == column_of.end() && GroupOfMetric(v.name) >= 2) continue;
    if (it == column_of.end())
      throw std::logic_error("sweep: the analysis reports \"" + v.name + "\", which has no results column");
    row.metrics[it->second] = v.value;
  }
  return row;
}

// The run's injury-risk counts (default options) into the risk columns; a run
// without chest loads or contacts leaves them empty.
void AddRiskColumns(const fs::path& file, ResultRow* row) {
  const std::map<std::string, std::size_t>& column_of = MetricColumnOf();
  reports::RunRisk risk;
  reports::RiskOptions options;
  options.read_contacts = false;  // the loads suffice
  try {
    risk = reports::AnalyseRunRisk(file, options);
  } catch (const InputError&) {
    return;
  }
  double longest = 0.0, max_load = 0.0;
  for (const reports::PersonRisk& p : risk.people) {
    longest = std::max(longest, p.longest_above_f0_s);
    max_load = std::max(max_load, p.max_load_n);
  }
  row->metrics[column_of.at("people_uncomfortable")] = risk.counts[1];
  row->metrics[column_of.at("people_danger")] = risk.counts[2];
  row->metrics[column_of.at("people_beyond_tolerance")] = risk.beyond_tolerance;
  row->metrics[column_of.at("max_chest_load_n")] = max_load;
  row->metrics[column_of.at("longest_above_f0_s")] = longest;
}

}  // namespace

void RemoveRunFiles(const fs::path& file) {
  std::error_code ec;
  fs::remove(file, ec);
  for (const char* suffix : kRunFileSidecars) fs::remove(file.string() + suffix, ec);
}

std::string StatusOf(const fs::path& file) {
  try {
    return runfile::RunFileReader(file).RunValue("status");
  } catch (const std::exception&) {
    return "";
  }
}

std::optional<ResultRow> ExecuteRun(const RunContext& ctx, const RunPlan& run) {
  const auto start = Clock::now();
  const fs::path file = ctx.runs_dir / (run.id + ".sqlite");
  const scenario::Scenario sc = RunScenarioOf(ctx.spec, run);  // checked before the sweep started
  scenario::RunOptions options;
  options.output = file;
  // Parallel over runs, not within one; a run handed out when no other was
  // left to start may take the cores that the runs before it free as they
  // end (engine::ThreadGovernor keeps it on one thread while they run).
  options.threads = ctx.threads_of_run ? ctx.threads_of_run->at(run.index) : 1;
  options.stop_flag = ctx.stop;
  if (ctx.simulated_s) options.simulated_s = &ctx.simulated_s[run.index];
  const bool resume = fs::exists(file) && fs::exists(scenario::CheckpointPath(file));
  // A run that completed but whose row was never written (the sweep was
  // stopped or killed while analysing it: hours of a long run's analysis)
  // is analysed, not simulated again.
  const bool completed = !resume && fs::exists(file) && StatusOf(file) == "complete";
  if (!resume && !completed) RemoveRunFiles(file);  // a run killed outright starts over

  ResultRow row;
  bool failed = false;
  double earlier_wall_s = 0.0;  // a resumed run's earlier invocations
  try {
    scenario::RunSummary summary;
    if (completed) {
      summary.status = "complete";
      summary.total_wall_s = scenario::RecordedWallSeconds(file);
    } else if (resume) {
      options.resume = true;
      try {
        summary = scenario::RunScenario(sc, options);
      } catch (const InputError&) {
        if (ctx.stop->load()) return std::nullopt;
        // A run that went numerically wrong after its checkpoint would go
        // wrong again, identically, from the start (hours later, for a long
        // run, and with its message and saved state deleted): it is
        // recorded as failed, its files kept. Only an unusable checkpoint
        // starts over.
        if (StatusOf(file).rfind("failed", 0) == 0) throw;  // (unreadable: as an unusable checkpoint)
        RemoveRunFiles(file);
        options.resume = false;
        summary = scenario::RunScenario(sc, options);
      }
    } else {
      summary = scenario::RunScenario(sc, options);
    }
    if (summary.status != "complete") return std::nullopt;
    earlier_wall_s = summary.total_wall_s - summary.wall_s;  // (all of it for a run simulated before)
    row = RowOf(run, analysis::AnalyzeRun(file, ctx.analysis));
    AddRiskColumns(file, &row);
    if (ctx.spec.ensemble_summaries) {
      // (Before the run file may go: its summary is what an ensemble keeps.)
      const reports::EnsembleOptions ensemble;
      const fs::path folder = ctx.runs_dir.parent_path() / "summaries";
      fs::create_directories(folder);
      WriteFileAtomically(folder / (run.id + ".json"),
                          reports::EnsembleSummaryJson(file, reports::ReadEnsembleRun(file, ensemble), ensemble));
    }
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
  // The caller's own measurement of the run (outside the try: its errors are
  // not the run's result but the sweep's).
  if (ctx.after_run && *ctx.after_run) (*ctx.after_run)(run, file, failed ? row.status : std::string("complete"));
  // A failed run keeps its file (and saved state) for inspection.
  if (!ctx.spec.keep_runs && !failed) RemoveRunFiles(file);
  row.wall_s = earlier_wall_s + std::chrono::duration<double>(Clock::now() - start).count();
  return row;
}

}  // namespace detail

using namespace detail;

std::vector<fs::path> RemovePartialRuns(const fs::path& sweep_dir) {
  const fs::path runs = sweep_dir / "runs";
  std::vector<fs::path> files, removed;
  std::error_code ec;
  for (fs::directory_iterator it(runs, ec), end; !ec && it != end; it.increment(ec)) files.push_back(it->path());
  std::sort(files.begin(), files.end());
  // A sidecar's run file: its name without the suffix ("" if it is none).
  const auto run_file_of = [](const fs::path& p) {
    const std::string name = p.string();
    for (const char* suffix : kRunFileSidecars) {
      const std::string s = suffix;
      if (name.size() > s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0)
        return fs::path(name.substr(0, name.size() - s.size()));
    }
    return fs::path();
  };
  for (const fs::path& p : files) {
    std::error_code gone;
    if (p.extension() == ".sqlite") {
      const std::string status = StatusOf(p);  // "" if killed before its first tables were written
      if (status.rfind("failed", 0) == 0 || status == "complete") continue;
      RemoveRunFiles(p);
      removed.push_back(p);
    } else if (const fs::path owner = run_file_of(p); !owner.empty() && !fs::exists(owner, gone)) {
      if (fs::remove(p, gone)) removed.push_back(p);  // (not those removed with their run file above)
    }
  }
  return removed;
}

}  // namespace crowdrecon::sweep
