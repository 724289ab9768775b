// The time series of an incident timeline's run (issue 20), for its figure
// and for the calibration: density in the venue, the counter-flow's share,
// each direction's mean speed, the flow through the measurement line, the
// people waiting at the entries, the avalanches and falls the run recorded,
// and what was recorded of the real incident (the scenario's marks).
//
//   density        people in the venue (walking and fallen: table census, or
//                  the frame's people) over the walkable area;
//   counter share  people of group 1 (the counter-flow) over people present;
//   speeds, flows  AnalyzeRun's series (run_analysis.hpp): each group's mean
//                  speed along its desired direction; crossings of the line
//                  per metre and second, trailing 2 s window;
//   exits          people removed through each exit by each frame;
//   smoothing      each series is also given as a centred moving mean over
//                  smooth_s (default 10 s), what the figure draws.
#pragma once

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "crowdrecon/analysis/plausibility.hpp"
#include "crowdrecon/analysis/regime.hpp"

namespace crowdrecon::analysis {

struct TimelineMark {
  double time_s = 0.0;
  std::string label;
  std::string kind;  // recorded: "avalanche", "fatal", "other"; detected: the event's kind
  // A detected avalanche's rise time (s), from its event ("... rise time
  // 0.05 s ...", written by the timeline's avalanche system); NaN otherwise.
  double rise_time_s = std::numeric_limits<double>::quiet_NaN();
};

// The clock of a timeline's run (the scenario's timeline.clock_start and
// timeline.clock_scale; run values timeline_clock_start, timeline_clock_scale):
// t seconds of the run stand for t x scale seconds of the incident after
// `start` (a compressed scenario's scale: 10 for a night told ten times
// faster).
struct RunClock {
  std::string start;   // "HH:MM" of t = 0, or "" (no clock)
  double scale = 1.0;  // seconds of the incident per second of the run
  // "02:37" for the incident's time at run time t; without a start, the
  // incident's minutes ("37 min").
  std::string Text(double t_s) const;
  // A time axis' label at run time t with ticks every tick_s: the clock
  // (Text) where a tick spans a minute of the incident or more, the run's
  // seconds otherwise ("30 s").
  std::string TickText(double t_s, double tick_s) const;
  // The words under such an axis: "time of the run" without a start or a
  // scale, "time of the incident since the run's start (a second of the run
  // stands for 10 s)" with a scale alone, else "time of night (run time 0 =
  // 21:45)", with the scale where it is not 1.
  std::string AxisLabel() const;
  // A moment's title (a density map's): "t = 15 s" of the run; with a scale
  // alone "t = 15 s (2 min 30 s of the incident)"; with a start the clock
  // ("21:47:30"), as the axis reads (issue 65, F11: maps and figure were on
  // two clocks).
  std::string MomentText(double t_s) const;
  bool operator==(const RunClock&) const = default;
};

struct TimelineSeries {
  std::string run_file;
  RunClock clock;
  double area_m2 = 0.0;
  std::vector<double> time_s;
  std::vector<double> density_per_m2;
  // Per measurement area of the venue (its id, its area) the people whose
  // centre lies inside it per square metre, by frame (an alley's own density
  // inside a street network's).
  std::vector<std::string> area_names;
  std::vector<double> area_m2_each;
  std::vector<std::vector<double>> area_density_per_m2;  // [area][frame]
  // The same areas' flow: the mean speed of the walking people inside along
  // their group's desired direction, by frame (NaN where nobody walks there);
  // the series the local reading of avalanches reads (AreaAvalanches).
  std::vector<std::vector<double>> area_speed_m_per_s;  // [area][frame]
  std::vector<double> counter_fraction;  // NaN where nobody is present
  std::vector<double> queued;            // waiting at the entries (0 without a census)
  std::vector<std::string> group_names;
  std::vector<std::vector<double>> group_speed_m_per_s;  // [group][frame]
  std::vector<double> flow_forward_per_m_s, flow_backward_per_m_s;
  // Per exit of the venue: its id and width, and the people who left
  // through it by each frame (cumulative, from the events `exit`).
  std::vector<std::string> exit_names;
  std::vector<double> exit_width_m;
  std::vector<std::vector<double>> exit_left;  // [exit][frame]
  std::vector<TimelineMark> avalanches;  // detected during the run (events `avalanche`)
  std::vector<TimelineMark> falls;       // events `fall`
  std::vector<TimelineMark> recorded;    // the scenario's marks (run value timeline_recorded)
  Plausibility validity;                 // states a human crowd can reach (the run's analysis, default options)
  double smooth_s = 10.0;
};

// Reads a run file; throws InputError if it is not a run or has no frames.
TimelineSeries ComputeTimeline(const std::filesystem::path& run_file, double smooth_s = 10.0);

// The local reading of avalanches (issue 39; docs/analysis.md, "Local
// avalanches"): the footage's avalanches were seen where a camera looked
// ("the fifth avalanche, at end of the corridor", paper, Figure 3), not as a
// stop of a whole hallway, so a stop and release of the flow inside one
// measurement area counts too. The analysis's detector (FindAvalanches,
// `options`) runs on each area's speed series, over each stretch of frames
// in which someone walks there; a release counts when the area was a crowd
// in contact while it was stopped: its mean density over the stop at least
// `min_density_per_m2` (Fruin's involuntary contact, kContactDensity). Each
// mark's label names the area; rise_time_s is the detector's.
inline constexpr double kContactDensity_per_m2 = 3.6;
std::vector<TimelineMark> AreaAvalanches(const TimelineSeries& s, const RegimeOptions& options = {},
                                         double min_density_per_m2 = kContactDensity_per_m2);

// One release seen in several places (the crowd, a direction, areas) is one
// avalanche: marks sorted by time, and a mark starting within `within_s` of
// the last one kept is dropped (the first seen stands for it).
std::vector<TimelineMark> MergeAvalanches(std::vector<TimelineMark> marks, double within_s);

// A run's avalanches under the local reading: its own avalanche events (the
// crowd's and each direction's) and its areas' (AreaAvalanches, default
// options), merged within the detector's shortest stop.
std::vector<TimelineMark> AvalanchesWithAreas(const TimelineSeries& s);

// Centred moving mean over `window_s` (NaN values left out; NaN where a window has none).
std::vector<double> MovingMean(const std::vector<double>& time_s, const std::vector<double>& values, double window_s);

// When the run is clogged for good: the start of the stretch, reaching its
// last frame, in which every direction present moves slower than
// `stop_speed_m_per_s` in its desired direction (each direction's speed as a
// moving mean over `smooth_s`); NaN if the last frame is not clogged or the
// stretch is shorter than `min_s`. Defaults: the regime classifier's stop
// speed and frozen window. The ensemble's score and a calibration's recorded
// fatal clog both read it (docs/reports.md, docs/calibration.md).
double ClogForGood(const TimelineSeries& s, double smooth_s = 10.0,
                   double stop_speed_m_per_s = RegimeOptions{}.stop_speed_m_per_s,
                   double min_s = RegimeOptions{}.frozen_window_s);

// An exit's specific flow: people per metre of its width and second between
// the times when 10 % and 90 % of those it let out had left (NaN if fewer
// than 10 left).
double ExitSpecificFlow(const TimelineSeries& s, std::size_t exit);

}  // namespace crowdrecon::analysis
