// Runs that stop once their regime is settled (issue 19): a phase-diagram run
// ends when it has provably reached an absorbing state, instead of at a fixed
// length that cuts some runs just before they freeze:
//
//   frozen   the regime classifier (analysis/regime.hpp, version 2, default
//            options) says clogging with *every* direction frozen, and for the
//            last frozen_window_s nobody moved more than frozen_displacement_m
//            from where they were at any sample of the window, and the force
//            network is static: sum_i |L_i(now) - L_i(then)| / sum_i L_i(now)
//            below frozen_load_change for every sample of the window (L_i the
//            sum of the magnitudes of person i's contact forces);
//   lanes    the classifier says lanes, and for the last lanes_window_s no
//            direction's mean speed along its desired direction fell below
//            the classifier's stop speed at any frame.
//
// Otherwise (avalanches, one direction stalled while the other walks,
// intermittent flow) the run goes on to its duration, the stated maximum.
// The classifier sees the same series at the stop as the analysis of the
// shortened run does, so the verdict of the stopped run is the one that made
// it stop; that a longer run would not change it is what the criteria claim,
// checked against full-length runs (docs/analysis.md, "Runs that stop when
// settled"). Scenario key: run.stop_when_settled (docs/scenarios.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "crowdrecon/common/periodic_box.hpp"
#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon {
class JsonReader;
}  // namespace crowdrecon

namespace crowdrecon::scenario {

struct SettleOptions {
  bool enabled = false;
  // How long a clog must have been frozen (s): twice the classifier's final
  // window, so that the verdict "clogging" has held through a whole window
  // before the one that judges it.
  double frozen_window_s = 20.0;
  // Largest movement of anyone over that window (m): a sixth of a body depth
  // (0.3 m), far below what a release moves (avalanche_move_m = 0.3 m).
  double frozen_displacement_m = 0.05;
  // Largest relative change of the loads over the window: 10 % (the
  // springs of a static network only relax by the damping).
  double frozen_load_change = 0.10;
  // How long lanes must have flowed without any direction stopping (s): five
  // times the classifier's final window; the time to walk the 12 m hallway
  // about five times at ~1 m/s.
  double lanes_window_s = 60.0;
  // How often the criteria are evaluated and positions and loads sampled (s).
  double sample_interval_s = 1.0;

  bool IsValid(std::string* error) const;
};

// A scenario's run.stop_when_settled: an object whose keys (all optional)
// are the fields above; enabled. Errors name the file, the JSON path and the
// allowed range.
SettleOptions ReadSettleOptions(const JsonReader& object);
// The settle options of a run's scenario (its JSON text, as a run file
// keeps it): its run.stop_when_settled, or the defaults if it has none;
// enabled either way (analyze --settle-check).
SettleOptions SettleOptionsOfScenario(const std::string& scenario_json, const std::string& origin);

// The criteria on a stream of frames, without the engine (tests feed it
// hand-made frames; SettleSystem feeds it the simulation's).
class SettleDetector {
 public:
  // `group` per person; `group_names` per group (direction of travel).
  SettleDetector(const SettleOptions& options, std::vector<std::uint32_t> group,
                 std::vector<std::string> group_names, PeriodicBox box);

  struct Frame {
    double time_s = 0.0;
    const std::vector<Vec2>* position_m = nullptr;
    const std::vector<Vec2>* velocity_m_per_s = nullptr;
    const std::vector<Vec2>* desired_direction = nullptr;  // unit, per person
    const std::vector<double>* load_n = nullptr;
    const std::vector<char>* present = nullptr;  // 0 for people removed from the run
  };
  // Adds a frame; returns why the run has settled ("" while it has not).
  std::string Add(const Frame& frame);

  // State for checkpoints, and back (a resumed run decides exactly as an
  // uninterrupted one). LoadState throws InputError on damaged data.
  std::string SaveState() const;
  void LoadState(const std::string& state);

 private:
  std::string Evaluate() const;
  SettleOptions options_;
  std::vector<std::uint32_t> group_;
  std::vector<std::string> group_names_;
  PeriodicBox box_;
  // The series the classifier reads: per frame, time, the crowd's mean speed
  // and each group's (NaN where a group has nobody present).
  std::vector<double> time_s_, crowd_speed_;
  std::vector<std::vector<double>> group_speed_;
  std::vector<std::size_t> group_people_;
  // Samples every sample_interval_s over the frozen window: positions, loads.
  struct Sample {
    double time_s = 0.0;
    std::vector<Vec2> position_m;
    std::vector<double> load_n;
  };
  std::vector<Sample> samples_;
  double next_sample_s_ = -1.0;
};

}  // namespace crowdrecon::scenario
