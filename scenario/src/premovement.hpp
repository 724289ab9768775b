// Pre-movement times of a timeline (timeline.hpp: PremovementSpec; RiMEA
// test 5, IMO test 5, NIST TN 1822 Verif.1.1): the people of the start stand
// until their time, then walk. A system of the run loop like the timeline's
// others (timeline_systems.hpp), in its own room.
//
//   premovement   at the first step that starts at or after a person's time,
//                 their desired speed is given back (their own, or their
//                 group's if an event set one), with an event `start`
#pragma once

#include <memory>
#include <vector>

#include "crowdrecon/scenario/run_loop.hpp"
#include "crowdrecon/scenario/world_builder.hpp"
#include "timeline_systems.hpp"

namespace crowdrecon::scenario::detail {

// Each person of the start's time (s), in id order: drawn uniformly from the
// population's seed (a stream of its own: no other draw changes), or as
// given. Throws InputError naming the key when the given times are not one
// per person of the start. Empty without pre-movement.
std::vector<double> PremovementTimes(const Scenario& scenario, std::size_t initial_people);

// At t = 0, before a checkpoint's state (if any) replaces the engine's:
// everyone of the start whose time is after 0 stands (desired speed 0).
void HoldUntilPremovement(engine::Simulation& sim, const std::vector<double>& times);

std::unique_ptr<RunSystem> MakePremovementSystem(TimelineState& state, const BuiltWorld& built,
                                                 std::vector<double> times);

}  // namespace crowdrecon::scenario::detail
