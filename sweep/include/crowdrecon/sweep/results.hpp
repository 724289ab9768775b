// The results of a sweep: one row per run, in DIR/results.sqlite (written as
// runs finish, one transaction per row) and DIR/results.csv (the same columns,
// rows in run-index order; rewritten every 10 s and at the end).
//
//   runs(run_index INTEGER PRIMARY KEY, run_id TEXT, variant TEXT, seed INTEGER,
//        "<axis path>" REAL or TEXT (one column per axis),
//        status TEXT, regime TEXT, regime_reason TEXT,
//        <every value of analysis::RunAnalysis::SummaryTable()> REAL,
//        wall_s REAL)
//   sweep(key TEXT PRIMARY KEY, value TEXT)
//        format, version, name, sweep (the sweep JSON, compact), sweep_file,
//        scenario (the base scenario JSON, compact), scenario_file,
//        analysis_options (JSON), axes, variants, seeds (JSON lists),
//        diagram_x, diagram_y, runs_total, crowdrecon_version,
//        source_fingerprint
//
// status is "complete" or "failed: <message>" (the run could not be placed,
// or went numerically wrong); a failed run has no regime and NULL metrics.
// NULL (an empty CSV field) means "no value" (e.g. the counter-flow group's
// speed in a run without counter-flow). Every column but wall_s depends on
// the run's parameters only, so the tables are identical whatever the number
// of jobs and MPI ranks; the CSV writes numbers in their shortest exact form.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/sweep/sweep_file.hpp"

namespace crowdrecon::sweep {

// The summary metrics stored per run, by name, in column order: the names of
// RunAnalysis::SummaryTable() for a run with a main flow and a counter-flow
// (groups 0 and 1).
const std::vector<std::string>& MetricColumns();
// The injury-risk columns among them (reports/risk.hpp with its default
// options: F0 400 N, danger 1112 N): people per zone, beyond the tolerance
// dose, the largest chest load (1 s mean) and the longest exposure above F0.
const std::vector<std::string>& RiskColumns();

struct ResultRow {
  std::size_t run_index = 0;
  std::string status;          // "complete" or "failed: ..."
  std::string regime;          // analysis::ToString(Regime); "" if failed
  std::string regime_reason;
  std::vector<double> metrics;  // MetricColumns() order; NaN = no value
  double wall_s = 0.0;          // simulation (over all its invocations, if resumed) and analysis of this run (s)
};

// Exact binary form of a row (for messages between MPI ranks).
std::string SerializeRow(const ResultRow& row);
ResultRow DeserializeRow(const std::string& bytes);

// The results folder of one sweep, open for writing. Not thread-safe: one
// thread (the coordinator) owns it.
class ResultsStore {
 public:
  // Creates DIR/results.sqlite, or opens it to continue the same sweep.
  // Throws InputError if DIR holds the results of a different sweep (another
  // sweep file, a changed scenario or other analysis options).
  ResultsStore(const std::filesystem::path& dir, const SweepSpec& spec, const std::vector<RunPlan>& runs,
               const std::string& analysis_options_json);
  ~ResultsStore();
  ResultsStore(const ResultsStore&) = delete;
  ResultsStore& operator=(const ResultsStore&) = delete;

  // Runs that already have a row.
  const std::set<std::size_t>& done() const { return done_; }
  // Writes one row (its own transaction).
  void Commit(const ResultRow& row);
  // Rewrites DIR/results.csv from the table (atomically: a temporary file
  // renamed over it).
  void WriteCsv() const;

  std::filesystem::path sqlite_file() const;
  std::filesystem::path csv_file() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::set<std::size_t> done_;
};

// A results table read back (for `crowdrecon phase`).
struct ResultsTable {
  struct Cell {
    bool null = true;
    bool numeric = false;  // INTEGER or REAL
    double number = 0.0;   // INTEGER and REAL values
    std::string text;     // TEXT values (and numbers as text)
  };
  std::map<std::string, std::string> sweep;  // the sweep table
  std::vector<std::string> columns;
  std::vector<std::vector<Cell>> rows;  // in run-index order

  // Index of a column; throws InputError naming the file if it is missing.
  std::size_t Column(const std::string& name) const;
  // Index of a column, or nullopt if the table has none (a column added
  // after the table was written).
  std::optional<std::size_t> FindColumn(const std::string& name) const;
  std::filesystem::path file;
};

// Reads DIR/results.sqlite (or a results.sqlite file given directly).
// Throws InputError if it is missing or not a sweep's results.
ResultsTable ReadResults(const std::filesystem::path& dir_or_file);

// The model profile a sweep's runs ran (issue 64): the sweep's "set" of
// "profile", else its scenario's "profile", else "paper" (a scenario without
// one); "NAME, OTHER" where variants set their own; a profile file by its
// name. "" for results written before the sweep table kept its sweep and
// scenario.
std::string SweepProfile(const ResultsTable& table);

// The build's version as stored with results (`git describe` at build time),
// for people.
std::string BuildVersion();

// What runs are reused by: a digest of the sources compiled into the tools,
// the compiler and its flags (cmake/WriteVersion.cmake). Runs of different
// fingerprints are never mixed; builds of different commits with the same
// sources (a commit of documents or results) share them.
std::string SourceFingerprint();

// A previous sweep folder: its results.sqlite holds a crowdrecon sweep's
// results (or is still empty, a sweep killed while starting); `sweep -o`
// continues it (common/output_path.hpp).
OutputKind SweepFolderOutput();

}  // namespace crowdrecon::sweep
