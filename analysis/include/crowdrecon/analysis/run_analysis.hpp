// AnalyzeRun: time series and summary metrics of one run file, and its regime
// (lanes / avalanches / clogging, regime.hpp). Definitions, formulas, units and
// the reasons for every threshold: docs/analysis.md.
//
// Per frame: flow through the measurement line in each direction, mean speed
// along the desired direction (everybody and per group), lane order parameter
// (metrics.hpp), fraction of people stopped, mean and maximum per-person load
// (person_state.load_n) and the fraction of people above the load threshold.
// Per run: averages over the stationary stage, avalanches, frozen-at-end, the
// load distribution, the regime with its reason.
//
// Where the definitions come from:
//   desired directions  the targets of the venue stored in the run file when
//                       every person's target is a fixed direction (the
//                       periodic hallway); otherwise the
//                       direction of the group's mean velocity over the run;
//   measurement line    AnalysisOptions::line, else the venue's first
//                       measurement line, else a line through the middle of
//                       the walkable area, across group 0's direction;
//   periodic wrap       run value `periodic_box`.
// The analysis says which applied (direction_source, line_source).
//
// WriteAnalysis stores the results in the run file:
//   metric_series(frame INTEGER, name TEXT, value REAL)     one row per frame and series
//   metric_summary(name TEXT PRIMARY KEY, value REAL, unit TEXT)
//   metric_avalanche(idx, start_frame, end_frame, start_time_s, end_time_s, duration_s,
//                    stopped_before_s, peak_speed_m_per_s, distance_m, people_moved,
//                    complete, stationary, rise_time_s)
//   metric_load_histogram(lower_n REAL, upper_n REAL, count INTEGER)   upper_n NULL = overflow
//   run values `regime`, `regime_reason`, `analysis_options` (JSON)
// replacing the tables of an earlier analysis.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "crowdrecon/analysis/metrics.hpp"
#include "crowdrecon/analysis/passages.hpp"
#include "crowdrecon/analysis/plausibility.hpp"
#include "crowdrecon/analysis/regime.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::analysis {

struct AnalysisOptions {
  RegimeOptions regime;
  LaneOrderOptions lanes;
  PassageOptions passages;
  // A person is stopped below this speed (m/s), |v| not only along the
  // desired direction: the same tenth of the desired speed as the crowd's
  // stop threshold (RegimeOptions::stop_speed_m_per_s).
  double stopped_person_speed_m_per_s = 0.1;
  // Trailing window of the flow series (s): at ~1 person/(m s) through a 3 m
  // line a 0.1 s frame sees 0 or 1 crossing; 2 s averages ~6 of them while
  // still resolving a stop of min_stop_duration_s.
  double flow_window_s = 2.0;
  // Load counted as dangerous (N): the paper's estimate of the load that
  // asphyxiated the victims (F0 = 400 N, "Risk of asphyxia by crushing").
  double load_threshold_n = 400.0;
  // Histogram of per-person loads over the stationary stage: bins of this
  // width (N) up to load_histogram_max_n, and one overflow bin.
  double load_histogram_bin_n = 50.0;
  double load_histogram_max_n = 1000.0;
  // Distance (m) along the desired direction a person must advance during an
  // avalanche to count as moved by it: about one body depth (0.24 m thorax +
  // 2 x 0.05 m sphero-radius), i.e. the person took someone's place.
  double avalanche_move_m = 0.3;
  // Measurement line overriding the venue's (and the default).
  std::optional<MeasurementLine> line;

  bool IsValid(std::string* error) const;
};

// One value per frame. NaN where a value does not exist (the flow at the first
// frame, the lane order of a frame where nobody has a neighbour).
struct MetricSeries {
  std::vector<std::int64_t> frame;
  std::vector<double> time_s;
  // Crossings of the measurement line per second per metre of line, in a
  // trailing window of flow_window_s; forward = along group 0's desired
  // direction (hallway: +x), backward = against it.
  std::vector<double> flow_forward_per_m_s;
  std::vector<double> flow_backward_per_m_s;
  // Mean over people of v_i . e_i, e_i the person's desired direction (m/s).
  std::vector<double> mean_speed_m_per_s;
  std::vector<std::vector<double>> group_mean_speed_m_per_s;  // [group][frame]
  std::vector<double> lane_order;        // metrics.hpp, in [0, 1]
  std::vector<double> stopped_fraction;  // people with |v| < stopped_person_speed_m_per_s
  std::vector<double> mean_load_n;
  std::vector<double> max_load_n;
  std::vector<double> above_load_fraction;  // people with load_n > load_threshold_n

  struct Column {
    std::string name;  // with its unit, e.g. "mean_speed_m_per_s"
    const std::vector<double>* values;
  };
  // Every series with its table name (group series as mean_speed_g<k>_m_per_s).
  std::vector<Column> Columns(std::vector<std::string>* group_names = nullptr) const;
};

struct SummaryValue {
  std::string name;
  double value = 0.0;
  std::string unit;  // "" if dimensionless
};

struct RunAnalysis {
  std::string run_file;
  std::string status;  // run.status ("complete", "running", ...)
  std::size_t people = 0;
  std::size_t groups = 0;
  std::size_t frames = 0;
  double duration_s = 0.0;

  // How the measurements were set up.
  std::vector<Vec2> group_direction;  // desired direction per group (unit)
  std::vector<std::string> group_name;   // the group's target, or "group <k>"
  std::vector<std::size_t> group_people;  // people per group
  std::string direction_source;
  MeasurementLine line;
  Vec2 forward;  // unit normal of the line on group 0's side
  std::string line_source;
  PeriodicBox box;

  MetricSeries series;

  // Summary over the stationary stage (t >= first frame + transient_s) unless
  // said otherwise.
  double mean_speed_m_per_s = 0.0;
  std::vector<double> group_mean_speed_m_per_s;
  double flow_forward_per_m_s = 0.0;
  double flow_backward_per_m_s = 0.0;
  std::int64_t crossings_forward = 0;   // whole run
  std::int64_t crossings_backward = 0;  // whole run
  double mean_stopped_fraction = 0.0;
  double mean_lane_order = 0.0;  // NaN if never defined
  // Avalanches (regime.avalanches holds each one; these summarise the
  // stationary ones).
  double avalanche_mean_duration_s = 0.0;
  double avalanche_max_duration_s = 0.0;
  double avalanche_mean_distance_m = 0.0;
  double avalanche_mean_people = 0.0;
  // Loads, over every person and frame of the stationary stage except where
  // marked "whole run". The load is the chest load (the larger of across the
  // chest and across the shoulders, table person_load; docs/reports.md) in
  // runs that record it, else the sum of the magnitudes of the contact
  // forces (person_state.load_n, older runs): chest_loads says which.
  bool chest_loads = false;
  double max_load_n = 0.0;          // whole run
  std::int64_t max_load_person = 0;  // id (1-based), whole run
  double max_load_time_s = 0.0;      // whole run
  double mean_load_n = 0.0;
  double load_p50_n = 0.0, load_p90_n = 0.0, load_p99_n = 0.0;
  double above_load_person_frames = 0.0;  // fraction of person-frames above the threshold
  double max_above_load_fraction = 0.0;   // largest per-frame fraction, whole run
  std::int64_t people_ever_above_load = 0;  // whole run
  double longest_above_load_s = 0.0;        // longest time one person stayed above, whole run
  double load_histogram_bin_n = 0.0;
  std::vector<std::int64_t> load_histogram;  // last bin: >= load_histogram_max_n

  // Per group (direction of travel): its passages through the measurement
  // line along its own desired direction, over the stationary stage.
  std::vector<PassageStatistics> passages;
  double avalanche_mean_rise_time_s = 0.0;  // over the stationary avalanches of the crowd

  RegimeResult regime;  // regime.directions: one verdict per group with people
  // The same series under the single-release reading (SingleReleaseReading;
  // issue 39): a clog of at least 5 s that releases is enough for avalanches.
  RegimeResult regime_single_release;
  // Whether the run's states are ones a human crowd can reach (issue 39):
  // peak local density, largest overlap, against the stated range.
  Plausibility plausibility;
  std::vector<std::string> notes;  // fallbacks taken, run not complete, ...

  // Every summary number by name, for tables (metric_summary, sweep results).
  std::vector<SummaryValue> SummaryTable() const;
  std::string BriefReport() const;  // a few lines: regime and key numbers
  std::string FullReport() const;   // everything, avalanches one per line
  std::string ToJson() const;       // summary, avalanches, histogram, series
};

// Analyses a run file. Throws InputError if the file is missing, is not a
// run file, has fewer than two frames, or the options are invalid.
RunAnalysis AnalyzeRun(const std::filesystem::path& run_file, const AnalysisOptions& options = {});

// Writes the analysis into its run file (see the table list above). Refuses a
// run whose status is still "running" (its writer holds the file).
void WriteAnalysis(const std::filesystem::path& run_file, const RunAnalysis& analysis,
                   const AnalysisOptions& options);

// The options as JSON (stored with the results).
std::string OptionsToJson(const AnalysisOptions& options);

// A previous `analyze --json` file (keys run_file, regime, summary), which
// --json may replace (common/output_path.hpp).
OutputKind AnalysisJsonOutput();

}  // namespace crowdrecon::analysis
