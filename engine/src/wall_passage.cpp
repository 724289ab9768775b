// A check, around the step, that nobody's centre went through a wall
// (docs/model.md, "Walls"): a safety net behind the contact check of
// Simulation (a core vertex crossing a wall line), cheap enough to run once
// per output frame.
#include <cstdint>
#include <string>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "simulation_internals.hpp"

namespace crowdrecon::engine {


bool PathCrossesSegment(Vec2 p, Vec2 q, Vec2 a, Vec2 b) {
  const double o1 = Cross(b - a, p - a), o2 = Cross(b - a, q - a);
  const bool path_crosses_line = (o1 > 0.0 && o2 <= 0.0) || (o1 < 0.0 && o2 >= 0.0);
  const double o3 = Cross(q - p, a - p), o4 = Cross(q - p, b - p);
  const bool segment_meets_path = (o3 <= 0.0 && o4 >= 0.0) || (o3 >= 0.0 && o4 <= 0.0);
  return path_crosses_line && segment_meets_path;
}

void CheckCentresStayInsideWalls(const Simulation& sim, const std::vector<Vec2>& centres_before) {
  const BodyState& bodies = sim.bodies();
  const std::vector<Wall>& walls = sim.definition().walls;
  for (std::size_t i = 0; i < bodies.size() && i < centres_before.size(); ++i) {
    if (bodies.state[i] == PersonState::kRemoved) continue;
    const Vec2 from = centres_before[i];
    const Vec2 to = from + sim.Separation(bodies.position_m[i], from);  // the path, across a periodic seam
    for (std::size_t w = 0; w < walls.size(); ++w) {
      if (!sim.WallEnabled(static_cast<std::uint32_t>(w))) continue;  // an open door
      const Wall& wall = walls[w];
      const std::size_t segments = wall.closed ? wall.points.size() : wall.points.size() - 1;
      for (std::size_t k = 0; k < segments; ++k)
        if (PathCrossesSegment(from, to, wall.points[k], wall.points[(k + 1) % wall.points.size()]))
          throw SimulationError("the centre of " + detail::PersonText(bodies, static_cast<std::uint32_t>(i)) + " went through wall " +
                                    std::to_string(w) + " before t = " + FormatNumber(sim.time_s()) +
                                    " s: its path since the last check runs from (" + FormatNumber(from.x) + ", " +
                                    FormatNumber(from.y) + ") to (" + FormatNumber(to.x) + ", " + FormatNumber(to.y) +
                                    ") across the wall line",
                                static_cast<std::int64_t>(i), -1, sim.time_s());
    }
  }
}

}  // namespace crowdrecon::engine
