// Mass properties of swept shapes against closed forms and independent checks.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/spheropolygon.hpp"

namespace crowdrecon::geometry {
namespace {

constexpr double kPi = std::numbers::pi;

void ExpectRelative(double actual, double expected, double tolerance, const char* what) {
  EXPECT_LE(std::abs(actual - expected), tolerance * std::abs(expected))
      << what << ": actual " << actual << " expected " << expected;
}

TEST(Spheropolygon, DiskMatchesClosedForm) {
  const double r = 0.23;
  const auto s = Spheropolygon::Create({{1.5, -2.0}}, r);
  ExpectRelative(s.area(), kPi * r * r, 1e-12, "area");
  EXPECT_EQ(s.centroid(), Vec2(1.5, -2.0));
  ExpectRelative(s.polar_moment(), kPi * std::pow(r, 4) / 2, 1e-12, "J");
}

TEST(Spheropolygon, CapsuleMatchesClosedForm) {
  const double r = 0.1, l = 0.4;
  const auto s = Spheropolygon::Create({{0.0, 0.0}, {l * std::cos(0.3), l * std::sin(0.3)}}, r);
  ExpectRelative(s.area(), 2 * r * l + kPi * r * r, 1e-12, "area");
  ExpectRelative(s.centroid().x, l * std::cos(0.3) / 2, 1e-12, "cx");
  ExpectRelative(s.centroid().y, l * std::sin(0.3) / 2, 1e-12, "cy");
  // Independent: rectangle 2r x l plus a full disk split into two half disks
  // whose centroids lie 4r/(3 pi) beyond the segment ends.
  const double rect = 2 * r * l * (l * l + 4 * r * r) / 12;
  const double half_area = kPi * r * r / 2, e = 4 * r / (3 * kPi);
  const double half_own = kPi * std::pow(r, 4) / 4 - half_area * e * e;  // about its centroid
  const double halves = 2 * (half_own + half_area * std::pow(l / 2 + e, 2));
  ExpectRelative(s.polar_moment(), rect + halves, 1e-12, "J");
}

TEST(Spheropolygon, RectangleCorePropertiesMatchClosedForm) {
  const double w = 0.45, h = 0.25;
  const auto p = PolygonProperties({{0, 0}, {w, 0}, {w, h}, {0, h}});
  ExpectRelative(p.area_m2, w * h, 1e-12, "area");
  ExpectRelative(p.centroid_m.x, w / 2, 1e-12, "cx");
  ExpectRelative(p.centroid_m.y, h / 2, 1e-12, "cy");
  ExpectRelative(p.polar_moment_m4, w * h * (w * w + h * h) / 12, 1e-12, "J");
  // Clockwise input gives the same properties.
  const auto q = PolygonProperties({{0, h}, {w, h}, {w, 0}, {0, 0}});
  ExpectRelative(q.area_m2, w * h, 1e-12, "area cw");
  ExpectRelative(q.polar_moment_m4, w * h * (w * w + h * h) / 12, 1e-12, "J cw");
}

TEST(Spheropolygon, RoundedRectangleMatchesClosedForm) {
  const double w = 0.35, h = 0.15, r = 0.05;
  const Vec2 c{0.7, 0.2};
  const auto s = Spheropolygon::Create(
      {{c.x - w / 2, c.y - h / 2}, {c.x + w / 2, c.y - h / 2}, {c.x + w / 2, c.y + h / 2},
       {c.x - w / 2, c.y + h / 2}},
      r);
  ExpectRelative(s.area(), w * h + 2 * r * (w + h) + kPi * r * r, 1e-12, "area");
  ExpectRelative(s.centroid().x, c.x, 1e-12, "cx");
  ExpectRelative(s.centroid().y, c.y, 1e-12, "cy");
  // Core + four edge strips + four quarter disks, about the centre.
  const auto strip = [](double len, double width, double dist) {
    return len * width * (len * len + width * width) / 12 + len * width * dist * dist;
  };
  const double quarter_area = kPi * r * r / 4;
  const double quarter =  // about the centre: own J about the corner + shift terms
      kPi * std::pow(r, 4) / 8 + quarter_area * (w * w + h * h) / 4 + 2 * (r * r * r / 3) * (w / 2 + h / 2);
  const double expected = w * h * (w * w + h * h) / 12 + 2 * strip(w, r, h / 2 + r / 2) +
                          2 * strip(h, r, w / 2 + r / 2) + 4 * quarter;
  ExpectRelative(s.polar_moment(), expected, 1e-12, "J");
}

TEST(Spheropolygon, ReflexVertexOverlapIsCountedOnce) {
  // L-shape with one reflex vertex of turning angle pi/2: the two edge strips
  // overlap in an r x r square that the naive sum counts twice, and the
  // exterior-angle sum adds a quarter disk too many: A = A_P + P r + pi r^2 +
  // (phi/2 - tan(phi/2)) r^2 with phi = pi/2.
  const double r = 0.05;
  const std::vector<Vec2> l_shape{{0, 0}, {1, 0}, {1, 0.4}, {0.4, 0.4}, {0.4, 1}, {0, 1}};
  const auto s = Spheropolygon::Create(l_shape, r);
  const double a_p = 1.0 * 0.4 + 0.4 * 0.6, perimeter = 4.0;
  ExpectRelative(s.area(), a_p + perimeter * r + kPi * r * r + (kPi / 4 - 1) * r * r, 1e-12, "area");
}

// Integrates the indicator of the swept shape on a fine grid (midpoint rule).
AreaProperties GridProperties(const Spheropolygon& s, double h) {
  const Vec2 lo = s.BoundsMin(), hi = s.BoundsMax();
  double a = 0, sx = 0, sy = 0, j0 = 0;
  for (double x = lo.x + h / 2; x < hi.x; x += h)
    for (double y = lo.y + h / 2; y < hi.y; y += h)
      if (s.SignedDistanceToCore({x, y}) <= s.radius()) {
        a += h * h;
        sx += x * h * h;
        sy += y * h * h;
        j0 += (x * x + y * y) * h * h;
      }
  AreaProperties p;
  p.area_m2 = a;
  p.centroid_m = {sx / a, sy / a};
  p.polar_moment_m4 = j0 - a * LengthSquared(p.centroid_m);
  return p;
}

TEST(Spheropolygon, NarrowGapFilledBySweepAgreesWithGridIntegration) {
  // A U whose slot (0.06 m) is narrower than 2r (0.1 m): the swept shape closes
  // the slot's mouth, leaving a hole. Exact offset must agree with a fine grid.
  const std::vector<Vec2> u{{0, 0}, {0.5, 0}, {0.5, 0.5}, {0.28, 0.5}, {0.28, 0.1},
                            {0.22, 0.1}, {0.22, 0.5}, {0, 0.5}};
  const auto s = Spheropolygon::Create(u, 0.05);
  const auto grid = GridProperties(s, 0.0005);
  ExpectRelative(s.area(), grid.area_m2, 2e-4, "area");
  ExpectRelative(s.centroid().y, grid.centroid_m.y, 2e-4, "cy");
  ExpectRelative(s.polar_moment(), grid.polar_moment_m4, 5e-4, "J");
  // The naive strip + sector sum would count the filled slot wrongly.
  const double naive = s.CorePolygonArea() + s.CorePerimeter() * 0.05 + kPi * 0.0025;
  EXPECT_GT(std::abs(naive - s.area()), 1e-3);
}

TEST(Spheropolygon, TransformsActOnMassProperties) {
  const std::vector<Vec2> v{{0, 0}, {0.3, -0.05}, {0.42, 0.1}, {0.2, 0.3}, {0.05, 0.12}};
  const auto s = Spheropolygon::Create(v, 0.04);
  const auto moved = s.Rotated(0.7).Translated({3, -1});
  // Rebuilt from the transformed vertices, the exact properties agree.
  const auto rebuilt = Spheropolygon::Create(moved.vertices(), 0.04);
  ExpectRelative(rebuilt.area(), s.area(), 1e-12, "area");
  ExpectRelative(rebuilt.polar_moment(), s.polar_moment(), 1e-11, "J");
  EXPECT_NEAR(rebuilt.centroid().x, moved.centroid().x, 1e-12);
  EXPECT_NEAR(rebuilt.centroid().y, moved.centroid().y, 1e-12);
  const auto scaled = s.Scaled(1.3);
  const auto rebuilt_scaled = Spheropolygon::Create(scaled.vertices(), 0.04 * 1.3);
  ExpectRelative(rebuilt_scaled.area(), scaled.area(), 1e-12, "scaled area");
  ExpectRelative(rebuilt_scaled.polar_moment(), scaled.polar_moment(), 1e-11, "scaled J");
  EXPECT_NEAR(s.Centered().centroid().x, 0.0, 1e-15);
}

TEST(Spheropolygon, BoundarySamplesLieOnTheSweptBoundary) {
  const std::vector<Vec2> l_shape{{0, 0}, {1, 0}, {1, 0.4}, {0.4, 0.4}, {0.4, 1}, {0, 1}};
  const auto s = Spheropolygon::Create(l_shape, 0.05);
  const auto samples = s.SampleBoundary(0.005);
  ASSERT_GT(samples.size(), 800u);
  for (const Vec2& p : samples) EXPECT_LT(s.DistanceToBoundary(p), 1e-9);
}

std::string ErrorOf(std::vector<Vec2> v, double r) {
  try {
    Spheropolygon::Create(std::move(v), r, "body 'test'");
  } catch (const GeometryError& e) {
    return e.what();
  }
  return "";
}

TEST(Spheropolygon, InvalidInputsAreRejectedWithReasons) {
  EXPECT_NE(ErrorOf({}, 0.05).find("no vertices"), std::string::npos);
  EXPECT_NE(ErrorOf({{0, 0}}, -0.05).find("sphero-radius -0.05"), std::string::npos);
  EXPECT_NE(ErrorOf({{0, 0}}, 0.0).find("expected a finite radius > 0"), std::string::npos);
  EXPECT_NE(ErrorOf({{0, 0}, {0, 0}}, 0.05).find("coincide"), std::string::npos);
  EXPECT_NE(ErrorOf({{0, 0}, {1, 0}, {1, 0}, {0, 1}}, 0.05).find("repeats vertex"), std::string::npos);
  EXPECT_NE(ErrorOf({{0, 0}, {2, 2}, {2, 0}, {0, 1}}, 0.05).find("intersect"), std::string::npos);
  EXPECT_NE(ErrorOf({{0, 0}, {0, 1}, {1, 1}, {1, 0}}, 0.05).find("clockwise"), std::string::npos);
  EXPECT_NE(ErrorOf({{0, 0}, {1, 0}, {2, 0}}, 0.05).find("zero area"), std::string::npos);
  EXPECT_NE(ErrorOf({{0, 0}, {NAN, 0}, {0, 1}}, 0.05).find("not finite"), std::string::npos);
  EXPECT_NE(ErrorOf({{0, 0}, {1, 0}, {0.5, 0}, {0.5, 1}}, 0.05).find("body 'test'"), std::string::npos);
}

}  // namespace
}  // namespace crowdrecon::geometry
