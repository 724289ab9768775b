// Regime of a hallway run (paper, Results: "three different regimes are
// observed ... i) lane formation ... ii) avalanches ... characterized by
// temporal clogging of the pedestrian flow, followed by a sudden release ...
// iii) clogging, characterized by a frozen stage"), decided from the time
// series of the crowd's mean speed along the desired direction.
//
// The criteria were fixed from these physical descriptions before any phase
// diagram was computed; every threshold is in RegimeOptions with its unit and
// reason, and docs/analysis.md states the definitions in full.
//
//   stop       the mean speed V(t) stays below stop_speed_m_per_s for at least
//              min_stop_duration_s (a stop that begins at the first frame is
//              the initial rest of a placed crowd, not a stop of a flow);
//   avalanche  after a stop, V rises above burst_speed_m_per_s; it starts at
//              the last upward crossing of stop_speed_m_per_s before that and
//              ends at the next downward crossing (or at the end of the run);
//   frozen     the mean of V over the last frozen_window_s is below
//              frozen_speed_m_per_s.
//
//   clogging     frozen at the end;
//   avalanches   not frozen, and at least min_avalanches avalanches start in
//                the stationary stage (after transient_s);
//   lanes        neither, the flow stopped at most max_stopped_fraction_for_lanes
//                of the stationary stage, and (if min_lane_order_for_lanes > 0)
//                the mean lane order reaches it;
//   unclassified anything else (e.g. one long stop and one release), or a run
//                too short to tell (stationary stage < frozen_window_s).
//
// Per direction (classifier version 2, ClassifyByDirection): the rules above
// are applied to each direction of travel's own mean speed (a group walking
// to one target), and the hallway's verdict combines them, the worst first:
// clogging if any direction is frozen at the end (a hallway one direction
// cannot pass is not free flow), else avalanches if any direction (or the
// crowd) has min_avalanches of them, else lanes if every direction and the
// crowd pass the lanes rule, else unclassified. Each direction keeps its own
// verdict and reason.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace crowdrecon::analysis {

enum class Regime {
  kLanes,         // free flow (lane formation at the stationary stage)
  kAvalanches,    // recurring stop-and-go: stops released by bursts of motion
  kClogging,      // frozen at the end of the run
  kUnclassified,  // none of the above clearly, or too short a run
};
const char* ToString(Regime regime);  // "lanes", "avalanches", "clogging", "unclassified"
bool FromString(const std::string& text, Regime* regime);

// The classifier's version, stored with every verdict (run value
// `regime_classifier`, summary `regime_classifier_version`): 1 judged the
// crowd's mean speed only; 2 judges each direction of travel and combines.
inline constexpr int kRegimeClassifierVersion = 2;

struct RegimeOptions {
  // Mean speed along the desired direction below which the flow counts as
  // stopped (m/s): a tenth of the mean desired speed (v0 ~ U(0.8, 1.2) m/s,
  // paper); at it a crowd advances one body depth (~0.3 m) in 3 s.
  double stop_speed_m_per_s = 0.1;
  // Mean speed that makes a release a burst (m/s): three times the stop
  // threshold, so that noise around the stop threshold is not an avalanche
  // (hysteresis), and 30 % of the desired speed: the crowd as a whole advances
  // a body depth per second.
  double burst_speed_m_per_s = 0.3;
  // Shortest stop (s): three relaxation times of the model (tau = 2/3 s,
  // paper): a person re-accelerates to their desired speed within ~tau, so a
  // dip shorter than this is a hesitation, not a stop.
  double min_stop_duration_s = 2.0;
  // Only a stop of a flow arms an avalanche: the series must first have
  // reached the burst speed (people placed at rest who start, bunch up and
  // set off again are starting, not released: issue 65, the night demo's
  // only "avalanche" and one at 02:00 in every seed of the full night). Off
  // for the regimes of the paper's diagrams (classifier version 2); on for
  // an incident's timeline (its avalanche marks and the local reading).
  bool require_flow_before_stop = false;
  // Only stops that begin this long after the series' first sample (or its
  // stretch's, between gaps) arm an avalanche (s): the start-up of a crowd
  // placed at rest, two groups placed facing each other meeting, stalling and
  // passing, is the transient (transient_s below), not a release. 0 for the
  // diagrams' regimes; an incident's timeline uses transient_s.
  double first_stop_after_s = 0.0;
  // Mean speed over the final window below which the flow is frozen (m/s):
  // half the stop threshold, i.e. the crowd advances less than two body depths
  // in the 10 s window: clogged "indefinitely" (paper) as far as a run can tell.
  double frozen_speed_m_per_s = 0.05;
  // Final window over which frozen-ness is judged (s): five minimal stops, and
  // longer than any stop that avalanches release.
  double frozen_window_s = 10.0;
  // Start-up stage left out of stationary averages (s): people are placed at
  // rest in random order; lanes need about the time to walk the 12 m corridor
  // once at ~1 m/s to form.
  double transient_s = 10.0;
  // Longest stationary stage (s): the regime is that of the stationary
  // state, which long runs reach at different times (lanes form, or plugs
  // freeze, between 20 and 150 s in the hallway), so the stage is the last
  // stationary_window_s of the run after the transient: six final windows,
  // the 12 m hallway walked five times at ~1 m/s. Once the state is reached a
  // longer run does not change the verdict. (Runs up to transient_s +
  // stationary_window_s long, e.g. the 30 s diagrams, are judged exactly as
  // by classifier version 1.)
  double stationary_window_s = 60.0;
  // Avalanches needed in the stationary stage for the avalanche regime: the
  // paper's regime is a recurring "temporal clogging followed by a sudden
  // release"; one stop-and-release may be a single rearrangement, two is the
  // least that recurs.
  int min_avalanches = 2;
  // Shortest stop before a release for that avalanche to count towards
  // min_avalanches (s); 0: every avalanche (the stop that armed it already
  // lasted min_stop_duration_s). The single-release reading sets 5 s
  // (SingleReleaseReading).
  double min_released_stop_s = 0.0;
  // Largest fraction of the stationary stage with the flow stopped that still
  // counts as free flow (lanes): lanes are a moving stationary state.
  double max_stopped_fraction_for_lanes = 0.1;
  // Lane order the stationary stage must reach for "lanes" (0 = not required).
  // Off by default: with little counter-flow free flow needs no lanes, and a
  // threshold here would be a fitted number.
  double min_lane_order_for_lanes = 0.0;

  bool IsValid(std::string* error) const;
};

struct Avalanche {
  std::size_t start_index = 0;  // sample where V rose above the stop speed
  std::size_t end_index = 0;    // sample where V fell back below it, or the last sample
  double start_time_s = 0.0;
  double end_time_s = 0.0;
  double duration_s = 0.0;
  double stopped_before_s = 0.0;  // from the start of the stop that preceded it
  double peak_speed_m_per_s = 0.0;
  // Mean distance travelled along the desired direction, the integral of V
  // over the avalanche (trapezoidal rule), m.
  double distance_m = 0.0;
  bool complete = true;         // false if the run ended during it
  bool stationary = false;      // starts after the transient
  // People who advanced at least AnalysisOptions::avalanche_move_m along their
  // desired direction during it; -1 where unknown (series without positions).
  int people_moved = -1;
  // Abruptness of the release: time from V crossing the stop speed upward to
  // V reaching the burst speed, both crossings interpolated linearly between
  // samples (s). A free start (eq. 2 without contacts) takes
  // tau ln((v0 - v_stop)/(v0 - v_burst)) = 0.17 s for v0 = 1 m/s.
  double rise_time_s = 0.0;
};

// The paper describes the avalanche regime as "temporal clogging of the
// pedestrian flow, followed by a sudden release". The default reading asks
// for it to recur (min_avalanches = 2); this one (issue 39, candidate (d))
// takes a single clog of at least 5 s that releases to flow as enough:
// `options` with min_avalanches = 1 and min_released_stop_s = 5. 5 s: the
// frozen window's half, 7.5 relaxation times -- a clog, not a hesitation.
RegimeOptions SingleReleaseReading(RegimeOptions options);

// The options of an incident timeline's avalanche marks (the run's avalanche
// events and the local reading by area): the defaults, but only stops of a
// flow (require_flow_before_stop) after the start-up (first_stop_after_s =
// transient_s) arm an avalanche.
RegimeOptions IncidentAvalancheOptions();

// Start of the stationary stage of a run from t_first to t_last:
// max(t_first + transient_s, t_last - stationary_window_s).
double StationaryStart(double t_first, double t_last, const RegimeOptions& options);

// Avalanches in a mean-speed series (`time_s` increasing, same length).
std::vector<Avalanche> FindAvalanches(const std::vector<double>& time_s, const std::vector<double>& speed_m_per_s,
                                      const RegimeOptions& options);

// The same over a series with gaps (NaN: nobody there to have a speed, a
// direction with no one walking yet or any more): each stretch between gaps
// on its own, so that an empty group is no stop and its first walkers no
// release (issue 65: the counter-flow's first arrivals were the night
// demo's only "avalanche"). Indices refer to the whole series.
std::vector<Avalanche> FindAvalanchesBetweenGaps(const std::vector<double>& time_s,
                                                 const std::vector<double>& speed_m_per_s,
                                                 const RegimeOptions& options);

struct DirectionRegime;

struct RegimeResult {
  Regime regime = Regime::kUnclassified;
  std::string reason;  // one sentence with the numbers that decided it
  std::vector<Avalanche> avalanches;  // all of them, transient included
  int stationary_avalanches = 0;
  double stationary_start_s = 0.0;      // time the stationary stage begins
  double stopped_time_fraction = 0.0;   // stationary samples with V < stop speed
  double end_mean_speed_m_per_s = 0.0;  // mean V over the final window
  bool frozen_at_end = false;
  double mean_lane_order = 0.0;  // over the stationary stage; NaN if no lane order given
  bool long_enough = false;      // stationary stage at least frozen_window_s long
  // Per direction of travel (ClassifyByDirection; empty from ClassifyRegime).
  std::vector<DirectionRegime> directions;
};

// One direction of travel: the people walking to one target (a group).
struct DirectionSeries {
  std::string name;                  // the target's name, or "group <k>"
  std::size_t people = 0;
  std::vector<double> speed_m_per_s;  // mean of v_i . e_i per sample; NaN where nobody is present
};

struct DirectionRegime {
  std::string name;
  std::size_t people = 0;
  RegimeResult result;  // the rules applied to this direction's series alone
};

// Classifies a run from its mean speed along the desired direction and
// (optionally, may be empty) its lane order series. Throws InputError if the
// options are invalid or the series differ in length.
RegimeResult ClassifyRegime(const std::vector<double>& time_s, const std::vector<double>& mean_speed_m_per_s,
                            const std::vector<double>& lane_order, const RegimeOptions& options);

// The hallway's verdict from the crowd's series and each direction's (see the
// combination rule at the top). The result holds the crowd's measurements
// (stopped fraction, avalanches, ...) with the combined regime and reason, and
// `directions` one verdict each. A direction's samples without anyone present
// are left out of its series (an open venue that empties); a direction with
// no sample left is skipped. Throws InputError as ClassifyRegime.
RegimeResult ClassifyByDirection(const std::vector<double>& time_s, const std::vector<double>& crowd_speed_m_per_s,
                                 const std::vector<DirectionSeries>& directions,
                                 const std::vector<double>& lane_order, const RegimeOptions& options);

}  // namespace crowdrecon::analysis
