// Narrow phase: contact points between two spheropolygons.
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
//
// How it is computed. A shape is kept in its own frame (ShapeGeometry, built
// once: vertices, edges with their inverse squared lengths, reflex corners,
// bounding box and circle) and placed by a pose (PlacedShape). For a pair,
// the two bounding boxes, each grown by half the reach r_A + r_B, are tested
// for overlap (separating axes); then each vertex of A is carried into B's
// frame by one rotation and translation, tested against B's grown box, and
// only the survivors are measured against B's edges, in B's frame, through a
// grid of candidate edges per cell (BuildEdgeGrid). The world vertices are
// never formed. Every cull is exact: it drops only vertices that are farther
// than the reach from B's core, and only edges that cannot be the closest.
// Shapes that are scaled copies of one outline (the paper's population)
// share one geometry placed with a scale, so that it stays in cache.
#pragma once

#include <cstdint>
#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::engine {

// One edge of a core: start vertex, edge vector, 1 / |edge|^2.
struct CoreEdge {
  Vec2 start;
  Vec2 direction;
  double inverse_length2 = 0.0;
};

// A core polygon, polyline or point in its own frame, with what the narrow
// phase needs precomputed. count 1 = disk; closed with count >= 3 = polygon
// (counter-clockwise); open = polyline (count - 1 edges; a capsule is an open
// polyline of 2 vertices). Walls (FromWorld) are open or closed polylines
// with no inside: `closed` is false for them, and a closed wall's edges
// include the closing one.
struct ShapeGeometry {
  std::vector<Vec2> vertices;
  std::vector<CoreEdge> edges;
  std::vector<std::uint8_t> reflex;  // per vertex of a closed polygon: 1 if reflex
  bool closed = true;
  double radius_m = 0.0;
  double core_radius_m = 0.0;  // max distance of a vertex from the frame's origin
  Vec2 box_min, box_max;       // bounding box of the core in the shape's frame

  // Optional grid over the box grown by grid_reach_m (BuildEdgeGrid): for each
  // cell, the edges that can be the closest to a point of the cell, in edge
  // order; none where every point of the cell lies outside the core and
  // farther than grid_reach_m from it. Exact: the closest edge is always a
  // candidate, and ties resolve as in the full search.
  double grid_reach_m = 0.0;
  Vec2 grid_origin;
  double grid_cell_m = 0.0;
  std::uint32_t grid_nx = 0, grid_ny = 0;
  std::vector<std::uint32_t> cell_start;  // grid_nx * grid_ny + 1
  std::vector<std::uint16_t> cell_edges;
  // Per cell without candidates: a lower bound on the distance from any point
  // of the cell to the core (> grid_reach_m); 0 for cells with candidates.
  std::vector<double> cell_clearance;

  // Builds the geometry of a core given in its own frame (a body: centroid at
  // the origin). Vertex counts must be 1..32767.
  static ShapeGeometry Make(std::vector<Vec2> vertices, bool closed, double radius_m);
  // A core given in world coordinates (a wall): the frame's origin is put at
  // the centre of its bounding box; `origin` receives that point, which is
  // the position of the shape's pose (angle 0). With `closed` the last point
  // joins the first, but the ring has no inside: a wall is a line on both
  // sides (people may stand inside a room walled all round).
  static ShapeGeometry FromWorld(const std::vector<Vec2>& points, bool closed, double radius_m, Vec2& origin);
  // Builds the grid for contacts whose reach r_A + r_B is at most reach_m
  // (shapes with fewer than 6 edges get none: the full search is as cheap).
  void BuildEdgeGrid(double reach_m);
  std::uint32_t count() const { return static_cast<std::uint32_t>(vertices.size()); }
  std::uint32_t edge_count() const { return static_cast<std::uint32_t>(edges.size()); }
};

// A shape placed in the world: its geometry, uniformly scaled by `scale`
// (vertices and radius), and a pose (the world position of its frame's
// origin, and the rotation of the frame). Scaling lets bodies that are scaled
// copies of one outline share one geometry, which then stays in cache.
struct PlacedShape {
  const ShapeGeometry* geometry = nullptr;
  Vec2 position;
  double cos_angle = 1.0, sin_angle = 0.0;
  double scale = 1.0;
};

struct ContactPoint {
  Vec2 point;            // application point (world): middle of the overlap
  Vec2 normal;           // unit normal (world) from B to A (a repulsive force on A is +normal)
  double overlap_m = 0;  // delta_n = r_A + r_B - distance (> 0 when touching)
  // The vertex that owns the contact: bit 15 clear = vertex of A, set = vertex of B.
  std::uint32_t feature = 0;
};

inline constexpr std::uint32_t kVertexOfB = 1u << 15;

// Taken off every clearance that is kept for later (metres): far more than
// the round-off of the distances and travels it is compared with (bodies
// ~1e2 m from the origin), far less than the motion of a body in one step.
inline constexpr double kClearanceSlack_m = 1e-9;

// A pair's memory of its vertices' clearances between calls (temporal
// coherence). `moved` bounds how far, together, the vertices of A and the
// core of B (and the reverse) can have moved since a reference that only the
// caller knows and that never goes back; a[i] (b[i]) holds for vertex i of A
// (of B) the value of `moved` below which it cannot touch: it is skipped while
// moved < a[i], and measured and updated otherwise. Start with -infinity.
struct VertexClearances {
  double moved = 0.0;
  double* a = nullptr;  // A's vertex count entries
  double* b = nullptr;  // B's vertex count entries
};

// Appends the contacts between A and B to `out` (nothing if they do not touch),
// vertices of A first, each side in vertex order.
//
// Returns the pair's clearance: 0 when it appended contacts; otherwise a lower
// bound c >= 0 (metres) on the distance that separates every counted vertex
// from the reach of the other core, min over vertices of d(vertex, other core)
// - (r_A + r_B). The distance from a point to a set changes by no more than
// the point and the set move, so no contact can appear before the vertices of
// A and the core of B (and the reverse) have moved, together, by c: a caller
// that bounds the motion of every core point since this call may skip the pair
// until that bound reaches c (Simulation's pair clearances). Every bound comes
// from a cull already taken: the bounding circles, the separating axis of the
// grown boxes, per vertex its grown box or its grid cell or its distance.
// With `memory`, vertices still apart since their last measurement are
// skipped (they cannot touch); the result is the same, contacts and order.
double CollideShapes(const PlacedShape& a, const PlacedShape& b, std::vector<ContactPoint>& out,
                     const VertexClearances* memory = nullptr);

}  // namespace crowdrecon::engine
