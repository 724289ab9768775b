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
#include <random>
#include <string>
#include <vector>

#include "crowdrecon/engine/world.hpp"
#include "crowdrecon/geometry/population.hpp"
#include "crowdrecon/geometry/triangulation.hpp"
#include "crowdrecon/scenario/scenario.hpp"

namespace crowdrecon::scenario {

// What a timeline adds to the world (timeline.hpp): the people to come and
// the doors. The world's people are engine slots: the first initial_people
// hold the people placed at the start, the rest are empty (kRemoved) until
// an arrival fills one.
struct BuiltTimeline {
  std::size_t initial_people = 0;
  // Per inflow, each arrival in order (body, mass, desired speed, group,
  // target; the pose is chosen when they enter), and each arrival's run id
  // (person index). Ids run on after the initial people in the order the
  // arrivals are due (ArrivalDueTime; at one time, inflow by inflow), so
  // that a person's id, like their body, does not depend on how long the
  // run is: a longer run only adds people with higher ids. Their shapes
  // follow the world's in the same order (shape = first + id - initial).
  std::vector<std::vector<engine::PersonDef>> arrivals;
  std::vector<std::vector<std::uint32_t>> arrival_id;
  std::vector<std::uint32_t> exit_wall;  // per venue exit: the engine wall of its door
};

struct BuiltWorld {
  engine::WorldDef world;
  BuiltTimeline timeline;  // empty without a timeline
  std::vector<std::string> target_names;  // by engine target index
  std::string walkable_wkt;               // for the run file
  double placement_area_m2 = 0.0;
  double max_initial_overlap_m = 0.0;     // after relaxation
  std::size_t relaxation_steps = 0;
};

// Placement, in three named steps that BuildWorld runs in turn (and that the
// incident timeline's arrivals reuse).
struct Placement {
  std::vector<Vec2> position;  // per person of the WorldDef, centres
  std::vector<double> angle;   // orientations (rad)
};
// 1. Random sequential placement of every person of `def` (its shapes at
//    `scale` of full size, `max_bound` the largest body reach at full size)
//    at uniformly random points of `regions` (total area_m2), facing their
//    target's direction, without touching a wall or anyone placed before
//    (the engine's narrow phase; periodic images near a seam). Draws from
//    `rng`. Throws InputError (naming `origin`, /population) when a person
//    finds no free place: a wall in every place tried, or a density too high.
Placement PlaceSequentially(const engine::WorldDef& def, const std::vector<geometry::AreaTriangulation>& regions,
                            double area_m2, double scale, double max_bound, Vec2 lo, Vec2 hi, std::mt19937_64& rng,
                            const std::string& origin);
// 2. Numbers people along a Hilbert curve through their places (the box
//    [lo, hi]): def.people, def.shapes (one per person) and the placement
//    are reordered together.
void NumberAlongCurve(engine::WorldDef& def, Placement& placement, Vec2 lo, Vec2 hi);
// 3. Grows the bodies from `initial_scale` to full size in stages, each
//    followed by a passive, quenched relaxation, until the largest overlap is
//    at most `tolerance` (or stops falling). Returns the largest overlap left
//    and the relaxation steps taken; `say` receives a line per stage.
struct Relaxation {
  double residual = 0.0;
  std::size_t steps = 0;
};
Relaxation GrowAndRelax(const engine::WorldDef& def, Placement& placement, double initial_scale, double tolerance,
                        const std::string& origin, const std::function<void(const std::string&)>& say);

// `progress` (optional) receives short status lines.
BuiltWorld BuildWorld(const Scenario& scenario, int threads,
                      const std::function<void(const std::string&)>& progress = {});

// Walls of a venue for the engine: wall segments (exits cut out) chained into
// polylines where consecutive segments share an endpoint.
std::vector<engine::Wall> VenueWalls(const geometry::Venue& venue);

// WKT of the walkable area (POLYGON or MULTIPOLYGON with obstacle holes).
std::string WalkableAreaWkt(const geometry::Venue& venue);

}  // namespace crowdrecon::scenario
