// Measures of the validation suite: what a test reads from trajectories, the
// same code for a simulated run and for an experiment's trajectories
// (observe::Trajectories holds either), so that a model is compared with data
// through one definition of every statistic (docs/validation.md, "Measures").
//
// A measure turns one run (or one experiment) into named statistics, each a
// list of values: one value for a statistic of the run (a flow, a clearance
// time), one per person (a travel time, a walking speed) or one per sample
// (a headway). Criteria (validation_test.hpp) pool them over seeds.
//
//   kind                 statistics
//   travel               travel_time_s, speed_m_per_s (per person: from the first crossing of
//                        `from` to the first crossing of `to` after it); arrived_share
//   walls                outside_walls (samples whose centre lies inside a wall's swept disc or
//                        beyond the walls), wall_crossings (frame-to-frame steps of a centre
//                        across a wall), people
//   walking_speed        speed_m_per_s (per person: path length / time inside `area`), with
//                        the person's group: speed_m_per_s@GROUP for each group name
//   passages             passed, passed_share, flow_per_s ((N-1) / (last - first passage)),
//                        sustained_flow_per_s ((N-1) / (the end - first passage), the end being
//                        the last passage when everyone passed, else the run's end),
//                        span_s, median_lapse_s, max_lapse_s, open_lapse_s (last passage to the
//                        end while people are left; 0 when everyone passed), tail_exponent,
//                        time_to_all_s (the last passage), time_to_95_s, front_density_per_m2
//                        (people in `area` / its area, mean over the frames between the first
//                        and the last passage; with an area)
//   clearance            left_share (people whose track ends before the last frame: removed at an
//                        exit, or out of an experiment's view), time_to_all_s (the last of them,
//                        when everyone left), time_to_95_s
//   fundamental_diagram  density_per_m2, speed_m_per_s (means over the frames after `skip_s`
//                        with somebody in `area`), specific_flow_per_m_s (their product),
//                        fd_density_per_m2 and fd_speed_m_per_s (one per frame sample, for the
//                        data's band)
//   headway              headway_m (per sample: distance to the nearest person ahead in the
//                        same file, within `lane_half_width_m` of the walking direction and
//                        `max_headway_m`), density_per_m2
//   lanes                lane_order (per sampled frame: the mean over walkers in `area` of
//                        (same - opposite) / (same + opposite), counting the walkers within
//                        `lane_half_width_m` across and 1.5 m along `direction` of each, by the sign
//                        of their velocity along it; 1: everyone in lanes), organized_share (of
//                        frames at or above 0.8), lane_breaks (organized runs that fell below 0.6:
//                        lanes that broke), lane_reformations (broken lanes that became organized
//                        again), longest_organized_s, organized_at_end
//   start_times          (from the run file: its `start` events, timeline.premovement) premovement_s
//                        (each person's time, there at it or not), start_delay_s (per person: the first frame from 1 s
//                        before their time at which they are 0.01 m from where they stood then, less
//                        their time), moved_early (people pushed 0.01 m from where they stood more
//                        than 1 s before their time), never_started, started_people (start events: times that came), gone_before_start
//                        (not walking at their time: pushed out of the venue, or fallen)
//   run_state            (from the run file; not for experiments) completed, peak_local_density_per_m2,
//                        peak_local_density_real_per_m2, largest_overlap_m
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/observe/observation.hpp"
#include "crowdrecon/observe/trajectories.hpp"

namespace crowdrecon::validate {

enum class MeasureKind {
  kTravel, kWalls, kWalkingSpeed, kPassages, kClearance, kFundamentalDiagram, kHeadway, kLanes, kStartTimes, kRunState
};
std::string ToString(MeasureKind kind);
// False (and *kind untouched) for a name that is not a measure.
bool FromString(const std::string& name, MeasureKind* kind);
// "travel, walls, ..." for messages.
std::string MeasureKindNames();
// The statistics a measure of `kind` gives (a run's measures also
// "completed"; walking_speed also "speed_m_per_s@GROUP" per group): a test's
// criterion that names another is refused when the test is read (issue 65,
// K19: a misspelt statistic was found after the runs, as a model failure).
// The measures' tests check every statistic they give is listed here.
const std::vector<std::string>& StatisticNames(MeasureKind kind);
// "" if `statistic` is one a measure of `kind` gives, else why not.
std::string UnknownStatistic(MeasureKind kind, const std::string& statistic);

struct MeasureSpec {
  MeasureKind kind = MeasureKind::kRunState;
  observe::Line from_line, to_line;  // travel
  observe::Line line;                // passages
  Vec2 direction{1.0, 0.0};          // passages: a crossing counts when it goes this way (normalised;
                                     // zero, "both" in a test file: either way); lanes: the walking axis
  bool has_area = false;
  observe::Region area;              // walking_speed, fundamental_diagram, headway; passages (optional: front density)
  double skip_s = 0.0;               // fundamental_diagram, headway: the start-up left out (s)
  double velocity_span_s = 0.4;      // fundamental_diagram, headway: positions this far apart give a velocity (s)
  double lane_half_width_m = 0.3;    // headway: how far off a walker's line a person still counts as ahead
  double max_headway_m = 5.0;        // headway: farther than this, nobody is ahead
  int frame_step = 5;                // fundamental_diagram, headway: every n-th frame (frames of one person are nearly alike)
  // Every kind: only the people of this group ("main", "counter" or a
  // timeline's own group name; "" = everyone). An experiment's people have
  // no group: a group given there keeps none.
  std::string group;

  bool IsValid(std::string* error) const;
};

// Named statistics: each a list of values (one for a run's own statistic,
// one per person or sample otherwise). A statistic that does not exist for
// this run (a flow with fewer than two passages) is absent or NaN.
using Statistics = std::map<std::string, std::vector<double>>;

// Applies the measure to trajectories (a run or an experiment). `walls` are
// a run's walls (run_state and walls need a run: use MeasureRun).
Statistics MeasureTrajectories(const observe::Trajectories& trajectories, const MeasureSpec& spec);

// Applies the measure to a run file: the trajectories' measure, and for
// `walls` and `run_state` what only a run holds (its walls, its validity).
// A run that did not complete gives completed = 0 and nothing else.
Statistics MeasureRun(const std::filesystem::path& run_file, const MeasureSpec& spec);

// The times (s) a track first crosses `line` going along `direction` (any way
// when `direction` is zero), interpolated within the frame interval; NaN if
// it never does. Exposed for tests.
double FirstCrossing_s(const observe::Track& track, double fps, const observe::Line& line, Vec2 direction,
                       double after_s = -1e300);

}  // namespace crowdrecon::validate
