// Spheropolygon validation and exact mass properties of the swept shape.
//
// The boundary of the swept region (polygon + disk of radius r) is made of
// pieces of the edges' offset segments (each edge moved outward by r) and of
// arcs of radius r around convex vertices. We split every such candidate curve
// at its intersections with every other one; a piece then lies either wholly
// on the boundary or wholly inside the region, which its midpoint decides (on
// the boundary iff its distance to the polygon is r). Each candidate is
// oriented with the region on its left, so by Green's theorem the area, first
// moments and polar moment are the sums of closed-form integrals over the kept
// pieces, with no need to assemble them into rings: a segment contributes the
// polygon-edge integrals, an arc those of its chord plus the circular segment
// between chord and arc. Reflex vertices, strips overlapping there and gaps
// narrower than 2r (which the sweep closes, leaving holes) are all handled
// exactly; the only rounding is that of the intersection points.
#include "crowdrecon/geometry/spheropolygon.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::geometry {

namespace {

constexpr double kPi = std::numbers::pi;

std::string PointText(Vec2 p) { return "(" + FormatNumber(p.x) + ", " + FormatNumber(p.y) + ")"; }

// Accumulates integrals over a region: area, integral of x and y, integral of x^2 + y^2
// (all about the origin).
struct Moments {
  double area = 0, sx = 0, sy = 0, j0 = 0;

  // Green's-theorem contribution of the directed segment p -> q.
  void AddSegment(Vec2 p, Vec2 q) {
    const double cross = Cross(p, q);
    area += cross / 2.0;
    sx += (p.x + q.x) * cross / 6.0;
    sy += (p.y + q.y) * cross / 6.0;
    j0 += (p.x * p.x + p.x * q.x + q.x * q.x + p.y * p.y + p.y * q.y + q.y * q.y) * cross / 12.0;
  }

  // Adds `sign` times the circular segment of radius R with centre c cut off by a
  // chord subtending the angle theta, whose bisector points along `bisector`.
  void AddCircularSegment(Vec2 c, double radius, double theta, Vec2 bisector, double sign) {
    const double r2 = radius * radius;
    const double a = r2 / 2.0 * (theta - std::sin(theta));
    // First moment about the centre along the bisector: a * d with
    // d = 4 R sin^3(theta/2) / (3 (theta - sin theta)), written without the division.
    const double half_sin = std::sin(theta / 2.0);
    const double first = 2.0 / 3.0 * r2 * radius * half_sin * half_sin * half_sin;
    // Polar moment about the centre: sector R^4 theta / 4 minus the triangle
    // R^4 sin(theta) (2 + cos(theta)) / 12.
    const double j_centre =
        r2 * r2 * (3.0 * theta - std::sin(theta) * (2.0 + std::cos(theta))) / 12.0;
    const Vec2 m1 = c * a + bisector * first;  // first moment about the origin
    area += sign * a;
    sx += sign * m1.x;
    sy += sign * m1.y;
    j0 += sign * (j_centre + a * LengthSquared(c) + 2.0 * Dot(c, bisector * first));
  }

  void Add(const Moments& o, double sign) {
    area += sign * o.area;
    sx += sign * o.sx;
    sy += sign * o.sy;
    j0 += sign * o.j0;
  }

  AreaProperties ToProperties() const {
    AreaProperties p;
    p.area_m2 = area;
    p.centroid_m = {sx / area, sy / area};
    p.polar_moment_m4 = j0 - area * LengthSquared(p.centroid_m);
    return p;
  }
};

// Signed distance from p to a closed polygon (negative inside; even-odd rule).
double SignedDistanceToPolygon(const std::vector<Vec2>& v, Vec2 p) {
  const std::size_t n = v.size();
  double d = std::numeric_limits<double>::infinity();
  bool inside = false;
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2 a = v[i], b = v[j];
    d = std::min(d, DistanceToSegment(p, a, b));
    if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x)
      inside = !inside;
  }
  return inside ? -d : d;
}

// A candidate boundary curve of the swept region: an offset segment p0 -> p1,
// or an arc of radius r about `centre` from angle `start` sweeping `sweep`
// counter-clockwise. Split parameters are in [0, 1] along the curve.
struct Candidate {
  bool is_arc = false;
  Vec2 p0, p1;                            // segment
  Vec2 centre;                            // arc
  double start = 0.0, sweep = 0.0;        // arc, radians
  std::vector<double> splits;

  Vec2 At(double u, double r) const {
    if (!is_arc) return p0 + (p1 - p0) * u;
    const double a = start + sweep * u;
    return centre + Vec2{std::cos(a), std::sin(a)} * r;
  }
  // Parameter of a point known to lie on the arc's circle, or -1 if outside the arc.
  double ArcParameter(Vec2 p) const {
    double t = std::atan2(p.y - centre.y, p.x - centre.x) - start;
    while (t < 0.0) t += 2.0 * kPi;
    while (t >= 2.0 * kPi) t -= 2.0 * kPi;
    return t <= sweep ? t / sweep : -1.0;
  }
};

// Points where the line p0 + s (p1 - p0) meets the circle |x - c| = r, s in [0, 1].
void LineCircle(Vec2 p0, Vec2 p1, Vec2 c, double r, std::vector<std::pair<double, Vec2>>& out) {
  const Vec2 d = p1 - p0, f = p0 - c;
  const double a = Dot(d, d), b = 2.0 * Dot(f, d), cc = Dot(f, f) - r * r;
  const double disc = b * b - 4.0 * a * cc;
  if (disc < 0.0) return;
  const double root = std::sqrt(disc);
  for (const double s : {(-b - root) / (2.0 * a), (-b + root) / (2.0 * a)})
    if (s >= 0.0 && s <= 1.0) out.emplace_back(s, p0 + d * s);
}

void Intersect(Candidate& a, Candidate& b, double r) {
  if (!a.is_arc && !b.is_arc) {
    const Vec2 da = a.p1 - a.p0, db = b.p1 - b.p0;
    const double denom = Cross(da, db);
    if (denom == 0.0) return;  // parallel: collinear offsets never overlap for simple polygons
    const Vec2 w = b.p0 - a.p0;
    const double s = Cross(w, db) / denom, t = Cross(w, da) / denom;
    if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0) {
      a.splits.push_back(s);
      b.splits.push_back(t);
    }
    return;
  }
  if (a.is_arc && !b.is_arc) return Intersect(b, a, r);
  std::vector<std::pair<double, Vec2>> hits;  // (parameter on a, point)
  if (!a.is_arc) {
    LineCircle(a.p0, a.p1, b.centre, r, hits);
  } else {
    const Vec2 d = b.centre - a.centre;
    const double dist = Length(d);
    if (dist == 0.0 || dist > 2.0 * r) return;
    const Vec2 mid = a.centre + d / 2.0;
    const double h = std::sqrt(std::max(0.0, r * r - dist * dist / 4.0));
    const Vec2 off = Perp(d / dist) * h;
    for (const Vec2 p : {mid + off, mid - off}) {
      const double u = a.ArcParameter(p);
      if (u >= 0.0) hits.emplace_back(u, p);
    }
  }
  for (const auto& [u, p] : hits) {
    const double t = b.ArcParameter(p);
    if (t < 0.0) continue;
    a.splits.push_back(u);
    b.splits.push_back(t);
  }
}

AreaProperties PolygonSweptProperties(const std::vector<Vec2>& v, double r) {
  const std::size_t n = v.size();
  std::vector<Candidate> curves;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = v[i], b = v[(i + 1) % n];
    const Vec2 normal = Normalized(Vec2{(b - a).y, -(b - a).x});  // outward (CCW polygon)
    Candidate seg;
    seg.p0 = a + normal * r;
    seg.p1 = b + normal * r;
    curves.push_back(seg);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 d_in = v[i] - v[(i + n - 1) % n], d_out = v[(i + 1) % n] - v[i];
    const double turn = std::atan2(Cross(d_in, d_out), Dot(d_in, d_out));  // exterior angle
    if (turn <= 0.0) continue;  // reflex or straight: no exposed arc
    Candidate arc;
    arc.is_arc = true;
    arc.centre = v[i];
    arc.start = std::atan2(-d_in.x, d_in.y);  // angle of the incoming edge's outward normal
    arc.sweep = turn;
    curves.push_back(arc);
  }
  for (std::size_t i = 0; i < curves.size(); ++i)
    for (std::size_t j = i + 1; j < curves.size(); ++j) Intersect(curves[i], curves[j], r);

  double extent = r;
  for (const Vec2& p : v) extent = std::max({extent, std::abs(p.x), std::abs(p.y)});
  const double tolerance = 1e-9 * extent;
  Moments m;
  for (Candidate& c : curves) {
    c.splits.push_back(0.0);
    c.splits.push_back(1.0);
    std::sort(c.splits.begin(), c.splits.end());
    for (std::size_t k = 0; k + 1 < c.splits.size(); ++k) {
      const double u0 = c.splits[k], u1 = c.splits[k + 1];
      if (u1 - u0 <= 1e-15) continue;
      if (SignedDistanceToPolygon(v, c.At((u0 + u1) / 2.0, r)) < r - tolerance) continue;
      const Vec2 p = c.At(u0, r), q = c.At(u1, r);
      m.AddSegment(p, q);
      if (c.is_arc) {
        const double theta = c.sweep * (u1 - u0);
        const double mid = c.start + c.sweep * (u0 + u1) / 2.0;
        m.AddCircularSegment(c.centre, r, theta, {std::cos(mid), std::sin(mid)}, 1.0);
      }
    }
  }
  return m.ToProperties();
}

int Orientation(Vec2 a, Vec2 b, Vec2 c) {
  const double o = Cross(b - a, c - a);
  return o > 0 ? 1 : (o < 0 ? -1 : 0);
}

bool OnSegment(Vec2 p, Vec2 a, Vec2 b) {
  return std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
         p.y <= std::max(a.y, b.y);
}

bool SegmentsIntersect(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const int o1 = Orientation(a, b, c), o2 = Orientation(a, b, d);
  const int o3 = Orientation(c, d, a), o4 = Orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  if (o1 == 0 && OnSegment(c, a, b)) return true;
  if (o2 == 0 && OnSegment(d, a, b)) return true;
  if (o3 == 0 && OnSegment(a, c, d)) return true;
  if (o4 == 0 && OnSegment(b, c, d)) return true;
  return false;
}

// True if every vertex lies within `tolerance` of the line through the first
// vertex and the vertex farthest from it.
bool AllCollinear(const std::vector<Vec2>& v, double tolerance) {
  std::size_t far = 0;
  for (std::size_t i = 1; i < v.size(); ++i)
    if (LengthSquared(v[i] - v[0]) > LengthSquared(v[far] - v[0])) far = i;
  const Vec2 d = v[far] - v[0];
  const double length = Length(d);
  if (length == 0.0) return true;
  return std::all_of(v.begin(), v.end(), [&](Vec2 p) { return std::abs(Cross(d, p - v[0])) / length <= tolerance; });
}

void ValidatePolygon(const std::vector<Vec2>& v, const std::string& what) {
  const std::size_t n = v.size();
  double extent = 0.0;
  for (const Vec2& p : v) extent = std::max({extent, std::abs(p.x), std::abs(p.y)});
  const double tiny = 1e-12 * std::max(extent, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = v[i], b = v[(i + 1) % n];
    if (Length(b - a) <= tiny)
      throw GeometryError(what + ": vertex " + std::to_string((i + 1) % n) + " " + PointText(b) +
                          " repeats vertex " + std::to_string(i) +
                          "; consecutive vertices must be distinct");
  }
  // Zero area is either a degenerate polygon (every vertex on one line) or one
  // whose parts cancel (a bow tie): the second is a self-intersection, named
  // by the check below.
  const double area = SignedArea(v);
  const bool zero_area = std::abs(area) <= tiny * std::max(extent, 1.0);
  if (zero_area && AllCollinear(v, tiny))
    throw GeometryError(what + ": the polygon has zero area (all vertices collinear)");
  // Simple: no two non-adjacent edges meet; adjacent edges meet only at their
  // shared vertex (no fold-back).
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = v[i], b = v[(i + 1) % n];
    for (std::size_t j = i + 1; j < n; ++j) {
      const Vec2 c = v[j], d = v[(j + 1) % n];
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      if (adjacent) {
        // Shared vertex: b == c (j == i+1) or a == d (wrap). A fold-back puts the
        // other endpoint on the first edge.
        const Vec2 shared = (j == i + 1) ? b : a;
        const Vec2 other_i = (j == i + 1) ? a : b;
        const Vec2 other_j = (j == i + 1) ? d : c;
        if (Orientation(other_i, shared, other_j) == 0 &&
            Dot(other_i - shared, other_j - shared) > 0)
          throw GeometryError(what + ": edges " + std::to_string(i) + " and " + std::to_string(j) +
                              " fold back onto each other at " + PointText(shared) +
                              "; the polygon must be simple");
        continue;
      }
      if (SegmentsIntersect(a, b, c, d))
        throw GeometryError(what + ": edges " + std::to_string(i) + " " + PointText(a) + "-" +
                            PointText(b) + " and " + std::to_string(j) + " " + PointText(c) + "-" +
                            PointText(d) + " intersect; the polygon must be simple");
    }
  }
  if (zero_area) throw GeometryError(what + ": the polygon has zero area; expected a polygon enclosing some area");
  if (area < 0)
    throw GeometryError(what + ": vertices are clockwise (signed area " + FormatNumber(area) +
                        " m^2); give them counter-clockwise");
}

}  // namespace

double SignedArea(const std::vector<Vec2>& polygon) {
  double twice = 0.0;
  for (std::size_t i = 0, n = polygon.size(); i < n; ++i)
    twice += Cross(polygon[i], polygon[(i + 1) % n]);
  return twice / 2.0;
}

AreaProperties PolygonProperties(const std::vector<Vec2>& polygon) {
  Moments m;
  for (std::size_t i = 0, n = polygon.size(); i < n; ++i) m.AddSegment(polygon[i], polygon[(i + 1) % n]);
  if (m.area < 0) m.Add(Moments(m), -2.0);  // clockwise input: flip the sign of every integral
  return m.ToProperties();
}

AreaProperties DiskProperties(double radius_m) {
  AreaProperties p;
  p.area_m2 = kPi * radius_m * radius_m;
  p.polar_moment_m4 = kPi * std::pow(radius_m, 4) / 2.0;
  return p;
}

AreaProperties CapsuleProperties(double length_m, double radius_m) {
  const double r = radius_m, l = length_m;
  AreaProperties p;
  p.area_m2 = 2.0 * r * l + kPi * r * r;
  // Rectangle 2r x l plus two half disks whose flat sides sit at +-l/2.
  p.polar_moment_m4 =
      kPi * std::pow(r, 4) / 2.0 + kPi * r * r * l * l / 4.0 + 2.0 * r * r * r * l + r * l * l * l / 6.0;
  return p;
}

Spheropolygon Spheropolygon::Create(std::vector<Vec2> vertices, double radius_m,
                                    const std::string& what) {
  if (vertices.empty()) throw GeometryError(what + ": no vertices; expected at least one");
  if (!std::isfinite(radius_m) || radius_m <= 0.0)
    throw GeometryError(what + ": sphero-radius " + FormatNumber(radius_m) +
                        " m is invalid; expected a finite radius > 0");
  for (std::size_t i = 0; i < vertices.size(); ++i)
    if (!std::isfinite(vertices[i].x) || !std::isfinite(vertices[i].y))
      throw GeometryError(what + ": vertex " + std::to_string(i) + " is not finite");

  AreaProperties props;
  if (vertices.size() == 1) {
    props = DiskProperties(radius_m);
    props.centroid_m = vertices[0];
  } else if (vertices.size() == 2) {
    const double length = Length(vertices[1] - vertices[0]);
    if (length <= 1e-12 * std::max(1.0, Length(vertices[0])))
      throw GeometryError(what + ": the two vertices of the capsule coincide at " +
                          PointText(vertices[0]) + "; use one vertex for a disk");
    props = CapsuleProperties(length, radius_m);
    props.centroid_m = (vertices[0] + vertices[1]) / 2.0;
  } else {
    ValidatePolygon(vertices, what);
    props = PolygonSweptProperties(vertices, radius_m);
  }
  return Spheropolygon(std::move(vertices), radius_m, props);
}

double Spheropolygon::CorePolygonArea() const {
  return vertices_.size() >= 3 ? SignedArea(vertices_) : 0.0;
}

double Spheropolygon::CorePerimeter() const {
  if (vertices_.size() < 2) return 0.0;
  if (vertices_.size() == 2) return 2.0 * Length(vertices_[1] - vertices_[0]);
  double p = 0.0;
  for (std::size_t i = 0, n = vertices_.size(); i < n; ++i)
    p += Length(vertices_[(i + 1) % n] - vertices_[i]);
  return p;
}

Spheropolygon Spheropolygon::Translated(Vec2 offset) const {
  std::vector<Vec2> v = vertices_;
  for (Vec2& p : v) p += offset;
  AreaProperties props = properties_;
  props.centroid_m += offset;
  return Spheropolygon(std::move(v), radius_, props);
}

Spheropolygon Spheropolygon::Centered() const { return Translated(-properties_.centroid_m); }

Spheropolygon Spheropolygon::Scaled(double s) const {
  if (!(s > 0.0) || !std::isfinite(s))
    throw GeometryError("spheropolygon: scale factor " + FormatNumber(s) +
                        " is invalid; expected a finite factor > 0");
  std::vector<Vec2> v = vertices_;
  for (Vec2& p : v) p *= s;
  AreaProperties props = properties_;
  props.area_m2 *= s * s;
  props.centroid_m *= s;
  props.polar_moment_m4 *= s * s * s * s;
  return Spheropolygon(std::move(v), radius_ * s, props);
}

Spheropolygon Spheropolygon::Rotated(double angle_rad) const {
  std::vector<Vec2> v = vertices_;
  for (Vec2& p : v) p = crowdrecon::Rotated(p, angle_rad);
  AreaProperties props = properties_;
  props.centroid_m = crowdrecon::Rotated(props.centroid_m, angle_rad);
  return Spheropolygon(std::move(v), radius_, props);
}

Vec2 Spheropolygon::BoundsMin() const {
  Vec2 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  for (const Vec2& p : vertices_) lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
  return lo - Vec2{radius_, radius_};
}

Vec2 Spheropolygon::BoundsMax() const {
  Vec2 hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const Vec2& p : vertices_) hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  return hi + Vec2{radius_, radius_};
}

double Spheropolygon::SignedDistanceToCore(Vec2 p) const {
  const std::size_t n = vertices_.size();
  if (n == 1) return Length(p - vertices_[0]);
  if (n == 2) return DistanceToSegment(p, vertices_[0], vertices_[1]);
  return SignedDistanceToPolygon(vertices_, p);
}

double Spheropolygon::DistanceToBoundary(Vec2 p) const {
  return std::abs(SignedDistanceToCore(p) - radius_);
}

std::vector<Vec2> Spheropolygon::SampleBoundary(double spacing_m) const {
  if (!(spacing_m > 0.0)) throw GeometryError("spheropolygon: sampling spacing must be > 0");
  std::vector<Vec2> candidates;
  const auto add_arc = [&](Vec2 c, double from, double sweep) {
    const int steps = std::max(1, static_cast<int>(std::ceil(std::abs(sweep) * radius_ / spacing_m)));
    for (int k = 0; k <= steps; ++k) {
      const double a = from + sweep * k / steps;
      candidates.push_back(c + Vec2{std::cos(a), std::sin(a)} * radius_);
    }
  };
  const auto add_edge = [&](Vec2 a, Vec2 b) {
    const Vec2 d = b - a;
    const Vec2 normal = Normalized(Vec2{d.y, -d.x});  // outward for a CCW polygon
    const int steps = std::max(1, static_cast<int>(std::ceil(Length(d) / spacing_m)));
    for (int k = 0; k <= steps; ++k) candidates.push_back(a + d * (double(k) / steps) + normal * radius_);
  };
  const std::size_t n = vertices_.size();
  if (n == 1) {
    add_arc(vertices_[0], 0.0, 2.0 * kPi);
    return candidates;
  }
  if (n == 2) {
    add_edge(vertices_[0], vertices_[1]);
    add_edge(vertices_[1], vertices_[0]);
  } else {
    for (std::size_t i = 0; i < n; ++i) add_edge(vertices_[i], vertices_[(i + 1) % n]);
  }
  // Vertex arcs from the outward normal of the incoming edge to that of the
  // outgoing edge (convex turns only; reflex vertices have no exposed arc).
  const std::size_t m = n == 2 ? 2 : n;
  for (std::size_t i = 0; i < m; ++i) {
    const Vec2 prev = n == 2 ? vertices_[1 - i] : vertices_[(i + n - 1) % n];
    const Vec2 cur = vertices_[i];
    const Vec2 next = n == 2 ? vertices_[1 - i] : vertices_[(i + 1) % n];
    const Vec2 d_in = cur - prev, d_out = next - cur;
    const double a_in = std::atan2(-d_in.x, d_in.y);  // angle of (d.y, -d.x)
    const double a_out = std::atan2(-d_out.x, d_out.y);
    // For a CCW polygon the outward normal turns counter-clockwise at a convex
    // vertex: sweep from a_in to a_out counter-clockwise.
    double sweep = a_out - a_in;
    while (sweep < 0) sweep += 2.0 * kPi;
    while (sweep >= 2.0 * kPi) sweep -= 2.0 * kPi;
    if (n == 2) sweep = kPi;
    if (sweep > kPi + 1e-12) continue;  // reflex vertex
    add_arc(cur, a_in, sweep);
  }
  // Drop points hidden inside the swept shape (strips overlapping at reflex
  // vertices or across narrow gaps).
  std::vector<Vec2> boundary;
  const double tolerance = 1e-9 * std::max(radius_, 1e-3);
  for (const Vec2& p : candidates)
    if (SignedDistanceToCore(p) >= radius_ - tolerance) boundary.push_back(p);
  return boundary;
}

}  // namespace crowdrecon::geometry
