// Navigation field: the desired walking direction of every target at every
// point of a venue.
//
// For an exit, the field is built from the geodesic distance T(x) to the exit
// over the walkable area (shortest walking distance around obstacles), which
// solves the eikonal equation |grad T| = 1 with T = 0 on the exit. T is computed
// once, on a regular grid, by the fast marching method (Sethian 1996; first-
// order upwind scheme), and the desired direction is e(x) = -grad T / |grad T|,
// interpolated bilinearly between grid nodes. People therefore walk around
// obstacles toward the exit rather than into them.
//
// For a fixed-direction target (periodic corridors) the field is constant.
//
// The grid is exposed as plain arrays so that the engine can sample it without
// this module: evaluating a field (navigation_field.cpp, the library
// crowdrecon_navigation_field) needs neither a venue nor CGAL, and FromGrid
// rebuilds a field from its arrays (engine world files).
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::geometry {

struct NavigationOptions {
  // Grid spacing of the fast marching grid (m). The error of T is of the order
  // of the spacing near the exit and obstacle corners and falls off relative to
  // the distance; 0.1 m is a fraction of a body width.
  double grid_spacing_m = 0.1;

  // Throws InputError naming the option if a value is out of range.
  // false (and *error: what is wrong, what was expected) if a value is out of range.
  bool IsValid(std::string* error) const;
};

class NavigationField {
 public:
  // Geodesic field toward the exit `exit_id` (GeometryError if there is none).
  static NavigationField ToExit(const Venue& venue, std::string_view exit_id,
                                const NavigationOptions& options = {});
  // Geodesic field toward the nearest of several exits (T = 0 on each: the
  // walking distance to the closest one).
  static NavigationField ToExits(const Venue& venue, const std::vector<std::string>& exit_ids,
                                 const NavigationOptions& options = {});
  // Constant field.
  static NavigationField Constant(Vec2 direction);
  // Constant field whose direction is kept exactly as given, not normalised
  // again: normalising a unit vector can move it by a rounding error, and a
  // field read back from a world file must be the same bit for bit.
  // `unit_direction` must be a unit vector (to rounding) or (0, 0); throws
  // InputError otherwise.
  static NavigationField ConstantExact(Vec2 unit_direction);
  // A grid field from its arrays (see the accessors below): node (i, j) at
  // origin + (i, j) * spacing, index j * nx + i. Throws InputError unless
  // spacing > 0, nx and ny >= 2 (a cell to interpolate in), both arrays hold
  // nx * ny entries, distances are +infinity (unreachable) or finite and
  // >= 0, and directions are finite.
  static NavigationField FromGrid(Vec2 origin_m, double spacing_m, std::size_t nx, std::size_t ny,
                                  std::vector<double> distance_m, std::vector<Vec2> direction);
  // The field of a target (see Venue::FindTarget): ToExit or Constant.
  static NavigationField ForTarget(const Venue& venue, std::string_view target_id,
                                   const NavigationOptions& options = {});

  bool is_constant() const { return constant_; }
  // The direction of a constant field ((0, 0) for a grid field).
  Vec2 constant_direction() const { return constant_direction_; }

  // Desired direction at p: a unit vector, or (0, 0) where the target cannot be
  // reached (a disconnected part of the venue) or p is far outside the area.
  // (Inline for the constant field: the engine asks once per person and step.)
  Vec2 Direction(Vec2 p) const { return constant_ ? constant_direction_ : FieldDirection(p); }

  // The nodes of the grid cell a caller last sampled, as Direction reads them.
  // A walking person stays in one cell (0.1 m) for a hundred steps or more,
  // while the grid of a large venue is megabytes (the 55 m x 35 m ground
  // floor: 4.6 MB), so reading it afresh for every person at every step
  // missed the caches on most reads. The engine keeps one per person.
  struct CellCache {
    const NavigationField* field = nullptr;  // whose cell this is (none yet)
    std::size_t cell = 0;                    // j * nx + i of its lower-left node
    Vec2 direction[4];                       // of nodes (i, j), (i+1, j), (i, j+1), (i+1, j+1)
    unsigned valid = 0;                      // bit c: node c reachable (finite distance)
  };
  // Direction(p), bit for bit, reading the grid only when p's cell is not the
  // one in `cache` (which it then holds).
  Vec2 Direction(Vec2 p, CellCache& cache) const { return constant_ ? constant_direction_ : CachedDirection(p, cache); }
  // Geodesic distance to the exit at p (m), bilinearly interpolated;
  // +infinity where unreachable. For a constant field: 0.
  double Distance(Vec2 p) const;

  // --- the grid (empty for a constant field) ---------------------------------
  // Node (i, j) is at origin + (i, j) * spacing, index j * nx + i.
  Vec2 origin_m() const { return origin_m_; }
  double spacing_m() const { return spacing_m_; }
  std::size_t nx() const { return nx_; }
  std::size_t ny() const { return ny_; }
  // T at each node (m); +infinity at nodes outside the area or unreachable.
  const std::vector<double>& distance_m() const { return distance_m_; }
  // -grad T at each node, normalised; (0, 0) outside or unreachable.
  const std::vector<Vec2>& direction() const { return direction_; }

 private:
  Vec2 FieldDirection(Vec2 p) const;
  Vec2 CachedDirection(Vec2 p, CellCache& cache) const;
  Vec2 NearestNodeDirection(Vec2 p) const;

  bool constant_ = true;
  Vec2 constant_direction_;
  Vec2 origin_m_;
  double spacing_m_ = 0.0;
  std::size_t nx_ = 0, ny_ = 0;
  std::vector<double> distance_m_;
  std::vector<Vec2> direction_;
};

// A regular grid for fast marching: node (i, j) at origin + (i, j) * spacing,
// index k = j * nx + i.
struct MarchingGrid {
  std::size_t nx = 0, ny = 0;
  double spacing_m = 0.1;
  std::vector<char> inside;         // per node: in the domain
  // Per node, optional (empty: nothing blocked): the link to the node east
  // (k + 1) or north (k + nx) is cut by a wall, so the front may not pass.
  std::vector<char> blocked_east;
  std::vector<char> blocked_north;
};

// Fast marching (first-order upwind): solves |grad T| = 1 on the grid's inside
// nodes with T fixed at source nodes (`source_distance_m[k]` finite there,
// +infinity elsewhere). Returns T at every node, +infinity outside the domain
// or where the sources cannot be reached.
std::vector<double> FastMarch(const MarchingGrid& grid, const std::vector<double>& source_distance_m);

inline constexpr double kUnreachable = std::numeric_limits<double>::infinity();

}  // namespace crowdrecon::geometry
