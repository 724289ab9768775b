// The parts of the narrow phase (narrow_phase.cpp) that the CUDA force
// computation (cuda_collide.cu) runs too, as templates over the geometry and
// placed-shape types of either side: one source, the same expressions in the
// same order, hence the same results bit for bit.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/engine/narrow_phase.hpp"
#include "host_device.hpp"

#if defined(__SSE2__) && !defined(__CUDACC__)
#include <emmintrin.h>
#endif

namespace crowdrecon::engine::detail {

// Closest point of the core of `g` (in g's frame) to p, with the signed
// distance: negative when p lies inside a polygon.
struct Closest {
  Vec2 point;
  double distance = std::numeric_limits<double>::infinity();
};

// t clamped to [0, 1]: t > 1 gives 1, t < 0 gives 0, else t itself (-0.0
// stays -0.0). On x86-64 by MINSD and MAXSD, whose operand order gives
// exactly these comparisons, so that no branch is taken per edge (whether a
// vertex projects before, on or beyond an edge varies from edge to edge and
// defeats branch prediction; the compiler keeps branches for the plain
// expressions, the device and other processors use them).
CROWDRECON_HOST_DEVICE CROWDRECON_INLINE double ClampToUnit(double t) {
#if defined(__SSE2__) && !defined(__CUDACC__)
  return _mm_cvtsd_f64(_mm_max_sd(_mm_setzero_pd(), _mm_min_sd(_mm_set_sd(1.0), _mm_set_sd(t))));
#else
  t = t > 1.0 ? 1.0 : t;
  return t < 0.0 ? 0.0 : t;
#endif
}

// Searches the edges edge_index[0..m) (all edges when edge_index is null).
// `Geometry`: ShapeGeometry, or the device's copy of it (cuda_collide.cu).
template <typename Geometry>
CROWDRECON_HOST_DEVICE CROWDRECON_INLINE Closest ClosestOnCore(Vec2 p, const Geometry& g, const std::uint16_t* edge_index,
                                             std::size_t m) {
  Closest best;
  if (g.edge_count() == 0) {
    best.point = g.vertices[0];
    const Vec2 d = p - g.vertices[0];
    best.distance = std::sqrt(d.x * d.x + d.y * d.y);  // Length(d), which is not for the device
    return best;
  }
  // The first candidate at the least squared distance, found without a
  // branch per candidate (selects, not jumps: which edge is closest, and
  // where along it, vary from vertex to vertex and defeat branch
  // prediction); its closest point is then computed again by the same
  // expressions, hence to the same bits.
  double best_d2 = std::numeric_limits<double>::infinity();
  std::size_t best_edge = 0;
  for (std::size_t k = 0; k < m; ++k) {
    const std::size_t j = edge_index ? edge_index[k] : k;
    const CoreEdge& e = g.edges[j];
    const double t = ClampToUnit(Dot(p - e.start, e.direction) * e.inverse_length2);
    const Vec2 q = e.start + e.direction * t;
    const double d2 = LengthSquared(p - q);
    const bool closer = d2 < best_d2;
    best_edge = closer ? j : best_edge;
    best_d2 = closer ? d2 : best_d2;
  }
  const CoreEdge& closest = g.edges[best_edge];
  const double best_t = ClampToUnit(Dot(p - closest.start, closest.direction) * closest.inverse_length2);
  best.point = closest.start + closest.direction * best_t;
  best.distance = std::sqrt(best_d2);
  if (g.closed) {
    // Inside test from the closest feature: across an edge interior by the
    // side of its line; at a vertex, p is inside exactly when the vertex is reflex.
    bool inside;
    if (best_t > 0.0 && best_t < 1.0) {
      inside = Cross(closest.direction, p - closest.start) > 0.0;  // left of a counter-clockwise edge
    } else {
      const std::size_t n = g.count();
      const std::size_t k = best_t <= 0.0 ? best_edge : (best_edge + 1 == n ? 0 : best_edge + 1);
      inside = g.reflex[k] != 0;
    }
    if (inside) best.distance = -best.distance;
  }
  return best;
}

// True when the bounding boxes of A and B, each grown by half the reach, do
// not overlap (separating axis theorem; four axes in 2D). Then no point of A's
// core comes within the reach of B's core.
// `Placed`: PlacedShape, or the device's (cuda_collide.cu).
template <typename Placed>
CROWDRECON_HOST_DEVICE CROWDRECON_INLINE double BoxesGap(const Placed& a, const Placed& b, double reach) {
  const auto& ga = *a.geometry;
  const auto& gb = *b.geometry;
  const double grow = reach / 2.0;
  const Vec2 ha = (ga.box_max - ga.box_min) * (a.scale / 2.0) + Vec2{grow, grow};
  const Vec2 hb = (gb.box_max - gb.box_min) * (b.scale / 2.0) + Vec2{grow, grow};
  const Vec2 ma = (ga.box_max + ga.box_min) * (a.scale / 2.0), mb = (gb.box_max + gb.box_min) * (b.scale / 2.0);
  const Vec2 ua{a.cos_angle, a.sin_angle}, va{-a.sin_angle, a.cos_angle};
  const Vec2 ub{b.cos_angle, b.sin_angle}, vb{-b.sin_angle, b.cos_angle};
  const Vec2 ca = a.position + ua * ma.x + va * ma.y;
  const Vec2 cb = b.position + ub * mb.x + vb * mb.y;
  const Vec2 t = cb - ca;
  const double uu = std::abs(Dot(ua, ub)), uv = std::abs(Dot(ua, vb));
  const double vu = std::abs(Dot(va, ub)), vv = std::abs(Dot(va, vb));
  const double gap_ua = std::abs(Dot(t, ua)) - (ha.x + hb.x * uu + hb.y * uv);
  const double gap_va = std::abs(Dot(t, va)) - (ha.y + hb.x * vu + hb.y * vv);
  const double gap_ub = std::abs(Dot(t, ub)) - (hb.x + ha.x * uu + ha.y * vu);
  const double gap_vb = std::abs(Dot(t, vb)) - (hb.y + ha.x * uv + ha.y * vv);
  return std::max(std::max(gap_ua, gap_va), std::max(gap_ub, gap_vb));
}

// The frame in which the vertices of `from` are measured against the core of
// `to` (VerticesAgainst): to's geometry's own units and frame. A vertex v of
// from's geometry is at (c v.x - s v.y + o.x, s v.x + c v.y + o.y) there: the
// rotation by (theta_from - theta_to) with the ratio of scales, then the
// offset of from's origin seen in to's frame. `reach` (metres) is the sum of
// the two sphero-radii, `reach_g` the same in to's units; [lo, hi] is to's
// core box grown by it.
struct VertexFrame {
  double reach, unit, reach_g, c, s;
  Vec2 o, lo, hi;
};

template <typename Placed>
CROWDRECON_HOST_DEVICE CROWDRECON_INLINE VertexFrame FrameOf(const Placed& from, const Placed& to) {
  const auto& f = *from.geometry;
  const auto& g = *to.geometry;
  VertexFrame fr;
  fr.reach = f.radius_m * from.scale + g.radius_m * to.scale;  // metres
  fr.unit = to.scale;                                            // metres per unit of g
  fr.reach_g = fr.reach / fr.unit;
  const double ratio = from.scale / fr.unit;
  fr.c = (from.cos_angle * to.cos_angle + from.sin_angle * to.sin_angle) * ratio;
  fr.s = (from.sin_angle * to.cos_angle - from.cos_angle * to.sin_angle) * ratio;
  const Vec2 d = from.position - to.position;
  fr.o = Vec2{to.cos_angle * d.x + to.sin_angle * d.y, -to.sin_angle * d.x + to.cos_angle * d.y} / fr.unit;
  fr.lo = g.box_min - Vec2{fr.reach_g, fr.reach_g};
  fr.hi = g.box_max + Vec2{fr.reach_g, fr.reach_g};
  return fr;
}

}  // namespace crowdrecon::engine::detail
