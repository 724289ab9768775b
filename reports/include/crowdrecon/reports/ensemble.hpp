// An ensemble of an incident's runs (issue 39, point 5): several seeds of a
// timeline scenario scored against what was recorded of the incident, and
// their figure, one row per run with its avalanches and falls beside the
// recorded times.
//
//   reports::EnsembleOptions o;               // tolerance, clog rule, risk
//   std::vector<reports::EnsembleRun> runs;
//   for (auto& f : files) runs.push_back(reports::ReadEnsembleRun(f, o));
//   const reports::EnsembleScore s = reports::ScoreEnsemble(runs, o);
//   s.Markdown(); s.Csv(); reports::DrawEnsembleFigure(s, "Madrid night", "ensemble.png");
//
// The score, for each recorded avalanche: the share of runs with an
// avalanche of their own within +-tolerance of it; per run: its avalanches
// that match no recorded one, when its venue clogs for good (against the
// recorded fatal clog), its falls before that, the people in the danger zone
// at its worst moment and its peak local density -- each as a median and
// range over the runs. Definitions: docs/reports.md, "Ensembles of an
// incident".
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "crowdrecon/analysis/regime.hpp"
#include "crowdrecon/analysis/timeline_series.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/reports/report.hpp"
#include "crowdrecon/reports/risk.hpp"

namespace crowdrecon::reports {

struct EnsembleOptions {
  // A run's avalanche matches a recorded one within this many seconds of run
  // time (the issue's +-2 minutes; a compressed scenario scales it with its
  // marks, e.g. 6 s for the demo's 1/20).
  double tolerance_s = 120.0;
  // Clogged: every direction of travel present moves slower than this along
  // its desired direction (the mean over the timeline's smoothing window;
  // the regime classifier's stop speed).
  double clog_speed_m_per_s = analysis::RegimeOptions{}.stop_speed_m_per_s;
  // Clogged for good: clogged from some time to the end of the run, for at
  // least this long (the classifier's frozen window).
  double clog_min_s = analysis::RegimeOptions{}.frozen_window_s;
  // The timeline series' smoothing window (s).
  double smooth_s = 10.0;
  // The danger zone's lower edge (reports::RiskOptions::danger_n).
  double danger_n = RiskOptions{}.danger_n;
  // The local reading of avalanches (analysis::AreaAvalanches): releases
  // inside the venue's measurement areas count besides the run's own
  // avalanche events, one release seen in several places once
  // (analysis::MergeAvalanches within the detector's shortest stop).
  bool area_avalanches = false;
  bool IsValid(std::string* error) const;
};

struct EnsembleRun {
  std::string run_file;
  std::string label;  // "seed 3", or the file's name (also where seeds repeat: ScoreEnsemble)
  analysis::RunClock clock;
  double end_s = 0.0;
  std::vector<double> avalanche_s;  // the run's avalanche events
  std::vector<double> rise_time_s;  // their rise times (NaN where the event gives none)
  std::vector<double> fall_s;       // its falls
  std::vector<double> time_s, density_per_m2;  // smoothed density, for the figure
  std::vector<std::string> area_names;         // the venue's measurement areas
  std::vector<std::vector<double>> area_density_per_m2;  // [area][frame], smoothed (an alley's own density)
  double clog_for_good_s = std::numeric_limits<double>::quiet_NaN();  // NaN: never
  std::size_t danger_peak = 0;  // most people above danger_n at once (1-s smoothed chest load)
  double danger_peak_time_s = std::numeric_limits<double>::quiet_NaN();
  bool loads_available = false;
  double peak_density_per_m2 = 0.0;             // local, over ~1 m^2 (analysis/plausibility.hpp)
  double peak_equivalent_density_per_m2 = 0.0;  // the same floor covered by real-size people
  std::vector<analysis::TimelineMark> recorded;  // the scenario's marks
};

// Reads one run (throws InputError naming the file if it is not a finished
// timeline run), or a run's summary (a file ending in .json written by
// WriteEnsembleSummary: what scoring and drawing need, so that an ensemble
// run over several sessions keeps each finished run's part in the
// repository instead of its run file), which must have been made with the
// same options (else InputError naming them).
EnsembleRun ReadEnsembleRun(const std::filesystem::path& run_file, const EnsembleOptions& options);

// A run's summary for an ensemble (format "crowdrecon-ensemble-run",
// version 1; docs/reports.md, "Ensembles over several sessions"): the
// EnsembleRun read with these options, the options, the run's scenario as
// the seeds' check compares it (its seed apart, file names only), its seed,
// the SHA-256 of its walkable area and of its run file; the density series
// thinned to at most kSummaryPoints points each, times to 1 ms and densities
// to 1e-4 /m² (for the figure; every score comes from exact numbers).
inline constexpr std::size_t kSummaryPoints = 2000;
std::string EnsembleSummaryJson(const std::filesystem::path& run_file, const EnsembleRun& run,
                                const EnsembleOptions& options);
struct EnsembleRunSummary {
  EnsembleRun run;
  EnsembleOptions options;
  std::string profile;  // the run's model profile
  std::string scenario_json;   // compared across seeds
  std::uint64_t seed = 0;
  std::string walkable_sha256, run_sha256;
};
// Throws InputError naming `origin` and the JSON path where the text is not
// such a summary.
EnsembleRunSummary ParseEnsembleSummary(const std::string& text, const std::string& origin);
// Recognises an earlier summary (for writing into its place).
OutputKind EnsembleSummaryOutput();
// A run file's or a summary's model profile and scenario name ("" where none).
std::string EnsembleRunProfile(const std::filesystem::path& run_or_summary);
std::string EnsembleRunScenarioName(const std::filesystem::path& run_or_summary);

// An ensemble is the seeds of one scenario: runs whose stored scenarios
// (the run value "scenario", with its overrides; files by their names, the
// venue by the walkable area each run stored) differ in anything but
// population.seed are refused, naming both runs and the first JSON path
// where they differ (a sweep's paper variant beside an extension's), and so
// are two runs of one seed (a copy of a run under another name would count
// twice). By content, not by name (issue 65). `what` names the ensemble in
// messages ("the ensemble"), `apart` says where other runs go ("give
// another scenario's runs with --compare").
void CheckSeedsOfOneScenario(const std::vector<std::filesystem::path>& runs, const std::string& what,
                             const std::string& apart = "give another scenario's runs apart");

struct RecordedScore {
  analysis::TimelineMark mark;
  std::size_t runs_matching = 0;   // runs with an avalanche within +-tolerance
  std::vector<bool> matched;       // per run
};

struct EnsembleScore {
  EnsembleOptions options;
  std::vector<EnsembleRun> runs;
  std::vector<RecordedScore> avalanches;  // one per recorded avalanche, in time order
  std::vector<analysis::TimelineMark> fatal;  // recorded marks of kind "fatal"
  std::vector<std::size_t> unmatched;     // per run: its avalanches within +-tolerance of no recorded one
  std::vector<std::size_t> falls_before_clog;  // per run (all its falls if it never clogs for good)
  // Median and range over the runs (reports::Spread; runs without the figure left out).
  Spread unmatched_spread, clog_spread, clog_minus_fatal_spread, falls_before_clog_spread, danger_spread,
      density_spread, equivalent_density_spread, avalanche_count_spread,
      rise_time_spread;  // over every avalanche of every run (s), against a free start's 0.17 s
  std::size_t runs_clogging_for_good = 0;

  std::string Markdown() const;  // the score table and one row per run
  std::string Csv() const;       // one row per run (RFC 4180)
};

// Scores runs of one scenario against its recorded marks (those of the first
// run; every run must carry the same). Throws InputError if they differ.
EnsembleScore ScoreEnsemble(std::vector<EnsembleRun> runs, const EnsembleOptions& options);

// A previous score file (Markdown or CSV, recognised by its first line).
OutputKind EnsembleScoresOutput();

// The figure: the runs' densities over time (top), then one row per run
// with its avalanches, falls and the stretch clogged for good, the recorded
// avalanches and their +-tolerance across every row. PNG, SVG or PDF.
void DrawEnsembleFigure(const EnsembleScore& score, const std::string& title, const std::filesystem::path& file);

// Ensembles of one incident side by side (`timeline RUN... --compare
// RUN...`: the validated crowd beside the paper's model, a fitted night
// beside the free one): each with its label. One score table with a column
// per ensemble, one CSV with an `ensemble` column, one figure with each
// ensemble's densities in its colour and its rows under its name. With one
// ensemble, the outputs above. CheckComparable refuses ensembles whose
// recorded marks, clock or tolerance differ (InputError naming a run of each).
struct LabelledEnsemble {
  std::string label;
  const EnsembleScore* score = nullptr;
};
void CheckComparable(const std::vector<LabelledEnsemble>& ensembles);
std::string EnsemblesMarkdown(const std::vector<LabelledEnsemble>& ensembles);
std::string EnsemblesCsv(const std::vector<LabelledEnsemble>& ensembles);
void DrawEnsemblesFigure(const std::vector<LabelledEnsemble>& ensembles, const std::string& title,
                         const std::filesystem::path& file);

}  // namespace crowdrecon::reports
