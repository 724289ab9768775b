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

// Bilinear weights of the four nodes around p; nodes for which `valid` is
// false are left out and the others renormalised. Returns false if no node
// of the cell is valid.
template <typename Valid, typename Accumulate>
bool Bilinear(Vec2 p, Vec2 origin, double h, std::size_t nx, std::size_t ny, Valid valid, Accumulate accumulate) {
  const double fx = (p.x - origin.x) / h, fy = (p.y - origin.y) / h;
  if (!(fx >= 0.0 && fy >= 0.0 && fx <= static_cast<double>(nx - 1) && fy <= static_cast<double>(ny - 1))) return false;
  const auto i = std::min(static_cast<std::size_t>(fx), nx - 2);
  const auto j = std::min(static_cast<std::size_t>(fy), ny - 2);
  const double u = fx - static_cast<double>(i), v = fy - static_cast<double>(j);
  const std::size_t k[4] = {j * nx + i, j * nx + i + 1, (j + 1) * nx + i, (j + 1) * nx + i + 1};
  const double w[4] = {(1 - u) * (1 - v), u * (1 - v), (1 - u) * v, u * v};
  double total = 0.0;
  for (int c = 0; c < 4; ++c)
    if (valid(k[c])) total += w[c];
  if (total <= 0.0) {
    // Every node of the cell is outside (a point right at a wall with its
    // cell's nodes beyond it): fall back to the nearest valid node around.
    return false;
  }
  for (int c = 0; c < 4; ++c)
    if (valid(k[c])) accumulate(k[c], w[c] / total);
  return true;
}

}  // namespace

Vec2 NavigationField::FieldDirection(Vec2 p) const {
  Vec2 sum;
  auto valid = [&](std::size_t k) { return std::isfinite(distance_m_[k]); };
  if (!Bilinear(p, origin_m_, spacing_m_, nx_, ny_, valid, [&](std::size_t k, double w) { sum += w * direction_[k]; })) {
    // Nearest reachable node within two cells.
    double best = 2.5 * spacing_m_;
    const double fx = (p.x - origin_m_.x) / spacing_m_, fy = (p.y - origin_m_.y) / spacing_m_;
    for (int dj = -2; dj <= 3; ++dj)
      for (int di = -2; di <= 3; ++di) {
        const double ci = std::floor(fx) + di, cj = std::floor(fy) + dj;
        if (ci < 0 || cj < 0 || ci >= static_cast<double>(nx_) || cj >= static_cast<double>(ny_)) continue;
        const std::size_t k = static_cast<std::size_t>(cj) * nx_ + static_cast<std::size_t>(ci);
        const double d = Length(p - (origin_m_ + spacing_m_ * Vec2{ci, cj}));
        if (valid(k) && d < best) {
          best = d;
          sum = direction_[k];
        }
      }
  }
  return Length(sum) > 1e-12 ? Normalized(sum) : Vec2{};
}

double NavigationField::Distance(Vec2 p) const {
  if (constant_) return 0.0;
  double sum = 0.0;
  auto valid = [&](std::size_t k) { return std::isfinite(distance_m_[k]); };
  if (!Bilinear(p, origin_m_, spacing_m_, nx_, ny_, valid, [&](std::size_t k, double w) { sum += w * distance_m_[k]; }))
    return kUnreachable;
  return sum;
}

}  // namespace crowdrecon::geometry
