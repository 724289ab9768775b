#include "crowdrecon/engine/narrow_phase.hpp"

#include "narrow_phase_core.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace crowdrecon::engine {

ShapeGeometry ShapeGeometry::Make(std::vector<Vec2> vertices, bool closed, double radius_m) {
  ShapeGeometry g;
  g.vertices = std::move(vertices);
  const std::size_t n = g.vertices.size();
  g.closed = closed && n >= 3;
  g.radius_m = radius_m;
  if (n == 0) return g;
  g.box_min = g.box_max = g.vertices.front();
  for (const Vec2& v : g.vertices) {
    g.core_radius_m = std::max(g.core_radius_m, Length(v));
    g.box_min = {std::min(g.box_min.x, v.x), std::min(g.box_min.y, v.y)};
    g.box_max = {std::max(g.box_max.x, v.x), std::max(g.box_max.y, v.y)};
  }
  const std::size_t edges = n == 1 ? 0 : (g.closed ? n : n - 1);
  g.edges.resize(edges);
  for (std::size_t j = 0; j < edges; ++j) {
    const Vec2 e0 = g.vertices[j], e1 = g.vertices[j + 1 == n ? 0 : j + 1];
    const Vec2 d = e1 - e0;
    g.edges[j] = {e0, d, 1.0 / LengthSquared(d)};
  }
  if (g.closed) {
    g.reflex.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const Vec2 prev = g.vertices[k == 0 ? n - 1 : k - 1], next = g.vertices[k + 1 == n ? 0 : k + 1];
      g.reflex[k] = Cross(g.vertices[k] - prev, next - g.vertices[k]) < 0.0 ? 1 : 0;
    }
  }
  return g;
}

ShapeGeometry ShapeGeometry::FromWorld(const std::vector<Vec2>& points, bool closed, double radius_m, Vec2& origin) {
  Vec2 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Vec2 hi = -lo;
  for (const Vec2& p : points) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  }
  origin = points.empty() ? Vec2{} : (lo + hi) / 2.0;
  std::vector<Vec2> local;
  local.reserve(points.size());
  for (const Vec2& p : points) local.push_back(p - origin);
  ShapeGeometry g = Make(std::move(local), closed, radius_m);
  // A wall is a line, whichever side a person is on: a closed wall keeps its
  // closing edge but has no inside (a room walled all round holds people
  // inside it). Crossing it is what the engine checks (WallCrossing).
  g.closed = false;
  g.reflex.clear();
  return g;
}

namespace {

using detail::BoxesGap;
using detail::Closest;
using detail::ClosestOnCore;

Closest ClosestOnCore(Vec2 p, const ShapeGeometry& g) { return ClosestOnCore(p, g, nullptr, g.edges.size()); }

// Contacts of the vertices of `from` against the core of `to`; `flip` makes
// normals point from B to A when `from` is B. Works in `to`'s unscaled frame
// (its geometry's own units).
// Returns the least clearance (d - reach, metres) over the vertices that did
// not touch, +infinity if there were none; see CollideShapes. `memory` (or
// null): per vertex of `from`, skip it while moved < memory[i], and record
// the bound for the vertices measured apart.
double VerticesAgainst(const PlacedShape& from, const PlacedShape& to, bool flip, std::uint32_t tag,
                       std::vector<ContactPoint>& out, double moved, double* memory) {
  const ShapeGeometry& f = *from.geometry;
  const ShapeGeometry& g = *to.geometry;
  const detail::VertexFrame frame = detail::FrameOf(from, to);  // g's units and frame
  const double reach = frame.reach, unit = frame.unit, reach_g = frame.reach_g, c = frame.c, s = frame.s;
  const Vec2 o = frame.o, lo = frame.lo, hi = frame.hi;
  const bool use_grid = !g.cell_start.empty() && reach_g <= g.grid_reach_m;
  const double inverse_cell = use_grid ? 1.0 / g.grid_cell_m : 0.0;
  const std::uint32_t n = f.count();
  double clearance = std::numeric_limits<double>::infinity();  // g's units
  // Vertex i measured apart by `gap` (g's units): the pair's least, and the
  // vertex's own threshold.
  const auto apart = [&](std::uint32_t i, double gap) {
    clearance = std::min(clearance, gap);
    if (memory) memory[i] = moved + gap * unit - kClearanceSlack_m;
  };
  // Least threshold of the vertices skipped below: their clearance, min over
  // i of (memory[i] - moved) / unit, is (least - moved) / unit (monotone in
  // memory[i], so exactly the same value), one division instead of one each.
  double least_skipped = std::numeric_limits<double>::infinity();
  // Measures vertex i: appends its contact, or records it apart.
  const auto measure = [&](std::uint32_t i) {
    const Vec2 v = f.vertices[i];
    const Vec2 p{c * v.x - s * v.y + o.x, s * v.x + c * v.y + o.y};
    if (p.x < lo.x || p.x > hi.x || p.y < lo.y || p.y > hi.y) {
      // Outside the box grown by the reach: d(p, core) - reach >= how far outside.
      apart(i, std::max(std::max(lo.x - p.x, p.x - hi.x), std::max(lo.y - p.y, p.y - hi.y)));
      return;
    }
    Closest cl;
    if (use_grid) {
      const double fx = (p.x - g.grid_origin.x) * inverse_cell, fy = (p.y - g.grid_origin.y) * inverse_cell;
      // Clamped before the conversion: a point beyond the range of the
      // integer (or not a number, in a step that is going numerically wrong
      // and that the check stage will stop) must not be converted; the same
      // cells as clamping the integers.
      const std::uint32_t cx = !(fx > 0.0) ? 0 : static_cast<std::uint32_t>(std::min(fx, double(g.grid_nx - 1)));
      const std::uint32_t cy = !(fy > 0.0) ? 0 : static_cast<std::uint32_t>(std::min(fy, double(g.grid_ny - 1)));
      const std::uint32_t cell = cy * g.grid_nx + cx;
      const std::uint32_t first = g.cell_start[cell], last = g.cell_start[cell + 1];
      if (first == last) {  // farther than the reach from the core
        apart(i, g.cell_clearance[cell] - reach_g);
        return;
      }
      cl = ClosestOnCore(p, g, &g.cell_edges[first], last - first);
    } else {
      cl = ClosestOnCore(p, g);
    }
    if (cl.distance >= reach_g) {
      apart(i, cl.distance - reach_g);
      return;
    }
    Vec2 normal;
    if (cl.distance > 0.0) {
      normal = (p - cl.point) / cl.distance;
    } else if (cl.distance < 0.0) {
      normal = (cl.point - p) / -cl.distance;  // p crossed into the core: push it back out
    } else {
      apart(i, 0.0);
      return;  // exactly on the core boundary: no direction (measure zero)
    }
    ContactPoint cp;
    cp.overlap_m = reach - cl.distance * unit;
    if (!(cp.overlap_m > 0.0)) {  // d < reach in g's units, but not once scaled (round-off)
      apart(i, 0.0);
      return;
    }
    const Vec2 local = cl.point * unit + normal * (g.radius_m * unit - cp.overlap_m / 2.0);  // metres, to's frame
    cp.point = to.position + Vec2{to.cos_angle * local.x - to.sin_angle * local.y,
                                  to.sin_angle * local.x + to.cos_angle * local.y};
    const Vec2 world_normal{to.cos_angle * normal.x - to.sin_angle * normal.y,
                            to.sin_angle * normal.x + to.cos_angle * normal.y};
    cp.normal = flip ? -world_normal : world_normal;
    cp.feature = tag | i;
    out.push_back(cp);
  };
  // In blocks of 64 vertices: first, in a short loop of their own, which
  // vertices are still apart since they were last measured (and the least of
  // their thresholds), then the others are measured, in vertex order.
  for (std::uint32_t base = 0; base < n; base += 64) {
    const std::uint32_t count = std::min<std::uint32_t>(64, n - base);
    std::uint64_t todo = count == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << count) - 1;
    if (memory) {
      todo = 0;
      double least = least_skipped;
      std::uint32_t k = 0;
#if defined(__SSE2__)
      // Two thresholds at a time (SSE2 is part of every x86-64): the same
      // comparisons, and the least of the same set of values.
      const __m128d moved2 = _mm_set1_pd(moved);
      const __m128d none2 = _mm_set1_pd(std::numeric_limits<double>::infinity());
      __m128d least2 = _mm_set1_pd(least);
      for (; k + 2 <= count; k += 2) {
        const __m128d threshold = _mm_loadu_pd(memory + base + k);
        const __m128d skip = _mm_cmplt_pd(moved2, threshold);
        least2 = _mm_min_pd(least2, _mm_or_pd(_mm_and_pd(skip, threshold), _mm_andnot_pd(skip, none2)));
        todo |= static_cast<std::uint64_t>(~_mm_movemask_pd(skip) & 3) << k;
      }
      least = std::min(_mm_cvtsd_f64(least2), _mm_cvtsd_f64(_mm_unpackhi_pd(least2, least2)));
#endif
      for (; k < count; ++k) {
        const double threshold = memory[base + k];
        const bool skip = moved < threshold;
        least = std::min(least, skip ? threshold : std::numeric_limits<double>::infinity());
        todo |= std::uint64_t{!skip} << k;
      }
      least_skipped = least;
    }
    for (; todo != 0; todo &= todo - 1) measure(base + static_cast<std::uint32_t>(std::countr_zero(todo)));
  }
  if (least_skipped < std::numeric_limits<double>::infinity())
    clearance = std::min(clearance, (least_skipped - moved) / unit);
  return clearance * unit;  // (an infinity stays one)
}


}  // namespace

void ShapeGeometry::BuildEdgeGrid(double reach_m) {
  cell_start.clear();
  cell_edges.clear();
  cell_clearance.clear();
  grid_nx = grid_ny = 0;
  grid_reach_m = 0.0;
  if (edges.size() < 6 || !(reach_m > 0.0) || edges.size() > 65535) return;
  const Vec2 lo = box_min - Vec2{reach_m, reach_m}, hi = box_max + Vec2{reach_m, reach_m};
  // About 24 cells along the longer side: a cell is small next to a body, so
  // few edges are candidates, and the grid stays a few kilobytes.
  const double cell = std::max(hi.x - lo.x, hi.y - lo.y) / 24.0;
  const auto nx = static_cast<std::uint32_t>(std::ceil((hi.x - lo.x) / cell));
  const auto ny = static_cast<std::uint32_t>(std::ceil((hi.y - lo.y) / cell));
  const double half_diagonal = cell * std::sqrt(0.5);
  const double slack = 1e-9 * (1.0 + core_radius_m + reach_m);  // round-off of the distances below
  std::vector<double> distance(edges.size());
  cell_start.assign(std::size_t{nx} * ny + 1, 0);
  cell_clearance.assign(std::size_t{nx} * ny, 0.0);
  for (std::uint32_t cy = 0; cy < ny; ++cy)
    for (std::uint32_t cx = 0; cx < nx; ++cx) {
      const Vec2 centre = lo + Vec2{(cx + 0.5) * cell, (cy + 0.5) * cell};
      double least = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < edges.size(); ++j) {
        const CoreEdge& e = edges[j];
        const double t = std::clamp(Dot(centre - e.start, e.direction) * e.inverse_length2, 0.0, 1.0);
        distance[j] = Length(centre - (e.start + e.direction * t));
        least = std::min(least, distance[j]);
      }
      const bool inside = ClosestOnCore(centre, *this).distance < 0.0;
      const std::size_t index = std::size_t{cy} * nx + cx;
      // Outside and farther than reach + half a diagonal: no point of the cell
      // can touch. Inside cells keep their candidates (a vertex there is deep
      // in the core, which the engine reports as an error).
      if (!inside && least - half_diagonal > reach_m + slack) {
        cell_start[index + 1] = static_cast<std::uint32_t>(cell_edges.size());
        cell_clearance[index] = least - half_diagonal - slack;  // any point p of the cell: d(p) >= this
        continue;
      }
      // Any point p of the cell: its closest edge e* has |p e*| <= |p e_least|
      // <= least + h, so |centre e*| <= least + 2h.
      for (std::size_t j = 0; j < edges.size(); ++j)
        if (distance[j] <= least + 2.0 * half_diagonal + slack) cell_edges.push_back(static_cast<std::uint16_t>(j));
      cell_start[index + 1] = static_cast<std::uint32_t>(cell_edges.size());
    }
  grid_origin = lo;
  grid_cell_m = cell;
  grid_nx = nx;
  grid_ny = ny;
  grid_reach_m = reach_m;
}

double CollideShapes(const PlacedShape& a, const PlacedShape& b, std::vector<ContactPoint>& out,
                     const VertexClearances* memory) {
  const ShapeGeometry& ga = *a.geometry;
  const ShapeGeometry& gb = *b.geometry;
  const double reach = ga.radius_m * a.scale + gb.radius_m * b.scale;
  const double bound = ga.core_radius_m * a.scale + gb.core_radius_m * b.scale + reach;
  const double d2 = LengthSquared(a.position - b.position);
  // Bounding circles apart: every core point lies within its circle.
  if (d2 >= bound * bound) return std::sqrt(d2) - bound;
  // Grown boxes apart along an axis: the gap of their projections bounds the
  // distance of the cores less the reach (each box is grown by half of it).
  const double boxes = BoxesGap(a, b, reach);
  if (boxes > 0.0) return boxes;
  // With a disk on either side, the disk's vertex alone gives the exact overlap.
  const bool a_side = ga.count() == 1 || gb.count() != 1;
  const bool b_side = ga.count() != 1;
  const std::size_t before = out.size();
  double clearance = std::numeric_limits<double>::infinity();
  const double moved = memory ? memory->moved : 0.0;
  if (a_side) clearance = std::min(clearance, VerticesAgainst(a, b, false, 0u, out, moved, memory ? memory->a : nullptr));
  if (b_side)
    clearance = std::min(clearance, VerticesAgainst(b, a, true, kVertexOfB, out, moved, memory ? memory->b : nullptr));
  if (out.size() != before) return 0.0;
  return std::max(0.0, clearance);
}

}  // namespace crowdrecon::engine
