// Narrow phase: contact points between two spheropolygons in world frame.
//
// Overlaps come from vertex-to-edge distances in both directions (paper,
// eqs. 8-9; Alonso-Marroquin 2008): every vertex of A interacts with the
// closest point of B's core polygon, and every vertex of B with the closest
// point of A's, when that distance is below r_A + r_B. The overlap of a vertex
// is delta = r_A + r_B - d(vertex, other polygon), and the elastic energy
// k_n delta^2 / 2 summed over vertices is a continuous function of the
// configuration (the distance to a polygon is continuous), so the contact
// forces are conservative: no energy is created when a vertex slides past a
// corner or from one edge to the next. Each contact belongs to one vertex,
// which also keys its tangential spring (eq. 9) for as long as it persists.
//
// A disk's core is a single point, so its distance to the other core already
// is the exact overlap of the two swept shapes: against a disk only the
// disk's own vertex is counted (a disk-disk contact is one spring k_n).
// Elsewhere, a corner touching a corner is counted from both sides (two
// springs), a flat face touching a face at up to four points (docs/model.md).
#pragma once

#include <cstdint>
#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::engine {

// A shape placed in the world: vertices in world coordinates. count 1 = disk;
// closed with count >= 3 = polygon (counter-clockwise); open = polyline
// (count - 1 edges; a capsule is an open polyline of 2 vertices; walls are
// open or closed polylines).
struct PlacedShape {
  const Vec2* vertices = nullptr;
  std::uint32_t count = 0;
  bool closed = true;
  double radius_m = 0.0;
  Vec2 centre;                 // centroid (for the cheap per-vertex cull)
  double core_radius_m = 0.0;  // max distance of a vertex from `centre`
  // Bounding box of the core in the shape's own frame (rotation `angle` about
  // `centre`): a vertex farther than r_a + r_b outside it cannot touch, which
  // culls most vertex tests of elongated bodies exactly.
  // Default: unbounded (no cull).
  Vec2 box_min{-1e300, -1e300}, box_max{1e300, 1e300};  // relative to centre, rotated frame
  double cos_angle = 1.0, sin_angle = 0.0;
};

struct ContactPoint {
  Vec2 point;            // application point: middle of the overlap
  Vec2 normal;           // unit normal from B to A (a repulsive force on A is +normal)
  double overlap_m = 0;  // delta_n = r_A + r_B - distance (> 0 when touching)
  // The vertex that owns the contact: bit 15 clear = vertex of A, set = vertex of B.
  std::uint32_t feature = 0;
};

inline constexpr std::uint32_t kVertexOfB = 1u << 15;

// Appends the contacts between A and B to `out` (nothing if they do not touch),
// vertices of A first, each side in vertex order. Vertex counts must be below 32768.
void CollideShapes(const PlacedShape& a, const PlacedShape& b, std::vector<ContactPoint>& out);

}  // namespace crowdrecon::engine
