// The incident timeline of a scenario (issue 20): an open venue whose people
// arrive through entry zones on an inflow schedule and leave through exits,
// timed events (a parameter change, an evacuation order, an exit opened or
// closed, an inflow started or stopped, falls the accounts record) and
// people who fall. Scenario key
// "timeline" (docs/scenarios.md, "Timelines"):
//
//   "timeline": {
//     "inflows": [
//       {"id": "leaving", "entry": "court_side", "group": "main",
//        "rate_per_s": [[0, 0.5], [600, 1.5]], "interpolation": "linear"},
//       {"id": "arriving", "entry": "street_side", "group": "counter", "rate_csv": "arrivals.csv"}
//     ],
//     "exits": ["street", "court"],            (default: every exit of the venue)
//     "closed_exits": [],                      (exits closed at t = 0: a door, a wall)
//     "events": [
//       {"time_s": 300, "set": {"back_force_gamma": 2.0}, "group": "main"},
//       {"time_s": 600, "target": "street", "group": "counter"},
//       {"time_s": 900, "close_exit": "court"}, {"time_s": 950, "stop_inflow": "arriving"},
//       {"time_s": 1000, "fall": {"at": [6, 1.5], "count": 5, "within_m": 3}}
//     ],
//     "premovement": {"uniform_s": [10, 100]},  (the people of the start set off at their times)
//     "falls": {"criterion": "acceleration", "threshold_m_per_s2": 5, "window_s": 0.5}
//              (or "criterion": "load"; with "acceleration", "trip_over_fallen": true)
//   }
//
// The schedule is deterministic: the k-th arrival of an inflow is due when
// the integral of its rate (counted while the inflow is on) reaches k; who
// arrives (body, desired speed) is drawn when the world is built, from the
// population's rules and the seed. Everything here is plain data; the systems
// that act on it are in scenario/src/timeline_systems.hpp.
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "crowdrecon/common/distribution.hpp"

namespace crowdrecon {
class JsonReader;
}  // namespace crowdrecon

namespace crowdrecon::geometry {
struct Venue;
}  // namespace crowdrecon::geometry

namespace crowdrecon::scenario {

// A rate over time (persons/s): points (t_k, r_k) with t ascending; "step":
// r_k on [t_k, t_k+1), "linear": interpolated between points; before the
// first point the rate is 0, after the last it stays r_last.
struct RateSchedule {
  std::vector<std::pair<double, double>> points;
  bool linear = false;
  // The integral from the first point to each point (Prepare); lets
  // Cumulative take O(log n) for a schedule of many rows.
  std::vector<double> prefix;

  // Fills `prefix` (after the points change).
  void Prepare();
  // The rate held back to at most `cap` (an inflow's "max_rate_per_s"):
  // min(rate, cap) at every time, exactly (a linear piece that crosses the
  // cap gets a point where it does).
  void Cap(double cap);
  double RateAt(double t_s) const;
  // The integral of the rate from -infinity to t (people due by t if always
  // on), exact for both kinds.
  double Cumulative(double t_s) const;
  // The integral over [a, b]: Cumulative(b) - Cumulative(a), 0 if b <= a.
  double Integral(double a_s, double b_s) const;
  // The inverse of Cumulative: the first time by which the integral reaches
  // `count` (the first point's time for count <= 0; +infinity where the
  // rate after the last point is 0 and the schedule never brings it).
  double TimeOfCumulative(double count) const;
};

struct InflowSpec {
  std::string id;
  std::string entry;            // venue entry zone
  std::size_t entry_index = 0;  // index into venue.entries
  std::string group;            // "main", "counter" or a name of its own
  std::string target;           // venue target of the arrivals (default: the group's)
  RateSchedule rate;
  bool on_at_start = true;      // "active": false waits for a start_inflow event
  // Desired speeds of the arrivals, v0 ~ U(min, max) (default: the population's).
  std::optional<std::pair<double, double>> desired_speed_m_per_s;
  std::string where;            // JSON path, for messages
};

struct TimelineEvent {
  enum class Kind { kSetParameters, kTarget, kOpenExit, kCloseExit, kStartInflow, kStopInflow, kFall };
  double time_s = 0.0;
  Kind kind = Kind::kSetParameters;
  std::string group;  // "" = everyone (kSetParameters, kTarget)
  // kSetParameters: model parameters by name (engine parameter table), plus
  // "desired_speed_m_per_s" (everyone of the group, and later arrivals of it).
  std::vector<std::pair<std::string, double>> parameters;
  std::string name;   // kTarget: target; k*Exit: exit id; k*Inflow: inflow id; kFall: its JSON path alone
                      // (the run's events name it; the file's name would differ between a run and its branch)
  // kFall, a fall the accounts record (an input, unlike a RecordedMark): the
  // `fall_count` walking people whose centres are nearest `fall_at` (ties by
  // id), of those within `fall_within_m` of it, fall at once. The model does
  // not decide who falls first; the fall criterion and tripping decide who
  // falls after them.
  double fall_at_x = 0.0, fall_at_y = 0.0;
  std::size_t fall_count = 0;
  double fall_within_m = 0.0;
  std::string where;  // JSON path, for messages
};

// ERRATA 10: "if pedestrians accelerate above 5 m/s^2 they were assumed to
// fall down", then lie as obstacles that neither rotate nor translate.
struct FallSpec {
  enum class Criterion { kNone, kAcceleration, kLoad };
  Criterion criterion = Criterion::kNone;
  // Acceleration criterion: |v(t) - v(t - window_s)| / window_s, the mean
  // acceleration over the window, above the threshold. The window: the
  // relaxation time tau = 0.5 s of eq. (3), the time on which a person takes
  // up a change of velocity of their own; single contacts last milliseconds
  // (2 pi / omega_max ~ 2-3 ms) and their spikes average out. A head-on
  // bump of two walkers (1.2 m/s each, restitution 0.4) changes a velocity
  // by 1.7 m/s: 3.4 m/s^2 over tau, not a fall; over 0.25 s it would be
  // 6.7 m/s^2, and every such bump would fell someone (measured in an open
  // hallway with counter-flow: docs/decisions.md, "Falls").
  double threshold_m_per_s2 = 5.0;
  double window_s = 0.5;
  // Tripping (issue 39; off: the paper's rule). A fallen person lies on the
  // floor: whoever runs into them is stopped (the acceleration above), and
  // whoever is pushed onto them is not held up at chest height but goes over
  // them. With it on, the same filter also runs on the velocity each person
  // would have had without the forces of their contacts with fallen people,
  // and either mean above the threshold fells them. Until the first fall it
  // is the paper's rule bit for bit (docs/decisions.md, "Falls that happen").
  bool trip_over_fallen = false;
  // Load criterion: the person's chest load (the larger of across the chest
  // and across the shoulders, reports/chest_load.hpp; table person_load)
  // above load_n for load_duration_s without a break.
  double load_n = 2000.0;
  double load_duration_s = 5.0;
  // Velocities are sampled for the filter this often (s); the window holds
  // window_s / sample_s samples.
  double sample_s = 0.05;
};

// Something recorded of the real incident at a time of the run (an
// avalanche on camera, the fatal clog): drawn on the timeline figure and,
// for the calibration, compared with what the run gives. Never an input of
// the simulation.
struct RecordedMark {
  double time_s = 0.0;
  std::string label;  // "avalanche 02:18"
  std::string kind;   // "avalanche", "fatal" or "other"
  // A speed read from the footage at this mark, with its uncertainty (NaN:
  // none): the paper's "velocities up to 3 m/s" at the fifth avalanche,
  // which a calibration matches with the observations' max_speed.
  double max_speed_m_per_s = std::numeric_limits<double>::quiet_NaN();
  double max_speed_uncertainty_m_per_s = std::numeric_limits<double>::quiet_NaN();
  bool HasMaxSpeed() const { return std::isfinite(max_speed_m_per_s); }
};

// Pre-movement times (RiMEA test 5, IMO MSC.1/Circ.1238 test 5, NIST TN 1822
// Verif.1.1): each person of the start stands (desired speed 0) until their
// time, then walks at their own desired speed (or their group's, if an event
// set one before). Arrivals through inflows walk at once. Key
// "premovement": a distribution (common/distribution.hpp: {"uniform_s": [10,
// 100]}, {"gamma": {"shape": 1.291, "scale_s": 103.901}}, {"lognormal":
// {"mu": 4.586, "sigma": 0.967}}, {"weibull": {"shape": 1.195, "scale_s":
// 139.285}}; drawn per person from the population's seed, in id order) or
// {"times_s": [10, 20, ...]} (one per person of the start, in id order).
struct PremovementSpec {
  bool enabled = false;
  Distribution distribution;         // without times_s
  std::vector<double> times_s;       // or one time per person of the start
  std::string where;                 // JSON path, for messages
};

struct TimelineSpec {
  bool enabled = false;  // a "timeline" key is present
  PremovementSpec premovement;
  std::vector<InflowSpec> inflows;
  std::vector<std::string> exits;         // where people are removed (default: every exit)
  std::vector<std::string> closed_exits;  // closed at t = 0
  std::vector<TimelineEvent> events;      // in time order (stable for equal times)
  FallSpec falls;
  // Group names by index: 0 "main", 1 "counter", then the inflows' own.
  std::vector<std::string> groups;
  // Room for an arrival: a place in the entry zone where their body keeps
  // this gap (m) from everyone and every wall. A person steps into a crowd
  // where there is room for a step, not into every gap that their body
  // fits: 0.1 m, a third of a step's length (~0.3 m at the slow walk of a
  // dense crowd). Without it, arrivals fill an entry zone to the densest
  // packing the bodies allow (15 persons/m^2 in the hallway, measured).
  double entry_clearance_m = 0.1;
  // Most people in the venue at once (engine slots); 0: from the venue's area.
  std::size_t max_present = 0;
  // End the run (complete) once this share of the people who entered has
  // left through the exits (an evacuation "until 95 % have left"); 0: never.
  double stop_when_left_fraction = 0.0;
  // The wall-clock time of t = 0 ("02:00", for the figure's axis), and what
  // was recorded of the incident (the figure marks it; the run ignores it).
  std::string clock_start;
  // Seconds of the incident a second of the run stands for: 1, or a
  // compressed scenario's factor (10: the evening told ten times faster), so
  // that its figures, maps and scores give the incident's clock times
  // (analysis::RunClock). The run's physics does not read it.
  double clock_scale = 1.0;
  std::vector<RecordedMark> recorded;

  bool HasInflow() const { return !inflows.empty(); }
};

// Reads scenario key "timeline" (`reader` is its value). `venue` is the
// scenario's (entries, exits and targets are checked against it); `base_dir`
// resolves rate_csv files; `default_targets` are the population's main and
// counter targets (group defaults). Errors name the file, the JSON path or the
// CSV line, the value and what was expected.
TimelineSpec ReadTimeline(const JsonReader& reader, const geometry::Venue& venue, const std::filesystem::path& base_dir,
                          const std::string& main_target, const std::string& counter_target);

// A rate CSV: a header "time_s,rate_per_s", then one row per point (times
// ascending, rates >= 0). Throws InputError naming the file and line.
RateSchedule ReadRateCsv(const std::filesystem::path& file);

// The number of arrivals due by time t for a schedule always on: floor of
// the integral from 0 (the pool the world is built with).
std::size_t ArrivalsDue(const RateSchedule& rate, double t_s);
// When the k-th arrival (k >= 1) of such a schedule is due: the time the
// integral from 0 reaches k (where ArrivalsDue reaches k, but for its
// tolerance of 1e-9 people). It does not depend on how long a run is (the order
// in which a timeline numbers its arrivals, BuiltTimeline).
double ArrivalDueTime(const RateSchedule& rate, std::size_t k);

}  // namespace crowdrecon::scenario
