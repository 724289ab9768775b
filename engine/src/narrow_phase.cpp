#include "crowdrecon/engine/narrow_phase.hpp"

#include <cmath>
#include <limits>

namespace crowdrecon::engine {

namespace {

// Closest point of `s`'s core (a point, a segment or a closed polygon) to p,
// with the signed distance: negative when p lies inside a polygon.
struct Closest {
  Vec2 point;
  double distance = std::numeric_limits<double>::infinity();
};

Closest ClosestOnCore(Vec2 p, const PlacedShape& s) {
  const Vec2* v = s.vertices;
  const std::uint32_t n = s.count;
  Closest best;
  if (n == 1) {
    best.point = v[0];
    best.distance = Length(p - v[0]);
    return best;
  }
  const bool closed = s.closed && n >= 3;
  const std::uint32_t edges = closed ? n : n - 1;
  double best_d2 = std::numeric_limits<double>::infinity();
  std::uint32_t best_edge = 0;
  double best_t = 0.0;
  for (std::uint32_t j = 0; j < edges; ++j) {
    const Vec2 e0 = v[j], e1 = v[j + 1 == n ? 0 : j + 1];
    const Vec2 d = e1 - e0;
    double t = Dot(p - e0, d) / LengthSquared(d);
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    const Vec2 q = e0 + d * t;
    const double d2 = LengthSquared(p - q);
    if (d2 < best_d2) {
      best_d2 = d2;
      best.point = q;
      best_edge = j;
      best_t = t;
    }
  }
  best.distance = std::sqrt(best_d2);
  if (closed) {
    // Inside test from the closest feature: across an edge interior by the
    // side of its line; at a vertex, p is inside exactly when the vertex is reflex.
    bool inside;
    if (best_t > 0.0 && best_t < 1.0) {
      const Vec2 e0 = v[best_edge], e1 = v[best_edge + 1 == n ? 0 : best_edge + 1];
      inside = Cross(e1 - e0, p - e0) > 0.0;  // left of a counter-clockwise edge
    } else {
      const std::uint32_t k = best_t <= 0.0 ? best_edge : (best_edge + 1 == n ? 0 : best_edge + 1);
      const Vec2 prev = v[k == 0 ? n - 1 : k - 1], next = v[k + 1 == n ? 0 : k + 1];
      inside = Cross(v[k] - prev, next - v[k]) < 0.0;
    }
    if (inside) best.distance = -best.distance;
  }
  return best;
}

// Contacts of the vertices of `from` against the core of `to`; `flip` makes
// normals point from B to A when `from` is B.
void VerticesAgainst(const PlacedShape& from, const PlacedShape& to, bool flip, std::uint32_t tag,
                     std::vector<ContactPoint>& out) {
  const double reach = from.radius_m + to.radius_m;
  const double cull = to.core_radius_m + reach;
  const Vec2 lo = to.box_min - Vec2{reach, reach}, hi = to.box_max + Vec2{reach, reach};
  for (std::uint32_t i = 0; i < from.count; ++i) {
    const Vec2 p = from.vertices[i];
    const Vec2 d = p - to.centre;
    if (LengthSquared(d) >= cull * cull) continue;
    const double lx = to.cos_angle * d.x + to.sin_angle * d.y;
    const double ly = -to.sin_angle * d.x + to.cos_angle * d.y;
    if (lx < lo.x || lx > hi.x || ly < lo.y || ly > hi.y) continue;
    const Closest c = ClosestOnCore(p, to);
    if (c.distance >= reach) continue;
    Vec2 normal;
    if (c.distance > 0.0) {
      normal = (p - c.point) / c.distance;
    } else if (c.distance < 0.0) {
      normal = (c.point - p) / -c.distance;  // p crossed into the core: push it back out
    } else {
      continue;  // exactly on the core boundary: no direction (measure zero)
    }
    ContactPoint cp;
    cp.overlap_m = reach - c.distance;
    cp.point = c.point + normal * (to.radius_m - cp.overlap_m / 2.0);
    cp.normal = flip ? -normal : normal;
    cp.feature = tag | i;
    out.push_back(cp);
  }
}

}  // namespace

void CollideShapes(const PlacedShape& a, const PlacedShape& b, std::vector<ContactPoint>& out) {
  const double reach = a.radius_m + b.radius_m;
  const double bound = a.core_radius_m + b.core_radius_m + reach;
  if (LengthSquared(a.centre - b.centre) >= bound * bound) return;
  // With a disk on either side, the disk's vertex alone gives the exact overlap.
  const bool a_side = a.count == 1 || b.count != 1;
  const bool b_side = a.count != 1;
  if (a_side) VerticesAgainst(a, b, false, 0u, out);
  if (b_side) VerticesAgainst(b, a, true, kVertexOfB, out);
}

}  // namespace crowdrecon::engine
