// Narrow phase (engine/narrow_phase.hpp): the candidate-edge grid and shape
// families are exact shortcuts of the plain vertex-to-edge search.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "crowdrecon/engine/narrow_phase.hpp"

namespace crowdrecon::engine {
namespace {

// A non-convex body with arms (14 vertices, counter-clockwise, chest +x).
std::vector<Vec2> ArmsOutline() {
  return {{0.08, -0.10}, {0.08, 0.10}, {0.03, 0.12}, {0.05, 0.20}, {0.00, 0.23}, {-0.04, 0.20}, {-0.06, 0.12},
          {-0.08, 0.08}, {-0.08, -0.08}, {-0.06, -0.12}, {-0.04, -0.20}, {0.00, -0.23}, {0.05, -0.20}, {0.03, -0.12}};
}

PlacedShape Place(const ShapeGeometry& g, Vec2 at, double angle, double scale = 1.0) {
  PlacedShape p;
  p.geometry = &g;
  p.position = at;
  p.cos_angle = std::cos(angle);
  p.sin_angle = std::sin(angle);
  p.scale = scale;
  return p;
}

// Two contact lists of the same length are equal bit for bit.
void ExpectSameContacts(const std::vector<ContactPoint>& expected, const std::vector<ContactPoint>& got) {
  for (std::size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(expected[k].feature, got[k].feature);
    EXPECT_EQ(expected[k].overlap_m, got[k].overlap_m);
    EXPECT_EQ(expected[k].point.x, got[k].point.x);
    EXPECT_EQ(expected[k].point.y, got[k].point.y);
    EXPECT_EQ(expected[k].normal.x, got[k].normal.x);
    EXPECT_EQ(expected[k].normal.y, got[k].normal.y);
  }
}

TEST(NarrowPhase, EdgeGridGivesExactlyTheFullSearch) {
  const ShapeGeometry plain = ShapeGeometry::Make(ArmsOutline(), true, 0.05);
  ShapeGeometry gridded = plain;
  gridded.BuildEdgeGrid(0.1);
  ASSERT_FALSE(gridded.cell_start.empty());
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::size_t touching = 0, points = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec2 at{0.35 * u(rng), 0.45 * u(rng)};
    const double ta = 3.2 * u(rng), tb = 3.2 * u(rng);
    std::vector<ContactPoint> expected, got;
    CollideShapes(Place(plain, {0, 0}, ta), Place(plain, at, tb), expected);
    CollideShapes(Place(gridded, {0, 0}, ta), Place(gridded, at, tb), got);
    ASSERT_EQ(expected.size(), got.size()) << "trial " << trial;
    ExpectSameContacts(expected, got);  // the same edges with the same arithmetic
    touching += got.empty() ? 0 : 1;
    points += got.size();
  }
  // The scene samples touching and non-touching pairs alike.
  EXPECT_GT(touching, 2000u);
  EXPECT_LT(touching, 18000u);
  EXPECT_GT(points, touching);
}

TEST(NarrowPhase, ScaledFamilyGeometryMatchesTheScaledShape) {
  // A shape used at scale s (unit geometry, radius 1) gives the contacts of
  // the explicitly scaled shape (vertices and radius times s).
  std::vector<Vec2> unit;
  for (const Vec2& v : ArmsOutline()) unit.push_back(v / 0.05);
  ShapeGeometry family = ShapeGeometry::Make(unit, true, 1.0);
  family.BuildEdgeGrid(2.5);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::size_t compared = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    const double sa = 0.05 * (1.0 + 0.15 * u(rng)), sb = 0.05 * (1.0 + 0.15 * u(rng));
    std::vector<Vec2> va, vb;
    for (const Vec2& v : unit) {
      va.push_back(v * sa);
      vb.push_back(v * sb);
    }
    const ShapeGeometry ga = ShapeGeometry::Make(va, true, sa), gb = ShapeGeometry::Make(vb, true, sb);
    const Vec2 at{0.35 * u(rng), 0.45 * u(rng)};
    const double ta = 3.2 * u(rng), tb = 3.2 * u(rng);
    std::vector<ContactPoint> expected, got;
    CollideShapes(Place(ga, {0.3, -0.2}, ta), Place(gb, Vec2{0.3, -0.2} + at, tb), expected);
    CollideShapes(Place(family, {0.3, -0.2}, ta, sa), Place(family, Vec2{0.3, -0.2} + at, tb, sb), got);
    // A vertex exactly at the reach could fall either side by round-off; the
    // random scenes never hit that, so the lists match one to one.
    ASSERT_EQ(expected.size(), got.size()) << "trial " << trial;
    for (std::size_t k = 0; k < got.size(); ++k) {
      EXPECT_EQ(expected[k].feature, got[k].feature);
      EXPECT_NEAR(expected[k].overlap_m, got[k].overlap_m, 1e-14);
      EXPECT_NEAR(expected[k].point.x, got[k].point.x, 1e-14);
      EXPECT_NEAR(expected[k].point.y, got[k].point.y, 1e-14);
      EXPECT_NEAR(expected[k].normal.x, got[k].normal.x, 1e-11);
      EXPECT_NEAR(expected[k].normal.y, got[k].normal.y, 1e-11);
      ++compared;
    }
  }
  EXPECT_GT(compared, 1000u);
}

TEST(NarrowPhase, DisksAndWallsAgainstClosedForms) {
  // Two disks: one contact, overlap r_a + r_b - distance, at the middle of the overlap.
  const ShapeGeometry disk = ShapeGeometry::Make({{0.0, 0.0}}, true, 1.0);
  std::vector<ContactPoint> out;
  CollideShapes(Place(disk, {0.0, 0.0}, 0.3, 0.2), Place(disk, {0.35, 0.0}, -1.0, 0.25), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].overlap_m, 0.10, 1e-15);
  EXPECT_NEAR(out[0].normal.x, -1.0, 1e-15);  // from B to A
  EXPECT_NEAR(out[0].point.x, 0.15, 1e-15);   // middle of [0.10, 0.20]
  // A capsule lying on a wall line touches at both ends.
  Vec2 origin;
  const ShapeGeometry wall = ShapeGeometry::FromWorld({{-5.0, 0.0}, {5.0, 0.0}}, false, 0.0, origin);
  const ShapeGeometry capsule = ShapeGeometry::Make({{-0.2, 0.0}, {0.2, 0.0}}, false, 0.1);
  out.clear();
  PlacedShape w;
  w.geometry = &wall;
  w.position = origin;
  CollideShapes(Place(capsule, {1.0, 0.09}, 0.0), w, out);
  ASSERT_EQ(out.size(), 2u);
  for (const ContactPoint& c : out) {
    EXPECT_NEAR(c.overlap_m, 0.01, 1e-15);
    EXPECT_NEAR(c.normal.y, 1.0, 1e-15);
    EXPECT_NEAR(c.point.y, -0.005, 1e-15);
  }
}

// The vertices of `from` in world coordinates.
std::vector<Vec2> WorldVertices(const PlacedShape& p) {
  std::vector<Vec2> out;
  for (const Vec2& v : p.geometry->vertices) {
    const Vec2 s = v * p.scale;
    out.push_back(p.position + Vec2{p.cos_angle * s.x - p.sin_angle * s.y, p.sin_angle * s.x + p.cos_angle * s.y});
  }
  return out;
}

// Distance from a point to a polyline or polygon (unsigned), by brute force.
double DistanceTo(Vec2 q, const std::vector<Vec2>& core, bool closed) {
  if (core.size() == 1) return Length(q - core[0]);
  double best = 1e300;
  const std::size_t edges = closed ? core.size() : core.size() - 1;
  for (std::size_t k = 0; k < edges; ++k) {
    const Vec2 a = core[k], b = core[(k + 1) % core.size()];
    const double t = std::clamp(Dot(q - a, b - a) / LengthSquared(b - a), 0.0, 1.0);
    best = std::min(best, Length(q - (a + (b - a) * t)));
  }
  return best;
}

TEST(NarrowPhase, ClearanceIsALowerBoundOnTheGapAndUseful) {
  // For pairs without contacts, the clearance is at most the exact gap
  // min over vertices of d(vertex, other core) - (r_A + r_B), and for most
  // pairs a good part of it (else skipping would gain nothing).
  ShapeGeometry body = ShapeGeometry::Make(ArmsOutline(), true, 0.05);
  body.BuildEdgeGrid(0.1);
  const ShapeGeometry disk = ShapeGeometry::Make({{0.0, 0.0}}, true, 0.1);
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::size_t apart = 0, tight = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const bool with_disk = trial % 4 == 3;
    const PlacedShape a = Place(body, {0.0, 0.0}, 3.2 * u(rng));
    const PlacedShape b = Place(with_disk ? disk : body, Vec2{0.6 * u(rng), 0.7 * u(rng)}, 3.2 * u(rng));
    std::vector<ContactPoint> out;
    const double clearance = CollideShapes(a, b, out);
    if (!out.empty()) {
      EXPECT_EQ(clearance, 0.0);
      continue;
    }
    const std::vector<Vec2> wa = WorldVertices(a), wb = WorldVertices(b);
    const double reach = a.geometry->radius_m + b.geometry->radius_m;
    double gap = 1e300;
    if (!with_disk)
      for (const Vec2& v : wa) gap = std::min(gap, DistanceTo(v, wb, true) - reach);
    for (const Vec2& v : wb) gap = std::min(gap, DistanceTo(v, wa, true) - reach);
    ASSERT_GE(clearance, 0.0) << "trial " << trial;
    ASSERT_LE(clearance, gap + 1e-12) << "trial " << trial;
    ++apart;
    tight += clearance > 0.3 * gap ? 1 : 0;
  }
  EXPECT_GT(apart, 5000u);
  EXPECT_GT(tight, apart * 7 / 10) << tight << " of " << apart;
}

TEST(NarrowPhase, RememberedClearancesGiveExactlyTheSameContacts) {
  // Two bodies wander into and out of contact in small random steps; a caller
  // keeps the pair's and the vertices' clearances between calls, bounding
  // each body's motion by |translation| + arm |rotation| as the engine does.
  // Every call must give the contacts of a call without memory, bit for bit,
  // while most pairs and vertices are skipped.
  ShapeGeometry body = ShapeGeometry::Make(ArmsOutline(), true, 0.05);
  body.BuildEdgeGrid(0.1);
  const double arm = body.core_radius_m * (1.0 + 1e-12);
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::size_t calls = 0, skipped = 0, touching = 0;
  for (int walk = 0; walk < 40; ++walk) {
    Vec2 xa{0.0, 0.0}, xb{0.45 + 0.1 * u(rng), 0.2 * u(rng)};
    double ta = 3.2 * u(rng), tb = 3.2 * u(rng);
    Vec2 va{0.4 * u(rng), 0.2 * u(rng)}, vb{-0.4 * std::abs(u(rng)), 0.2 * u(rng)};
    double wa = 2.0 * u(rng), wb = 2.0 * u(rng);
    double travel_a = 0.0, travel_b = 0.0, pair_clear = -1e300;
    std::vector<double> memory(2 * body.count(), -std::numeric_limits<double>::infinity());
    for (int step = 0; step < 1500; ++step) {
      // Random accelerations; steps of ~0.3 mm and ~0.5 mrad, like the engine's.
      const double h = 3e-4;
      va += Vec2{u(rng), u(rng)} * 0.05;
      vb += Vec2{u(rng), u(rng)} * 0.05;
      wa += 0.2 * u(rng);
      wb += 0.2 * u(rng);
      xa += va * h;
      xb += vb * h;
      ta += wa * h;
      tb += wb * h;
      travel_a += Length(va * h) + arm * std::abs(wa * h);
      travel_b += Length(vb * h) + arm * std::abs(wb * h);
      const PlacedShape a = Place(body, xa, ta), b = Place(body, xb, tb);
      std::vector<ContactPoint> expected, got;
      CollideShapes(a, b, expected);
      ++calls;
      const double moved = travel_a + travel_b;
      if (moved < pair_clear) {
        ++skipped;
        ASSERT_TRUE(expected.empty()) << "walk " << walk << " step " << step;
        continue;
      }
      const VertexClearances remembered{moved, memory.data(), memory.data() + body.count()};
      const double clearance = CollideShapes(a, b, got, &remembered);
      if (got.empty()) pair_clear = moved + clearance - kClearanceSlack_m;
      ASSERT_EQ(expected.size(), got.size()) << "walk " << walk << " step " << step;
      ExpectSameContacts(expected, got);
      touching += got.empty() ? 0 : 1;
    }
  }
  // The walks spend time both touching and apart, and the memory is used.
  EXPECT_GT(touching, calls / 10) << touching << " of " << calls;
  EXPECT_GT(skipped, calls / 10) << skipped << " of " << calls;
}

}  // namespace
}  // namespace crowdrecon::engine
