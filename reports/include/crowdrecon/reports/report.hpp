// The injury-risk report: from one run or an ensemble of runs (seeds), and
// optionally a second ensemble to compare with, DIR/report.html (self-
// contained: figures as inline SVG), DIR/report.pdf (the same page printed
// by headless Chromium) and DIR/people.csv (one row per person and run).
//
//   reports::ReportOptions options;
//   options.inputs = {"hallway.sqlite"};
//   options.compare = {"evacuation.sqlite"};
//   options.output_dir = "out/report";
//   reports::ReportSummary summary = reports::WriteReport(options);
//   std::puts(summary.BriefReport().c_str());
//
// Used by `crowdrecon report`; docs/reports.md describes every section.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/reports/risk.hpp"

namespace crowdrecon::reports {

struct ReportOptions {
  // Run files, or folders whose *.sqlite run files (recursively) are taken:
  // one ensemble of seeds of one scenario.
  std::vector<std::filesystem::path> inputs;
  std::vector<std::filesystem::path> compare;  // a second ensemble (may be empty)
  std::string label = "runs";                  // names of the two ensembles in the report
  std::string compare_label = "comparison";
  std::filesystem::path output_dir;
  RiskOptions risk;
  bool pdf = true;          // print report.pdf with headless Chromium
  std::string chromium;     // the browser to print with; "" = chromium, chromium-browser, google-chrome on PATH
  std::string command_line; // recorded in the reproducibility section
  std::size_t table_rows = 40;  // people listed in the HTML table (all of them in people.csv)
  // The force network's close-up: a square window of this side (m) around
  // the most loaded person at the worst moment, drawn beside the whole view
  // when the whole view is more than three times as large (a 3-m alley in a
  // 75-m street network); 0: never.
  double close_up_m = 12.0;
  // A sweep's folder (DIR/results.sqlite) as the only input gives the
  // venue-design envelope: the region of the sweep's diagram where the median
  // over seeds of `envelope_metric` (a risk column of the results) stays at or
  // below `envelope_level`.
  std::string envelope_metric = "people_danger";
  double envelope_level = 0.0;
  bool force = false;           // replace what is at output_dir (never an input)
  std::function<void(const std::string&)> progress;  // one line per step (may be empty)
  // What the validation suite says of the model profiles (report
  // --validation: a validation's results.json, read by
  // validate::LoadValidationSummary), for the methods page: per profile, the
  // tests it passes and those it fails. Empty: the page says where to look.
  struct ProfileValidation {
    std::string profile;
    std::size_t tests = 0, passed = 0;
    std::vector<std::string> failed;  // "test-id (role)"
  };
  std::vector<ProfileValidation> validation;
  std::string validation_source;  // the results file and the build that judged

  bool IsValid(std::string* error) const;
};

// An interval across the runs of an ensemble: the median and the smallest
// and largest value over its runs.
struct Spread {
  double median = 0.0, low = 0.0, high = 0.0;
  std::size_t runs = 0;
};
// The spread of values over runs (NaN values, runs without the figure, left out).
Spread SpreadOf(std::vector<double> values);

// The ratio of the fractions of people in danger, other / main, over every
// pair of a run of each ensemble. A pair whose main run had nobody in danger
// has no finite ratio: it is counted apart (where the other run had someone)
// or not at all (nobody in either), never left out silently, so that a
// median over the finite pairs alone is not read as the ensembles' ratio.
struct DangerRatio {
  Spread finite;                      // the pairs whose main run had someone in danger
  std::size_t main_none = 0;          // pairs: nobody in the main run, someone in the other (ratio not finite)
  std::size_t neither = 0;            // pairs: nobody in danger in either run
  std::size_t Pairs() const { return finite.runs + main_none + neither; }
};
// Each run given as (people in danger, people in the run).
DangerRatio DangerRatioOf(const std::vector<std::pair<double, double>>& main,
                          const std::vector<std::pair<double, double>>& other);
// The ratio in a sentence naming both ensembles (html: escaped, its figure in bold).
std::string DangerRatioText(const DangerRatio& ratio, const std::string& main_label, const std::string& other_label,
                            bool html);

struct EnsembleSummary {
  std::string label;
  std::size_t runs = 0;
  std::array<Spread, kZones> zone;  // people per zone
  Spread people;                    // people who appeared
  Spread beyond_tolerance;          // dose >= 1
  Spread danger_fraction;           // danger / people
  double longest_exposure_s = 0.0;  // over every person of every run
  double max_load_n = 0.0;
};

struct ReportSummary {
  std::filesystem::path html, pdf, csv;
  EnsembleSummary main, other;  // other.runs = 0 without --compare
  // Ratio of the fraction of people in danger (other / main) over every
  // pair of runs (DangerRatioOf).
  DangerRatio danger_ratio;
  bool envelope = false;            // a sweep's design envelope (then main/other are empty)
  std::size_t envelope_runs = 0;
  std::vector<std::string> envelope_lines;  // per variant and row of the diagram: the envelope's reach
  // Per ensemble: whether its states are ones a human crowd can reach
  // (analysis/plausibility.hpp; issue 39), in plain words.
  std::vector<std::string> validity_lines;
  std::vector<std::string> notes;  // e.g. what a killed report had left in the folder, now removed
  double seconds = 0.0;
  std::string BriefReport() const;
};

ReportSummary WriteReport(const ReportOptions& options);

// A previous report folder (report.html written by crowdrecon, report.pdf,
// people.csv, and nothing else), which report -o may write into.
OutputKind ReportFolderOutput();

}  // namespace crowdrecon::reports
