#include "crowdrecon/engine/narrow_phase.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

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
  return Make(std::move(local), closed, radius_m);
}

namespace {

// Closest point of the core of `g` (in g's frame) to p, with the signed
// distance: negative when p lies inside a polygon.
struct Closest {
  Vec2 point;
  double distance = std::numeric_limits<double>::infinity();
};

Closest ClosestOnCore(Vec2 p, const ShapeGeometry& g) {
  Closest best;
  if (g.edges.empty()) {
    best.point = g.vertices[0];
    best.distance = Length(p - g.vertices[0]);
    return best;
  }
  const std::size_t edges = g.edges.size();
  double best_d2 = std::numeric_limits<double>::infinity();
  std::size_t best_edge = 0;
  double best_t = 0.0;
  for (std::size_t j = 0; j < edges; ++j) {
    const CoreEdge& e = g.edges[j];
    double t = Dot(p - e.start, e.direction) * e.inverse_length2;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    const Vec2 q = e.start + e.direction * t;
    const double d2 = LengthSquared(p - q);
    if (d2 < best_d2) {
      best_d2 = d2;
      best.point = q;
      best_edge = j;
      best_t = t;
    }
  }
  best.distance = std::sqrt(best_d2);
  if (g.closed) {
    // Inside test from the closest feature: across an edge interior by the
    // side of its line; at a vertex, p is inside exactly when the vertex is reflex.
    bool inside;
    if (best_t > 0.0 && best_t < 1.0) {
      const CoreEdge& e = g.edges[best_edge];
      inside = Cross(e.direction, p - e.start) > 0.0;  // left of a counter-clockwise edge
    } else {
      const std::size_t n = g.vertices.size();
      const std::size_t k = best_t <= 0.0 ? best_edge : (best_edge + 1 == n ? 0 : best_edge + 1);
      inside = g.reflex[k] != 0;
    }
    if (inside) best.distance = -best.distance;
  }
  return best;
}

// Contacts of the vertices of `from` against the core of `to`; `flip` makes
// normals point from B to A when `from` is B. Works in `to`'s frame.
void VerticesAgainst(const PlacedShape& from, const PlacedShape& to, bool flip, std::uint32_t tag,
                     std::vector<ContactPoint>& out) {
  const ShapeGeometry& f = *from.geometry;
  const ShapeGeometry& g = *to.geometry;
  const double reach = f.radius_m + g.radius_m;
  // from-frame -> to-frame: rotation by (theta_from - theta_to), then the
  // offset of from's origin seen in to's frame.
  const double c = from.cos_angle * to.cos_angle + from.sin_angle * to.sin_angle;
  const double s = from.sin_angle * to.cos_angle - from.cos_angle * to.sin_angle;
  const Vec2 d = from.position - to.position;
  const Vec2 o{to.cos_angle * d.x + to.sin_angle * d.y, -to.sin_angle * d.x + to.cos_angle * d.y};
  const Vec2 lo = g.box_min - Vec2{reach, reach}, hi = g.box_max + Vec2{reach, reach};
  const std::uint32_t n = f.count();
  for (std::uint32_t i = 0; i < n; ++i) {
    const Vec2 v = f.vertices[i];
    const Vec2 p{c * v.x - s * v.y + o.x, s * v.x + c * v.y + o.y};
    if (p.x < lo.x || p.x > hi.x || p.y < lo.y || p.y > hi.y) continue;
    const Closest cl = ClosestOnCore(p, g);
    if (cl.distance >= reach) continue;
    Vec2 normal;
    if (cl.distance > 0.0) {
      normal = (p - cl.point) / cl.distance;
    } else if (cl.distance < 0.0) {
      normal = (cl.point - p) / -cl.distance;  // p crossed into the core: push it back out
    } else {
      continue;  // exactly on the core boundary: no direction (measure zero)
    }
    ContactPoint cp;
    cp.overlap_m = reach - cl.distance;
    const Vec2 local = cl.point + normal * (g.radius_m - cp.overlap_m / 2.0);
    cp.point = to.position + Vec2{to.cos_angle * local.x - to.sin_angle * local.y,
                                  to.sin_angle * local.x + to.cos_angle * local.y};
    const Vec2 world_normal{to.cos_angle * normal.x - to.sin_angle * normal.y,
                            to.sin_angle * normal.x + to.cos_angle * normal.y};
    cp.normal = flip ? -world_normal : world_normal;
    cp.feature = tag | i;
    out.push_back(cp);
  }
}

// True when the bounding boxes of A and B, each grown by half the reach, do
// not overlap (separating axis theorem; four axes in 2D). Then no point of A's
// core comes within the reach of B's core.
bool BoxesApart(const PlacedShape& a, const PlacedShape& b, double reach) {
  const ShapeGeometry& ga = *a.geometry;
  const ShapeGeometry& gb = *b.geometry;
  const double grow = reach / 2.0;
  const Vec2 ha = (ga.box_max - ga.box_min) / 2.0 + Vec2{grow, grow};
  const Vec2 hb = (gb.box_max - gb.box_min) / 2.0 + Vec2{grow, grow};
  const Vec2 ma = (ga.box_max + ga.box_min) / 2.0, mb = (gb.box_max + gb.box_min) / 2.0;
  const Vec2 ua{a.cos_angle, a.sin_angle}, va{-a.sin_angle, a.cos_angle};
  const Vec2 ub{b.cos_angle, b.sin_angle}, vb{-b.sin_angle, b.cos_angle};
  const Vec2 ca = a.position + ua * ma.x + va * ma.y;
  const Vec2 cb = b.position + ub * mb.x + vb * mb.y;
  const Vec2 t = cb - ca;
  const double uu = std::abs(Dot(ua, ub)), uv = std::abs(Dot(ua, vb));
  const double vu = std::abs(Dot(va, ub)), vv = std::abs(Dot(va, vb));
  if (std::abs(Dot(t, ua)) > ha.x + hb.x * uu + hb.y * uv) return true;
  if (std::abs(Dot(t, va)) > ha.y + hb.x * vu + hb.y * vv) return true;
  if (std::abs(Dot(t, ub)) > hb.x + ha.x * uu + ha.y * vu) return true;
  if (std::abs(Dot(t, vb)) > hb.y + ha.x * uv + ha.y * vv) return true;
  return false;
}

}  // namespace

void CollideShapes(const PlacedShape& a, const PlacedShape& b, std::vector<ContactPoint>& out) {
  const ShapeGeometry& ga = *a.geometry;
  const ShapeGeometry& gb = *b.geometry;
  const double reach = ga.radius_m + gb.radius_m;
  const double bound = ga.core_radius_m + gb.core_radius_m + reach;
  if (LengthSquared(a.position - b.position) >= bound * bound) return;
  if (BoxesApart(a, b, reach)) return;
  // With a disk on either side, the disk's vertex alone gives the exact overlap.
  const bool a_side = ga.count() == 1 || gb.count() != 1;
  const bool b_side = ga.count() != 1;
  if (a_side) VerticesAgainst(a, b, false, 0u, out);
  if (b_side) VerticesAgainst(b, a, true, kVertexOfB, out);
}

}  // namespace crowdrecon::engine
