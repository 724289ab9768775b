// The incident timeline's systems of the run loop (run_loop.hpp; the spec in
// timeline.hpp), in the order RunScenario adds them, before the built-in ones:
//
//   timeline_events  the timed events, at the first step that starts at or after their time
//   inflow           arrivals due by the schedule: placed in their entry zone where
//                    there is room, otherwise queued there (FIFO) and placed later
//   exits            a walking person whose centre crosses an open exit is removed
//   falls            the fall criterion (filtered acceleration, or a sustained load)
//   avalanches       (per frame) the analysis's avalanche detector on each direction's
//                    mean speed, events as avalanches are first seen
//   left             (per frame) ends an evacuation once stop_when_left_fraction has left
//
// They share a TimelineState (queues, exits open, inflows on, counts, the
// events of the frame), saved in checkpoints by timeline_events; the falls
// system saves its filters. The frames system (run_systems.hpp) writes each
// frame with the events that happened since the last one and the head count
// (run file table census), checking that entered = walking + fallen +
// removed: one transaction per frame.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "crowdrecon/geometry/triangulation.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/scenario/run_loop.hpp"
#include "crowdrecon/scenario/scenario.hpp"
#include "crowdrecon/scenario/world_builder.hpp"

namespace crowdrecon::scenario::detail {

struct TimelineState {
  TimelineState(const Scenario& scenario, const BuiltWorld& built);

  const Scenario& scenario;
  const TimelineSpec& spec;
  const BuiltTimeline& built;
  std::vector<std::string> target_names;  // engine targets by index

  // Checkpointed (SaveState / LoadState).
  std::size_t next_event = 0;
  std::vector<std::uint8_t> inflow_on;
  std::vector<double> inflow_before;  // the rate's integral over closed on-intervals
  std::vector<double> inflow_since;   // start of the current on-interval (s)
  std::vector<std::uint64_t> placed;  // arrivals placed, per inflow
  std::vector<double> next_try_s;     // per inflow: when to try the queue's head again
  std::vector<std::mt19937_64> rng;   // per inflow: placement draws
  std::vector<std::uint8_t> exit_open;     // per venue exit
  std::vector<std::uint64_t> exit_count;   // removed through each exit
  std::vector<std::int64_t> group_target;  // per group: target of later arrivals (-1: their inflow's)
  std::vector<double> group_speed;         // per group: desired speed of later arrivals (NaN: their own)
  std::vector<double> group_gamma, group_lambda;  // per group: own Gamma, lambda (NaN: the model's)
  std::uint64_t removed = 0, fallen = 0;

  // Not checkpointed: emptied into each frame (a checkpoint follows a frame).
  std::vector<runfile::Event> events;
  // Entry zones (triangulated once), per inflow.
  std::vector<geometry::AreaTriangulation> entry_area;

  // Arrivals due by time t (floor of the integral while on).
  std::uint64_t Due(std::size_t inflow, double t_s) const;
  std::uint64_t Queued(double t_s) const;
  std::uint64_t Entered() const;
  // The head count now; throws std::logic_error (an internal error) if
  // entered != walking + fallen + removed.
  runfile::Census Count(const engine::Simulation& sim) const;
  void Event(double time_s, const std::string& kind, std::int64_t person, const std::string& detail);
  // The person in `slot` falls now (by the fall criterion or a recorded
  // fall): lies as an obstacle, counted, with a `fall` event saying why.
  void Fall(engine::Simulation& sim, std::uint32_t slot, const std::string& cause);
  std::string SaveState() const;
  void LoadState(const std::string& state);
};

// Who holds each engine slot, for the systems that follow a person's path
// from one check to the next: an empty slot (never used, or its person
// removed) holds no one (kNoOne), so that whoever is spawned into it is a
// newcomer. (An empty slot's placeholder carries the slot's index as its
// id, which may be the id of the arrival spawned into it: compared by id
// alone, that arrival walked from the placeholder's parking place, the
// walkable area's lower corner, to its entry; the Itaewon evening's wall
// check stopped both seeds at 22:20 on such a path.)
constexpr std::uint32_t kNoOne = UINT32_MAX;
void SlotHolders(const engine::BodyState& bodies, std::vector<std::uint32_t>* holders);  // reuses its storage

// The model parameters of everyone as a global "set" event leaves them: its
// values by the parameter table, the wall's restitution following the
// restitution unless the event gives it (as when a scenario is read). Group
// values and desired speeds are not the model's and are left out. The
// scenario's check of its events (scenario.cpp) and their application
// (the timeline's event system) both use it.
void ApplyEventToModel(const TimelineEvent& e, engine::ModelParameters* p);

std::unique_ptr<RunSystem> MakeTimelineEventSystem(TimelineState& state);
std::unique_ptr<RunSystem> MakeInflowSystem(TimelineState& state);
std::unique_ptr<RunSystem> MakeExitSystem(TimelineState& state);
std::unique_ptr<RunSystem> MakeFallSystem(TimelineState& state);
std::unique_ptr<RunSystem> MakeAvalancheSystem(TimelineState& state);
std::unique_ptr<RunSystem> MakeLeftSystem(TimelineState& state);

// Opens and closes the doors as the timeline starts (before the first step).
void OpenDoorsAtStart(engine::Simulation& sim, const TimelineState& state);

}  // namespace crowdrecon::scenario::detail
