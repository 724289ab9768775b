// Calibration files: which scenario values to fit, to which observations, with
// how many seeds and which approach (docs/calibration.md).
//
//   {
//     "format": "crowdrecon-calibration", "version": 1,
//     "name": "Madrid Arena hallway: Γ, λ and ε from the velocities",
//     "scenario": "../scenarios/hallway-5pm2-30cf.json",        (relative to this file)
//     "set": {"run.duration_s": 30, "run.contacts": false},     (every run, as in a sweep)
//     "parameters": [
//       {"path": "model.back_force_gamma", "min": 0.3, "max": 4.8, "start": 1.2},
//       {"path": "model.torsion_stiffness_lambda"},             (bounds: the parameter table; start: the scenario)
//       {"path": "population.desired_speed_m_per_s", "min": 0.6, "max": 1.8, "width": 0.4}   (a range's centre)
//     ],
//     "observations": [
//       {"file": "recorded.observation.json", "time_offset_s": 0,
//        "series": [{"quantity": "speed", "where": "hallway", "direction": "forward",
//                    "from_s": 5, "to_s": 30, "window_s": 0, "relative_error": 0,
//                    "simulated_from_s": 5, "simulated_to_s": 30,       (default: the same window + offset)
//                    "reduce": "mean"}],                                (or "max": the window's largest bin)
//        "events": [{"kind": "stop", "where": "hallway", "direction": "forward", "from_s": 0, "to_s": 30}]},
//       {"recorded": {"kind": "avalanche", "direction": "crowd", "from_s": 0, "to_s": 5700}},
//                                                                 (the scenario's timeline.recorded against the run's events)
//       {"recorded": {"kind": "max_speed", "spec": "../observations/hallway-night.json", "where": "exit end"}}
//     ],                                                          (a speed read from footage against the run's max_speed)
//     "seeds": {"first": 1, "count": 8},
//     "approach": "surrogate",                                   (or "gradient")
//     "starts": [{"model.back_force_gamma": 3.0}],               (more starting points)
//     "options": {"refinements": 2, "shrink": 0.5, "gradient_step": 0.1, "max_iterations": 8,
//                 "bootstrap": 200, "profile_points": 7, "measure_noise": false,
//                 "posterior_steps": 20000}
//   }
//
// "scenario", "set" and "seeds" mean what they mean in a sweep file (they are
// read by the sweep's parser, so overrides and file paths behave alike). A
// parameter's bounds default to the model parameter table's range for
// "model.*" paths and must be given otherwise; its start defaults to the
// base scenario's value (with "set" applied), else the table's default.
// Errors name the file, the JSON path, the value and what was expected.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "crowdrecon/observe/observation.hpp"
#include "crowdrecon/sweep/sweep_file.hpp"

namespace crowdrecon::calibrate {

struct Parameter {
  std::string path;  // dotted scenario path
  std::string name;  // its last element, for tables ("back_force_gamma")
  double min = 0.0, max = 1.0;
  double start = 0.0;
  // A range value ([low, high], e.g. population.desired_speed_m_per_s): the
  // parameter is its centre and the range keeps this width (0: a number).
  double width = 0.0;
  bool is_range = false;
  double Range() const { return max - min; }
  // The JSON text written at `path` for a value.
  std::string JsonOf(double value) const;
};

// A series of an observation compared over windows of time: the mean of its
// bins whose centres lie in each window [from, from + window), ..., up to to.
struct SeriesMatch {
  std::string quantity, where, direction;
  double from_s = 0.0, to_s = 0.0;  // on the observation's clock
  double window_s = 0.0;            // 0: one window from..to
  // The observation's systematic error as a fraction of its value (e.g. the
  // footage study's 10 %), added to its statistical one.
  double relative_error = 0.0;
  // The simulated window, when it is not the observed one shifted by the
  // observation's time offset (NaN): the steady state of an experiment
  // against the steady state of a periodic run. One window only.
  double simulated_from_s = std::numeric_limits<double>::quiet_NaN();
  double simulated_to_s = std::numeric_limits<double>::quiet_NaN();
  // "reduce": "max": a window's largest bin instead of its mean (a peak,
  // e.g. the fastest person during an avalanche; its uncertainty that bin's).
  bool take_max = false;
  // A value recorded of the incident instead of the observation's series
  // (timeline.recorded's max_speed: the observation has no series): the
  // observed value and its uncertainty (NaN: from the series).
  double recorded_value = std::numeric_limits<double>::quiet_NaN();
  double recorded_sigma = std::numeric_limits<double>::quiet_NaN();
};

// Events (observe/events.hpp) of one kind, place and direction, compared as
// cumulative counts: after each observed onset and at the end of the window.
struct EventMatch {
  std::string kind;  // stop, surge
  std::string where, direction;
  double from_s = 0.0, to_s = 0.0;
  // Instead of counts, the time of the first onset in the window (the
  // window's end where there is none): a recorded event that happens once,
  // the Madrid night's fatal clog against the run's clog for good. The
  // observed time and its uncertainty.
  bool first_time = false;
  double recorded_time_s = 0.0, recorded_sigma_s = 0.0;
};

struct ObservationMatch {
  std::filesystem::path file;  // empty for what the scenario records
  // What was recorded of the real incident in the base scenario's
  // timeline.recorded, and "" for an observation file: "avalanche" (e.g. the
  // five avalanches of the Madrid Arena, against the run's own events of
  // that kind, its event table) or "max_speed" (a speed read from the
  // footage at a mark, against the max_speed series of the run observed
  // with `observation.spec`, the largest in a window around the mark) or
  // "fatal" (the recorded fatal clog's time, against the time from which the
  // run is clogged for good: analysis::ClogForGood).
  std::string recorded_kind;
  bool UsesRunEvents() const { return recorded_kind == "avalanche"; }
  bool UsesRunClog() const { return recorded_kind == "fatal"; }
  // What the runs' values of this match are computed from, one text for the
  // statistics (Statistic::simulated_from) and the evaluator's cache:
  // kFromRunEvents, kFromRunClog or the observation spec as JSON.
  std::string SimulatedFrom() const {
    return UsesRunEvents() ? kFromRunEvents : UsesRunClog() ? kFromRunClog : observe::SpecToJson(observation.spec);
  }
  static constexpr const char* kFromRunEvents = "run events";
  static constexpr const char* kFromRunClog = "run clog";
  observe::Observation observation;
  // Simulated time = observed time + offset (an experiment's clock against
  // the run's, which starts at 0).
  double time_offset_s = 0.0;
  std::vector<SeriesMatch> series;
  std::vector<EventMatch> events;
};

enum class Approach { kSurrogate, kGradient };
const char* ToString(Approach a);

struct CalibrationOptions {
  // Surrogate: rounds of refinement after the design over the whole box, each
  // in a box `shrink` times the previous one around the optimum found.
  int refinements = 2;
  double shrink = 0.5;
  // Gradient: the central-difference step, as a fraction of each range, and
  // Ceres' iterations per start.
  double gradient_step = 0.1;
  int max_iterations = 8;
  // Replicates of the seed-and-observation bootstrap (0: none).
  int bootstrap = 200;
  // Simulated points along each parameter's whole range through the best
  // fit (0: no profiles).
  int profile_points = 7;
  // Measure the objective's noise along each parameter at small steps first.
  bool measure_noise = false;
  double noise_step = 0.01;  // fraction of the range
  // Steps of each of the posterior's four Metropolis chains (0: no posterior).
  int posterior_steps = 20000;
};

struct CalibrationSpec {
  std::filesystem::path file;
  std::string origin;  // names the file in messages
  std::string name;
  // The sweep that every evaluation is: scenario, "set", seeds (no axes, no
  // variants: each parameter set becomes a variant of a batch).
  sweep::SweepSpec base;
  std::vector<Parameter> parameters;
  std::vector<ObservationMatch> observations;
  Approach approach = Approach::kSurrogate;
  // Starting points, each one value per parameter: the parameters' starts
  // first, then the file's "starts".
  std::vector<std::vector<double>> starts;
  CalibrationOptions options;
  // The length of every run (the base scenario's run.duration_s, after
  // "set"): every simulated window must lie within [0, run_duration_s].
  double run_duration_s = 0.0;
  // What a run depends on besides the parameter values and its seed: the
  // build (runs of different builds are never mixed, as in sweeps), the base
  // scenario, "set" and the parameters' paths. Cached runs are keyed by it
  // and by the values (the seed and the observation spec name the files).
  std::string fingerprint;
};

CalibrationSpec LoadCalibration(const std::filesystem::path& file);
CalibrationSpec ParseCalibration(const std::string& json_text, const std::string& origin,
                                 const std::filesystem::path& base_dir);

}  // namespace crowdrecon::calibrate
