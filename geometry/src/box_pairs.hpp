// Axis-aligned boxes and the pairs of them that overlap, found by a sweep
// along x rather than by testing every pair: the checks that look for rings
// or edges that meet (venue validation, self-intersections of outlines) stay
// near-linear for plans of 10000 pillars or outlines of 1e6 points.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::geometry::detail {

struct Box {
  Vec2 lo, hi;
  bool Overlaps(const Box& o) const { return lo.x <= o.hi.x && o.lo.x <= hi.x && lo.y <= o.hi.y && o.lo.y <= hi.y; }
};

// Bounds of a non-empty point list.
Box BoundsOf(const std::vector<Vec2>& points);
// Bounds of every edge of a closed ring (edge i from point i to i + 1).
std::vector<Box> EdgeBoxes(const std::vector<Vec2>& ring);

// The pairs (i < j) of boxes that overlap, sorted. Coordinates must be
// finite.
std::vector<std::pair<std::size_t, std::size_t>> OverlappingPairs(const std::vector<Box>& boxes);

}  // namespace crowdrecon::geometry::detail
