// CGAL-backed polygon operations used to turn an outline into the core polygon
// of a body. Internal to the geometry module: the CGAL types stay in
// outline_cgal.cpp (the only translation unit of the body pipeline that
// includes CGAL), and this header speaks in plain rings of Vec2.
#pragma once

#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::geometry::detail {

// True if the closed ring (no repeated closing point) is a simple polygon.
bool IsSimpleRing(const std::vector<Vec2>& ring);

// Polyline simplification of a closed simple ring (CGAL::Polyline_simplification_2,
// which never introduces self-intersections). Both variants use the
// Squared_distance_cost: the cost of removing a vertex is the largest distance
// from the original (dense) vertices to the new edge, i.e. a Hausdorff-like error
// measured against the input ring, not against the previous simplification.
//
// Removes vertices while each removal costs at most `tolerance` (in the ring's units).
std::vector<Vec2> SimplifyRingToTolerance(const std::vector<Vec2>& ring, double tolerance);
// Removes the cheapest vertices until `count` remain (or none can be removed
// without making the ring non-simple).
std::vector<Vec2> SimplifyRingToCount(const std::vector<Vec2>& ring, std::size_t count);

// Inward offset of a simple counter-clockwise ring by `distance` (> 0) with
// CGAL's straight skeleton. The offset may split into several pieces (narrow
// necks) or vanish; pieces are returned counter-clockwise, largest area first.
std::vector<std::vector<Vec2>> InwardOffsetPieces(const std::vector<Vec2>& ring, double distance);

}  // namespace crowdrecon::geometry::detail
