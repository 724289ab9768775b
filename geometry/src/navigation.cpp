// Navigation fields: geodesic distance to an exit by fast marching, and the
// desired direction -grad T. (Evaluating a field is in navigation_field.cpp,
// which the engine links without the rest of this module.)
#include "crowdrecon/geometry/navigation.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <utility>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::geometry {

bool NavigationOptions::IsValid(std::string* error) const {
  if (grid_spacing_m >= 0.005 && grid_spacing_m <= 10.0) return true;
  if (error)
    *error = "grid_spacing_m = " + FormatNumber(grid_spacing_m) + " is out of range; expected a spacing in [0.005, 10] m";
  return false;
}

// ---------------------------------------------------------------------------
// Fast marching
// ---------------------------------------------------------------------------

std::vector<double> FastMarch(const MarchingGrid& grid, const std::vector<double>& source_distance_m) {
  const std::size_t nx = grid.nx, ny = grid.ny, n = nx * ny;
  const double h = grid.spacing_m;
  std::vector<double> t(n, kUnreachable);
  std::vector<char> known(n, 0), fixed(n, 0);
  auto east_open = [&](std::size_t k) { return grid.blocked_east.empty() || !grid.blocked_east[k]; };
  auto north_open = [&](std::size_t k) { return grid.blocked_north.empty() || !grid.blocked_north[k]; };

  // Min-heap of (T, node); stale entries are skipped when popped. Ties are
  // broken by node index, so the order (and the result) is deterministic.
  using Entry = std::pair<double, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> heap;
  for (std::size_t k = 0; k < n; ++k)
    if (grid.inside[k] && std::isfinite(source_distance_m[k])) {
      t[k] = source_distance_m[k];
      fixed[k] = 1;
      heap.emplace(t[k], k);
    }

  // Smallest known T of the two neighbours along one axis (infinity if none).
  auto known_min = [&](std::size_t k, bool x_axis) {
    const std::size_t i = k % nx, j = k / nx;
    double best = kUnreachable;
    if (x_axis) {
      if (i > 0 && known[k - 1] && east_open(k - 1)) best = std::min(best, t[k - 1]);
      if (i + 1 < nx && known[k + 1] && east_open(k)) best = std::min(best, t[k + 1]);
    } else {
      if (j > 0 && known[k - nx] && north_open(k - nx)) best = std::min(best, t[k - nx]);
      if (j + 1 < ny && known[k + nx] && north_open(k)) best = std::min(best, t[k + nx]);
    }
    return best;
  };

  // First-order upwind update: the largest T with
  // (T - a)^2 + (T - b)^2 = h^2 over the upwind neighbours a, b (Sethian 1996);
  // when only one axis has a known neighbour, or the two differ by h or more,
  // the front arrives along one axis: T = min(a, b) + h.
  auto solve = [&](std::size_t k) {
    const double a = known_min(k, true), b = known_min(k, false);
    const double lo = std::min(a, b), hi = std::max(a, b);
    if (!std::isfinite(hi) || hi - lo >= h) return lo + h;
    const double d = hi - lo;
    return 0.5 * (lo + hi + std::sqrt(2.0 * h * h - d * d));
  };

  while (!heap.empty()) {
    const auto [value, k] = heap.top();
    heap.pop();
    if (known[k] || value > t[k]) continue;
    known[k] = 1;
    const std::size_t i = k % nx, j = k / nx;
    std::size_t neighbours[4];
    std::size_t count = 0;
    if (i > 0 && east_open(k - 1)) neighbours[count++] = k - 1;
    if (i + 1 < nx && east_open(k)) neighbours[count++] = k + 1;
    if (j > 0 && north_open(k - nx)) neighbours[count++] = k - nx;
    if (j + 1 < ny && north_open(k)) neighbours[count++] = k + nx;
    for (std::size_t m = 0; m < count; ++m) {
      const std::size_t q = neighbours[m];
      if (!grid.inside[q] || known[q] || fixed[q]) continue;
      const double candidate = solve(q);
      if (candidate < t[q]) {
        t[q] = candidate;
        heap.emplace(candidate, q);
      }
    }
  }
  return t;
}

// ---------------------------------------------------------------------------
// Building a field for a venue
// ---------------------------------------------------------------------------

namespace {

// Do segments [p, q] and [a, b] meet (touching counts)?
bool SegmentsMeet(Vec2 p, Vec2 q, Vec2 a, Vec2 b) {
  auto side = [](Vec2 o, Vec2 u, Vec2 v) { return Cross(u - o, v - o); };
  auto on = [](Vec2 o, Vec2 u, Vec2 v) {  // v on segment [o, u], given collinear
    return std::min(o.x, u.x) <= v.x && v.x <= std::max(o.x, u.x) && std::min(o.y, u.y) <= v.y &&
           v.y <= std::max(o.y, u.y);
  };
  const double d1 = side(a, b, p), d2 = side(a, b, q), d3 = side(p, q, a), d4 = side(p, q, b);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  return (d1 == 0 && on(a, b, p)) || (d2 == 0 && on(a, b, q)) || (d3 == 0 && on(p, q, a)) ||
         (d4 == 0 && on(p, q, b));
}

}  // namespace

NavigationField NavigationField::ForTarget(const Venue& venue, std::string_view target_id,
                                           const NavigationOptions& options) {
  const std::optional<Target> target = venue.FindTarget(target_id);
  if (!target) {
    std::string known;
    for (const Target& t : venue.targets) known += (known.empty() ? "\"" : ", \"") + t.id + "\"";
    for (const Exit& e : venue.exits) known += (known.empty() ? "\"" : ", \"") + e.id + "\"";
    throw InputError(venue.origin + ": no target or exit named \"" + std::string(target_id) + "\"; expected one of " +
                     (known.empty() ? std::string("(none declared)") : known));
  }
  if (target->kind == Target::Kind::kDirection) return Constant(target->direction);
  return ToExits(venue, target->exit_ids.empty() ? std::vector<std::string>{target->exit_id} : target->exit_ids, options);
}

NavigationField NavigationField::ToExit(const Venue& venue, std::string_view exit_id,
                                        const NavigationOptions& options) {
  return ToExits(venue, {std::string(exit_id)}, options);
}

NavigationField NavigationField::ToExits(const Venue& venue, const std::vector<std::string>& exit_ids,
                                         const NavigationOptions& options) {
  if (std::string error; !options.IsValid(&error)) throw InputError("navigation: " + error);
  std::vector<const Exit*> exits;
  for (const std::string& id : exit_ids) {
    const Exit* e = venue.FindExit(id);
    if (!e) throw GeometryError(venue.origin + ": no exit named \"" + id + "\"");
    exits.push_back(e);
  }
  if (exits.empty()) throw GeometryError(venue.origin + ": a target with no exit");
  const double h = options.grid_spacing_m;

  // 1. Grid over the walkable area's bounds. The origin is offset by an
  // irrational fraction of a cell so that nodes do not fall exactly on walls
  // drawn at round coordinates (a node on a wall is neither side of it).
  Vec2 lo, hi;
  WalkableBounds(venue, &lo, &hi);
  NavigationField f;
  f.constant_ = false;
  f.spacing_m_ = h;
  f.origin_m_ = lo - Vec2{0.618034 * h, 0.618034 * h};
  f.nx_ = static_cast<std::size_t>(std::floor((hi.x - f.origin_m_.x) / h)) + 2;
  f.ny_ = static_cast<std::size_t>(std::floor((hi.y - f.origin_m_.y) / h)) + 2;
  if (static_cast<double>(f.nx_) * static_cast<double>(f.ny_) > 5e7)
    throw InputError(venue.origin + ": navigation grid of " + std::to_string(f.nx_) + " x " + std::to_string(f.ny_) +
                     " nodes is too large; expected a larger grid_spacing_m than " + FormatNumber(h) + " m");
  const std::size_t nx = f.nx_, ny = f.ny_, n = nx * ny;
  auto node = [&](std::size_t i, std::size_t j) {
    return f.origin_m_ + Vec2{static_cast<double>(i) * h, static_cast<double>(j) * h};
  };

  // 2. Inside nodes by scanline: on each grid row, the crossings of every ring
  // (outer rings and obstacles, which nest without touching) sorted in x
  // bound the inside spans (even-odd rule).
  MarchingGrid grid;
  grid.nx = nx;
  grid.ny = ny;
  grid.spacing_m = h;
  grid.inside.assign(n, 0);
  std::vector<const Ring*> rings;
  for (const Ring& r : venue.walkable_area) rings.push_back(&r);
  for (const Obstacle& o : venue.obstacles) rings.push_back(&o.polygon);
  std::vector<double> crossings;
  for (std::size_t j = 0; j < ny; ++j) {
    const double y = node(0, j).y;
    crossings.clear();
    for (const Ring* ring : rings)
      for (std::size_t a = 0, b = ring->size() - 1; a < ring->size(); b = a++) {
        const Vec2 p = (*ring)[a], q = (*ring)[b];
        if ((p.y > y) != (q.y > y)) crossings.push_back(p.x + (y - p.y) / (q.y - p.y) * (q.x - p.x));
      }
    std::sort(crossings.begin(), crossings.end());
    for (std::size_t c = 0; c + 1 < crossings.size(); c += 2) {
      const double x0 = (crossings[c] - f.origin_m_.x) / h, x1 = (crossings[c + 1] - f.origin_m_.x) / h;
      const auto i0 = static_cast<std::size_t>(std::max(0.0, std::ceil(x0)));
      const auto i1 = static_cast<std::size_t>(std::clamp(std::floor(x1), -1.0, static_cast<double>(nx - 1)) + 1.0);
      for (std::size_t i = i0; i < i1; ++i) grid.inside[j * nx + i] = 1;
    }
  }

  // 3. Walls cut the links they cross (thin walls and barriers inside the
  // area), and nodes within a wall's sphero-radius are not walkable.
  grid.blocked_east.assign(n, 0);
  grid.blocked_north.assign(n, 0);
  for (const WallSegment& w : WallSegments(venue)) {
    const double reach = w.radius_m + h;
    const auto index_range = [&](double a, double b, double origin, std::size_t count) {
      const double lo_i = std::floor((std::min(a, b) - reach - origin) / h);
      const double hi_i = std::ceil((std::max(a, b) + reach - origin) / h);
      return std::pair<std::size_t, std::size_t>{
          static_cast<std::size_t>(std::clamp(lo_i, 0.0, static_cast<double>(count - 1))),
          static_cast<std::size_t>(std::clamp(hi_i, 0.0, static_cast<double>(count - 1)))};
    };
    const auto [i0, i1] = index_range(w.a.x, w.b.x, f.origin_m_.x, nx);
    const auto [j0, j1] = index_range(w.a.y, w.b.y, f.origin_m_.y, ny);
    for (std::size_t j = j0; j <= j1; ++j)
      for (std::size_t i = i0; i <= i1; ++i) {
        const std::size_t k = j * nx + i;
        const Vec2 p = node(i, j);
        if (w.radius_m > 0.0 && DistanceToSegment(p, w.a, w.b) < w.radius_m) grid.inside[k] = 0;
        if (i + 1 < nx && SegmentsMeet(p, node(i + 1, j), w.a, w.b)) grid.blocked_east[k] = 1;
        if (j + 1 < ny && SegmentsMeet(p, node(i, j + 1), w.a, w.b)) grid.blocked_north[k] = 1;
      }
  }

  // 4. Sources: inside nodes within 1.5 cells of an exit take their exact
  // distance to it (the nearest exit's), which makes the front start as the
  // right shape (a flat front across a doorway, round around its ends).
  std::vector<double> source(n, kUnreachable);
  for (const Exit* exit : exits) {
    std::size_t sources = 0;
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        const std::size_t k = j * nx + i;
        if (!grid.inside[k]) continue;
        const double d = DistanceToSegment(node(i, j), exit->a, exit->b);
        if (d <= 1.5 * h) {
          source[k] = std::min(source[k], d);
          ++sources;
        }
      }
    if (sources == 0)
      throw GeometryError(venue.origin + ": exit \"" + exit->id + "\" has no grid node of the walkable area within " +
                          FormatNumber(1.5 * h) + " m; expected a smaller navigation grid spacing");
  }

  // 5. March, then -grad T at each node by central differences where both
  // neighbours are reachable and not walled off, one-sided otherwise.
  f.distance_m_ = FastMarch(grid, source);
  f.direction_.assign(n, Vec2{});
  const auto& t = f.distance_m_;
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      const std::size_t k = j * nx + i;
      if (!std::isfinite(t[k])) continue;
      auto derivative = [&](bool has_minus, std::size_t minus, bool has_plus, std::size_t plus) {
        const bool m = has_minus && std::isfinite(t[minus]);
        const bool p = has_plus && std::isfinite(t[plus]);
        if (m && p) return (t[plus] - t[minus]) / (2.0 * h);
        if (p) return (t[plus] - t[k]) / h;
        if (m) return (t[k] - t[minus]) / h;
        return 0.0;
      };
      const double gx = derivative(i > 0 && !grid.blocked_east[k - 1], k - 1, i + 1 < nx && !grid.blocked_east[k], k + 1);
      const double gy = derivative(j > 0 && !grid.blocked_north[k - nx], k - nx, j + 1 < ny && !grid.blocked_north[k],
                                   k + nx);
      const Vec2 g{-gx, -gy};
      if (Length(g) > 0.0) f.direction_[k] = Normalized(g);
    }
  return f;
}

}  // namespace crowdrecon::geometry
