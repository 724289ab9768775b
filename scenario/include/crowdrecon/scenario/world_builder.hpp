// Building the engine's world from a scenario: the population (bodies with
// consistent mass and inertia), their targets and desired speeds, and their
// placement in the venue without initial overlaps.
//
// Placement: people are first placed at a reduced size s0 (so that random
// sequential placement succeeds), at uniformly random points of the placement
// region, facing their desired direction; they are then grown to full size in
// stages, each followed by a passive relaxation (no ground reaction forces,
// velocities quenched) until the largest overlap is below the tolerance. A
// density that cannot be relaxed below the tolerance is refused with the
// residual overlap stated. People are then numbered along a Hilbert curve
// through their places (neighbours in the crowd get close numbers, so their
// data lie close in the engine's arrays), each with its own body shape at the
// same index. Everything is deterministic given the seed.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "crowdrecon/engine/world.hpp"
#include "crowdrecon/geometry/population.hpp"
#include "crowdrecon/scenario/scenario.hpp"

namespace crowdrecon::scenario {

struct BuiltWorld {
  engine::WorldDef world;
  std::vector<std::string> target_names;  // by engine target index
  std::string walkable_wkt;               // for the run file
  double placement_area_m2 = 0.0;
  double max_initial_overlap_m = 0.0;     // after relaxation
  std::size_t relaxation_steps = 0;
};

// `progress` (optional) receives short status lines.
BuiltWorld BuildWorld(const Scenario& scenario, int threads,
                      const std::function<void(const std::string&)>& progress = {});

// Walls of a venue for the engine: wall segments (exits cut out) chained into
// polylines where consecutive segments share an endpoint.
std::vector<engine::Wall> VenueWalls(const geometry::Venue& venue);

// WKT of the walkable area (POLYGON or MULTIPOLYGON with obstacle holes).
std::string WalkableAreaWkt(const geometry::Venue& venue);

}  // namespace crowdrecon::scenario
