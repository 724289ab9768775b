// Navigation fields as the engine uses them: made from a direction or from
// the arrays of a grid, and sampled (bilinear interpolation of the desired
// direction and of the distance). Nothing here needs a venue, CGAL or OpenCV,
// so this file is a library of its own (crowdrecon_navigation_field) that the
// engine links without the rest of the geometry module; building a field from
// a venue is in navigation.cpp.
#include "crowdrecon/geometry/navigation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::geometry {

// ---------------------------------------------------------------------------
// Making a field
// ---------------------------------------------------------------------------

NavigationField NavigationField::Constant(Vec2 direction) {
  NavigationField f;
  f.constant_ = true;
  f.constant_direction_ = Length(direction) > 0.0 ? Normalized(direction) : Vec2{};
  return f;
}

NavigationField NavigationField::ConstantExact(Vec2 unit_direction) {
  // A unit vector from Normalized is within a few rounding errors of length
  // 1; the tolerance only refuses what is plainly not a direction.
  const double length = Length(unit_direction);
  if (!(std::isfinite(length) && (length == 0.0 || std::abs(length - 1.0) <= 1e-9)))
    throw InputError("navigation field: constant direction (" + FormatNumber(unit_direction.x) + ", " +
                     FormatNumber(unit_direction.y) + ") has length " + FormatNumber(length) +
                     "; expected a unit vector or (0, 0)");
  NavigationField f;
  f.constant_ = true;
  f.constant_direction_ = unit_direction;
  return f;
}

NavigationField NavigationField::FromGrid(Vec2 origin_m, double spacing_m, std::size_t nx, std::size_t ny,
                                          std::vector<double> distance_m, std::vector<Vec2> direction) {
  const std::string what = "navigation field: ";
  if (!(std::isfinite(origin_m.x) && std::isfinite(origin_m.y)))
    throw InputError(what + "grid origin (" + FormatNumber(origin_m.x) + ", " + FormatNumber(origin_m.y) +
                     ") is not finite; expected a point in metres");
  if (!(std::isfinite(spacing_m) && spacing_m > 0.0))
    throw InputError(what + "grid spacing " + FormatNumber(spacing_m) + " m; expected a finite spacing > 0");
  // Sampling interpolates within a cell, so it needs at least one: two nodes
  // along each axis.
  if (nx < 2 || ny < 2)
    throw InputError(what + "grid of " + std::to_string(nx) + " x " + std::to_string(ny) +
                     " nodes; expected at least 2 x 2");
  if (nx > std::numeric_limits<std::size_t>::max() / ny)
    throw InputError(what + "grid of " + std::to_string(nx) + " x " + std::to_string(ny) + " nodes is too large");
  const std::size_t n = nx * ny;
  if (distance_m.size() != n || direction.size() != n)
    throw InputError(what + "grid of " + std::to_string(nx) + " x " + std::to_string(ny) + " nodes has " +
                     std::to_string(distance_m.size()) + " distances and " + std::to_string(direction.size()) +
                     " directions; expected " + std::to_string(n) + " of each");
  for (std::size_t k = 0; k < n; ++k) {
    // +infinity marks an unreachable node (kUnreachable); NaN or a negative
    // distance would silently turn a node invalid or reverse the gradient.
    if (std::isnan(distance_m[k]) || distance_m[k] < 0.0)
      throw InputError(what + "distance at node " + std::to_string(k) + " is " + FormatNumber(distance_m[k]) +
                       "; expected a distance >= 0 m or +infinity (unreachable)");
    if (!(std::isfinite(direction[k].x) && std::isfinite(direction[k].y)))
      throw InputError(what + "direction at node " + std::to_string(k) + " is not finite; expected a unit vector or (0, 0)");
  }
  NavigationField f;
  f.constant_ = false;
  f.origin_m_ = origin_m;
  f.spacing_m_ = spacing_m;
  f.nx_ = nx;
  f.ny_ = ny;
  f.distance_m_ = std::move(distance_m);
  f.direction_ = std::move(direction);
  return f;
}

// ---------------------------------------------------------------------------
// Sampling
// ---------------------------------------------------------------------------

namespace {

// The grid cell around p, node (i, j) at its lower left, and p's place in it
// (u, v in [0, 1]).
struct CellPlace {
  std::size_t i, j;
  double u, v;
};

// False if p is outside the grid.
bool Locate(Vec2 p, Vec2 origin, double h, std::size_t nx, std::size_t ny, CellPlace* place) {
  const double fx = (p.x - origin.x) / h, fy = (p.y - origin.y) / h;
  if (!(fx >= 0.0 && fy >= 0.0 && fx <= static_cast<double>(nx - 1) && fy <= static_cast<double>(ny - 1))) return false;
  place->i = std::min(static_cast<std::size_t>(fx), nx - 2);
  place->j = std::min(static_cast<std::size_t>(fy), ny - 2);
  place->u = fx - static_cast<double>(place->i);
  place->v = fy - static_cast<double>(place->j);
  return true;
}

// The cell's four nodes: (i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1).
void CellNodes(const CellPlace& place, std::size_t nx, std::size_t k[4]) {
  const std::size_t i = place.i, j = place.j;
  k[0] = j * nx + i;
  k[1] = j * nx + i + 1;
  k[2] = (j + 1) * nx + i;
  k[3] = (j + 1) * nx + i + 1;
}

// Bilinear weights of the four nodes; nodes whose bit in `valid` is clear are
// left out (weight 0) and the others renormalised. Returns false if no node
// of the cell is valid (a point right at a wall with its cell's nodes beyond
// it: the caller falls back to the nearest valid node around).
bool Weights(const CellPlace& place, unsigned valid, double weight[4]) {
  const double u = place.u, v = place.v;
  const double w[4] = {(1 - u) * (1 - v), u * (1 - v), (1 - u) * v, u * v};
  double total = 0.0;
  for (int c = 0; c < 4; ++c)
    if (valid >> c & 1u) total += w[c];
  if (total <= 0.0) return false;
  for (int c = 0; c < 4; ++c) weight[c] = valid >> c & 1u ? w[c] / total : 0.0;
  return true;
}

Vec2 UnitOrZero(Vec2 sum) { return Length(sum) > 1e-12 ? Normalized(sum) : Vec2{}; }

}  // namespace

// Direction and CachedDirection must give the same bits: they share every
// operation above and sum the nodes in the same order.
Vec2 NavigationField::FieldDirection(Vec2 p) const {
  CellPlace place;
  if (!Locate(p, origin_m_, spacing_m_, nx_, ny_, &place)) return UnitOrZero(NearestNodeDirection(p));
  std::size_t k[4];
  CellNodes(place, nx_, k);
  unsigned valid = 0;
  for (int c = 0; c < 4; ++c)
    if (std::isfinite(distance_m_[k[c]])) valid |= 1u << c;
  double weight[4];
  if (!Weights(place, valid, weight)) return UnitOrZero(NearestNodeDirection(p));
  Vec2 sum;
  for (int c = 0; c < 4; ++c)
    if (valid >> c & 1u) sum += weight[c] * direction_[k[c]];
  return UnitOrZero(sum);
}

Vec2 NavigationField::CachedDirection(Vec2 p, CellCache& cache) const {
  CellPlace place;
  if (!Locate(p, origin_m_, spacing_m_, nx_, ny_, &place)) return UnitOrZero(NearestNodeDirection(p));
  const std::size_t cell = place.j * nx_ + place.i;
  if (cache.field != this || cache.cell != cell) {
    std::size_t k[4];
    CellNodes(place, nx_, k);
    cache.field = this;
    cache.cell = cell;
    cache.valid = 0;
    for (int c = 0; c < 4; ++c) {
      if (std::isfinite(distance_m_[k[c]])) cache.valid |= 1u << c;
      cache.direction[c] = direction_[k[c]];
    }
  }
  double weight[4];
  if (!Weights(place, cache.valid, weight)) return UnitOrZero(NearestNodeDirection(p));
  Vec2 sum;
  for (int c = 0; c < 4; ++c)
    if (cache.valid >> c & 1u) sum += weight[c] * cache.direction[c];
  return UnitOrZero(sum);
}

// The direction of the nearest reachable node within two cells of p (not
// normalised), or (0, 0) if there is none.
Vec2 NavigationField::NearestNodeDirection(Vec2 p) const {
  Vec2 sum;
  double best = 2.5 * spacing_m_;
  const double fx = (p.x - origin_m_.x) / spacing_m_, fy = (p.y - origin_m_.y) / spacing_m_;
  for (int dj = -2; dj <= 3; ++dj)
    for (int di = -2; di <= 3; ++di) {
      const double ci = std::floor(fx) + di, cj = std::floor(fy) + dj;
      if (ci < 0 || cj < 0 || ci >= static_cast<double>(nx_) || cj >= static_cast<double>(ny_)) continue;
      const std::size_t k = static_cast<std::size_t>(cj) * nx_ + static_cast<std::size_t>(ci);
      const double d = Length(p - (origin_m_ + spacing_m_ * Vec2{ci, cj}));
      if (std::isfinite(distance_m_[k]) && d < best) {
        best = d;
        sum = direction_[k];
      }
    }
  return sum;
}

double NavigationField::Distance(Vec2 p) const {
  if (constant_) return 0.0;
  CellPlace place;
  if (!Locate(p, origin_m_, spacing_m_, nx_, ny_, &place)) return kUnreachable;
  std::size_t k[4];
  CellNodes(place, nx_, k);
  unsigned valid = 0;
  for (int c = 0; c < 4; ++c)
    if (std::isfinite(distance_m_[k[c]])) valid |= 1u << c;
  double weight[4];
  if (!Weights(place, valid, weight)) return kUnreachable;
  double sum = 0.0;
  for (int c = 0; c < 4; ++c)
    if (valid >> c & 1u) sum += weight[c] * distance_m_[k[c]];
  return sum;
}

}  // namespace crowdrecon::geometry
