// Whether a point lies inside a polygon, for every library that needs it
// (venues' zones and measurement areas; the engine's slope region).
#pragma once

#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon {

// Crossing number with the half-open rule (an edge counts when one endpoint
// is strictly above p and the other not), so vertices are not counted twice.
inline bool PointInPolygon(const std::vector<Vec2>& ring, Vec2 p) {
  bool inside = false;
  const std::size_t n = ring.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2 a = ring[i], b = ring[j];
    if ((a.y > p.y) != (b.y > p.y)) {
      const double x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
      if (p.x < x) inside = !inside;
    }
  }
  return inside;
}

}  // namespace crowdrecon
