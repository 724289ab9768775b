// Validation of a venue's geometry. CGAL's exact predicates (Epick kernel)
// decide simplicity, crossings and containment, so that touching rings and
// collinear overlaps are found whatever the rounding of the coordinates.
// Problems are collected (not thrown one at a time) so that a user fixing a
// floor plan sees all of them at once.
// GCC's -Wnull-dereference fires inside CGAL's inlined triangulation and
// container code after optimisation, where the system-header exemption no
// longer applies (CGAL's own sentinels); silence it for this file only.
#pragma GCC diagnostic ignored "-Wnull-dereference"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/intersections.h>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "box_pairs.hpp"

namespace crowdrecon::geometry {

namespace {

using detail::BoundsOf;
using detail::Box;
using detail::EdgeBoxes;
using detail::OverlappingPairs;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_2;
using Segment = Kernel::Segment_2;

Point ToCgal(Vec2 p) { return {p.x, p.y}; }

std::string PointText(Vec2 p) { return "(" + FormatNumber(p.x) + ", " + FormatNumber(p.y) + ")"; }

// A point of the intersection of two segments, for messages. (CGAL 5.5
// returns boost::optional<boost::variant<...>>; CGAL 6 moves to std::.)
Vec2 IntersectionPoint(const Segment& s, const Segment& t) {
  const auto result = CGAL::intersection(s, t);
  if (result) {
    if (const Point* p = boost::get<Point>(&*result)) return {p->x(), p->y()};
    if (const Segment* q = boost::get<Segment>(&*result)) return {q->source().x(), q->source().y()};
  }
  return {s.source().x(), s.source().y()};
}

Segment Edge(const Ring& ring, std::size_t i) {
  return {ToCgal(ring[i]), ToCgal(ring[(i + 1) % ring.size()])};
}

// First place where the boundaries of two rings meet (cross or touch).
std::optional<Vec2> RingsMeet(const Ring& a, const Ring& b) {
  if (!BoundsOf(a).Overlaps(BoundsOf(b))) return std::nullopt;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Segment s = Edge(a, i);
    for (std::size_t j = 0; j < b.size(); ++j) {
      const Segment t = Edge(b, j);
      if (CGAL::do_intersect(s, t)) return IntersectionPoint(s, t);
    }
  }
  return std::nullopt;
}

// The first vertex i (and the next j > i at the same place) that the ring
// repeats, found by sorting (a plan's ring may have 1e5 vertices).
std::optional<std::pair<std::size_t, std::size_t>> FirstRepeatedVertex(const Ring& ring) {
  std::vector<std::size_t> order(ring.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const auto key = [&](std::size_t i) { return std::make_tuple(ring[i].x, ring[i].y, i); };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
  std::optional<std::pair<std::size_t, std::size_t>> first;
  for (std::size_t k = 0; k + 1 < order.size(); ++k)
    if (ring[order[k]] == ring[order[k + 1]] && (!first || order[k] < first->first))
      first = std::make_pair(order[k], order[k + 1]);
  return first;
}

// The pairs (i < j) of rings whose bounding boxes overlap: only these can
// meet or nest (a plan of 10000 pillars has 5e7 pairs, of which a few
// thousand are neighbours).
std::vector<std::pair<std::size_t, std::size_t>> OverlappingRings(const std::vector<Ring>& rings) {
  std::vector<Box> boxes;
  boxes.reserve(rings.size());
  for (const Ring& r : rings) boxes.push_back(r.empty() ? Box{} : BoundsOf(r));
  return OverlappingPairs(boxes);
}

// Strictly inside (a ring's interior, by exact predicate).
bool StrictlyInside(const Ring& ring, Vec2 p) {
  std::vector<Point> pts;
  pts.reserve(ring.size());
  for (Vec2 q : ring) pts.push_back(ToCgal(q));
  return CGAL::bounded_side_2(pts.begin(), pts.end(), ToCgal(p), Kernel()) == CGAL::ON_BOUNDED_SIDE;
}

class Checker {
 public:
  explicit Checker(const Venue& v) : v_(v) {}

  std::vector<std::string> Run() {
    // Everything below squares coordinates: refuse absurd ones first.
    if (!CheckCoordinates()) return problems_;
    CheckIds();
    std::vector<bool> outer_ok, obstacle_ok;
    for (std::size_t i = 0; i < v_.walkable_area.size(); ++i)
      outer_ok.push_back(CheckRing(v_.walkable_area[i], "/walkable_area/" + Index(i), "outer ring"));
    for (std::size_t i = 0; i < v_.obstacles.size(); ++i)
      obstacle_ok.push_back(CheckRing(v_.obstacles[i].polygon, ObstaclePath(i), "obstacle"));
    CheckAreaLayout(outer_ok, obstacle_ok);
    const bool area_ok = std::all_of(outer_ok.begin(), outer_ok.end(), [](bool b) { return b; });
    if (area_ok && WalkableArea_m2(v_) <= 1e-9)
      Problem("/walkable_area", "the walkable area is empty (area " + FormatNumber(WalkableArea_m2(v_)) +
                                    " m^2); expected a positive area");
    CheckWalls();
    // Placement checks need a sound walkable area to measure against.
    if (!area_ok) return problems_;
    for (std::size_t i = 0; i < v_.exits.size(); ++i)
      CheckSegmentInArea(v_.exits[i].a, v_.exits[i].b, "/exits/" + Index(i) + "/segment", "exit");
    for (std::size_t i = 0; i < v_.entries.size(); ++i)
      CheckZone(v_.entries[i].polygon, "/entries/" + Index(i) + "/polygon", "entry zone");
    for (std::size_t i = 0; i < v_.measurement_areas.size(); ++i)
      CheckZone(v_.measurement_areas[i].polygon, "/measurement_areas/" + Index(i) + "/polygon",
                "measurement area");
    for (std::size_t i = 0; i < v_.measurement_lines.size(); ++i)
      CheckSegmentInArea(v_.measurement_lines[i].a, v_.measurement_lines[i].b,
                         "/measurement_lines/" + Index(i) + "/segment", "measurement line");
    CheckTargets();
    CheckPeriodic();
    CheckSlopeRegion();
    return problems_;
  }

 private:
  static std::string Index(std::size_t i) { return std::to_string(i); }
  static std::string ObstaclePath(std::size_t i) { return "/obstacles/" + Index(i) + "/polygon"; }

  void Problem(const std::string& path, const std::string& what) {
    problems_.push_back((v_.origin.empty() ? std::string("venue") : v_.origin) + ": " + path + ": " + what);
  }

  // Finite and within kVenueMaxCoordinate_m; one problem per list of points.
  bool CheckPoints(const std::vector<Vec2>& points, const std::string& path) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vec2 p = points[i];
      if (std::isfinite(p.x) && std::isfinite(p.y) && std::abs(p.x) <= kVenueMaxCoordinate_m &&
          std::abs(p.y) <= kVenueMaxCoordinate_m)
        continue;
      Problem(path + "/" + Index(i), "coordinate " + PointText(p) + " is beyond " +
                                         FormatNumber(kVenueMaxCoordinate_m) +
                                         " m; expected metres: check the scale/units (metadata.scale_m_per_unit, "
                                         "or --scale when importing)");
      return false;
    }
    return true;
  }

  bool CheckCoordinates() {
    bool ok = true;
    for (std::size_t i = 0; i < v_.walkable_area.size(); ++i)
      ok &= CheckPoints(v_.walkable_area[i], "/walkable_area/" + Index(i));
    for (std::size_t i = 0; i < v_.obstacles.size(); ++i) ok &= CheckPoints(v_.obstacles[i].polygon, ObstaclePath(i));
    for (std::size_t i = 0; i < v_.walls.size(); ++i)
      ok &= CheckPoints(v_.walls[i].points, "/walls/" + Index(i) + (v_.walls[i].closed ? "/polygon" : "/polyline"));
    for (std::size_t i = 0; i < v_.exits.size(); ++i)
      ok &= CheckPoints({v_.exits[i].a, v_.exits[i].b}, "/exits/" + Index(i) + "/segment");
    for (std::size_t i = 0; i < v_.entries.size(); ++i)
      ok &= CheckPoints(v_.entries[i].polygon, "/entries/" + Index(i) + "/polygon");
    for (std::size_t i = 0; i < v_.measurement_areas.size(); ++i)
      ok &= CheckPoints(v_.measurement_areas[i].polygon, "/measurement_areas/" + Index(i) + "/polygon");
    for (std::size_t i = 0; i < v_.measurement_lines.size(); ++i)
      ok &= CheckPoints({v_.measurement_lines[i].a, v_.measurement_lines[i].b},
                        "/measurement_lines/" + Index(i) + "/segment");
    if (v_.slope && !v_.slope->region.empty()) ok &= CheckPoints(v_.slope->region, "/slope/region");
    return ok;
  }

  // Checks one ring; returns true if it is a simple polygon of positive area.
  bool CheckRing(const Ring& ring, const std::string& path, const std::string& what) {
    if (ring.size() < 3) {
      Problem(path, what + " has " + Index(ring.size()) + " distinct vertices; expected at least 3");
      return false;
    }
    // Repeated vertices make a ring non-simple in CGAL's sense; name them
    // separately because the fix (delete a vertex) differs from a crossing.
    if (const auto repeat = FirstRepeatedVertex(ring)) {
      Problem(path, what + " repeats a vertex: vertices " + Index(repeat->first) + " and " + Index(repeat->second) +
                        " are both at " + PointText(ring[repeat->first]) + "; expected distinct vertices");
      return false;
    }
    std::vector<Point> pts;
    pts.reserve(ring.size());
    for (Vec2 p : ring) pts.push_back(ToCgal(p));
    const bool collinear = std::all_of(pts.begin() + 2, pts.end(), [&](const Point& q) {
      return CGAL::collinear(pts[0], pts[1], q);
    });
    if (collinear) {
      Problem(path, what + " has zero area (all its vertices lie on one line); expected a polygon enclosing some area");
      return false;
    }
    if (!CGAL::is_simple_2(pts.begin(), pts.end(), Kernel())) {
      Problem(path, what + " is self-intersecting: " + DescribeSelfIntersection(ring) +
                        "; expected a simple polygon");
      return false;
    }
    const double area = std::abs(RingSignedArea_m2(ring));
    if (area <= 1e-12) {
      Problem(path, what + " has zero area; expected a polygon enclosing some area");
      return false;
    }
    return true;
  }

  // Names the first pair of non-adjacent edges that meet (only run once a
  // ring is known not to be simple; edges whose boxes overlap only).
  static std::string DescribeSelfIntersection(const Ring& ring) {
    const std::size_t n = ring.size();
    for (const auto& [i, j] : OverlappingPairs(EdgeBoxes(ring))) {
      const Segment s = Edge(ring, i), t = Edge(ring, j);
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      if (adjacent) {
        // Adjacent edges share a vertex; they only overlap if they fold back.
        if (CGAL::collinear(s.source(), s.target(), t.target()) &&
            CGAL::collinear(t.source(), t.target(), s.source())) {
          const auto r = CGAL::intersection(s, t);
          if (r && boost::get<Segment>(&*r))
            return "edges " + Index(i) + " and " + Index(j) + " fold back on each other at " +
                   PointText(IntersectionPoint(s, t));
        }
        continue;
      }
      if (CGAL::do_intersect(s, t))
        return "edges " + Index(i) + " " + PointText(ring[i]) + "-" + PointText(ring[(i + 1) % n]) +
               " and " + Index(j) + " " + PointText(ring[j]) + "-" + PointText(ring[(j + 1) % n]) +
               " cross at " + PointText(IntersectionPoint(s, t));
    }
    return "its edges intersect";
  }

  void CheckAreaLayout(const std::vector<bool>& outer_ok, const std::vector<bool>& obstacle_ok) {
    const auto& outer = v_.walkable_area;
    for (const auto& [i, j] : OverlappingRings(outer)) {
      if (!outer_ok[i] || !outer_ok[j]) continue;
      if (auto p = RingsMeet(outer[i], outer[j]))
        Problem("/walkable_area/" + Index(j), "outer ring meets outer ring /walkable_area/" + Index(i) +
                                                  " at " + PointText(*p) +
                                                  "; expected disjoint outer rings (merge them into one)");
      else if (StrictlyInside(outer[i], outer[j][0]) || StrictlyInside(outer[j], outer[i][0]))
        Problem("/walkable_area/" + Index(j), "outer rings /walkable_area/" + Index(i) + " and /walkable_area/" +
                                                  Index(j) + " are nested; expected disjoint outer rings "
                                                  "(an enclosed non-walkable region is an obstacle)");
    }
    for (std::size_t k = 0; k < v_.obstacles.size(); ++k) {
      if (!obstacle_ok[k]) continue;
      const Ring& hole = v_.obstacles[k].polygon;
      bool placed = false;
      for (std::size_t i = 0; i < outer.size() && !placed; ++i) {
        if (!outer_ok[i]) { placed = true; continue; }
        if (auto p = RingsMeet(outer[i], hole)) {
          Problem(ObstaclePath(k), "obstacle \"" + v_.obstacles[k].id + "\" meets the boundary of the walkable area " +
                                       "/walkable_area/" + Index(i) + " at " + PointText(*p) +
                                       "; expected it strictly inside (cut a notch in the outer ring instead)");
          placed = true;
        } else if (StrictlyInside(outer[i], hole[0])) {
          placed = true;
        }
      }
      if (!placed)
        Problem(ObstaclePath(k), "obstacle \"" + v_.obstacles[k].id + "\" near " + PointText(hole[0]) +
                                     " lies outside the walkable area; expected it inside an outer ring");
    }
    std::vector<Ring> obstacle_rings;
    obstacle_rings.reserve(v_.obstacles.size());
    for (const Obstacle& o : v_.obstacles) obstacle_rings.push_back(o.polygon);
    for (const auto& [a, b] : OverlappingRings(obstacle_rings)) {
      if (!obstacle_ok[a] || !obstacle_ok[b]) continue;
      const Ring& ra = v_.obstacles[a].polygon;
      const Ring& rb = v_.obstacles[b].polygon;
      if (auto p = RingsMeet(ra, rb))
        Problem(ObstaclePath(b), "obstacles \"" + v_.obstacles[a].id + "\" (" + ObstaclePath(a) + ") and \"" +
                                     v_.obstacles[b].id + "\" overlap or touch at " + PointText(*p) +
                                     "; expected disjoint obstacles (merge them into one)");
      else if (StrictlyInside(ra, rb[0]) || StrictlyInside(rb, ra[0]))
        Problem(ObstaclePath(b), "obstacles \"" + v_.obstacles[a].id + "\" and \"" + v_.obstacles[b].id +
                                     "\" are nested; expected disjoint obstacles");
    }
  }

  void CheckWalls() {
    for (std::size_t i = 0; i < v_.walls.size(); ++i) {
      const Wall& w = v_.walls[i];
      const std::string path = "/walls/" + Index(i) + (w.closed ? "/polygon" : "/polyline");
      if (w.closed) {
        CheckRing(w.points, path, "wall polygon");
        continue;
      }
      for (std::size_t k = 0; k + 1 < w.points.size(); ++k)
        if (w.points[k] == w.points[k + 1]) {
          Problem(path, "wall has a zero-length edge: points " + Index(k) + " and " + Index(k + 1) +
                            " are both at " + PointText(w.points[k]) + "; expected distinct consecutive points");
          break;
        }
    }
  }

  // Distance from p to the closed walkable area (0 inside).
  double DistanceOutside(Vec2 p) const {
    if (IsWalkable(v_, p)) return 0.0;
    double d = std::numeric_limits<double>::infinity();
    for (const Ring& r : v_.walkable_area) d = std::min(d, DistanceToRing(r, p));
    for (const Obstacle& o : v_.obstacles) d = std::min(d, DistanceToRing(o.polygon, p));
    return d;
  }

  // Does [a, b] cross the boundary of the walkable area properly (pass from
  // inside to outside through the interior of an edge)?
  std::optional<Vec2> CrossesBoundary(Vec2 a, Vec2 b) const {
    const Point pa = ToCgal(a), pb = ToCgal(b);
    auto check = [&](const Ring& ring) -> std::optional<Vec2> {
      for (std::size_t i = 0; i < ring.size(); ++i) {
        const Point q0 = ToCgal(ring[i]), q1 = ToCgal(ring[(i + 1) % ring.size()]);
        const auto o1 = CGAL::orientation(pa, pb, q0), o2 = CGAL::orientation(pa, pb, q1);
        const auto o3 = CGAL::orientation(q0, q1, pa), o4 = CGAL::orientation(q0, q1, pb);
        if (o1 != CGAL::COLLINEAR && o2 != CGAL::COLLINEAR && o1 != o2 && o3 != CGAL::COLLINEAR &&
            o4 != CGAL::COLLINEAR && o3 != o4)
          return IntersectionPoint(Segment(pa, pb), Segment(q0, q1));
      }
      return std::nullopt;
    };
    for (const Ring& r : v_.walkable_area)
      if (auto p = check(r)) return p;
    for (const Obstacle& o : v_.obstacles)
      if (auto p = check(o.polygon)) return p;
    return std::nullopt;
  }

  void CheckSegmentInArea(Vec2 a, Vec2 b, const std::string& path, const std::string& what) {
    if (Length(b - a) <= kVenueTolerance_m) {
      Problem(path, what + " has zero length (both ends at " + PointText(a) + "); expected two distinct points");
      return;
    }
    for (Vec2 p : {a, b, 0.5 * (a + b)}) {
      const double d = DistanceOutside(p);
      if (d > kVenueTolerance_m) {
        Problem(path, what + " point " + PointText(p) + " is " + FormatNumber(d) +
                          " m outside the walkable area; expected it on the boundary or inside");
        return;
      }
    }
    if (auto p = CrossesBoundary(a, b))
      Problem(path, what + " crosses the boundary of the walkable area at " + PointText(*p) +
                        "; expected it on the boundary or inside");
  }

  void CheckZone(const Ring& ring, const std::string& path, const std::string& what) {
    if (!CheckRing(ring, path, what)) return;
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const double d = DistanceOutside(ring[i]);
      if (d > kVenueTolerance_m) {
        Problem(path, what + " vertex " + Index(i) + " " + PointText(ring[i]) + " is " + FormatNumber(d) +
                          " m outside the walkable area; expected the zone inside it");
        return;
      }
    }
    for (std::size_t i = 0; i < ring.size(); ++i)
      if (auto p = CrossesBoundary(ring[i], ring[(i + 1) % ring.size()])) {
        Problem(path, what + " edge " + Index(i) + " crosses the boundary of the walkable area at " +
                          PointText(*p) + "; expected the zone inside it");
        return;
      }
  }

  // A slope's region (issue 65: it was never checked): a simple polygon of
  // positive area that overlaps the walkable area; it may reach beyond it
  // (the floor slopes where both are), but one wholly outside would make the
  // slope act nowhere.
  void CheckSlopeRegion() {
    if (!v_.slope || v_.slope->region.empty()) return;
    const Ring& region = v_.slope->region;
    if (!CheckRing(region, "/slope/region", "slope region")) return;
    bool overlaps = false;
    for (std::size_t i = 0; i < region.size() && !overlaps; ++i)
      overlaps = DistanceOutside(region[i]) == 0.0 || CrossesBoundary(region[i], region[(i + 1) % region.size()]);
    for (const Ring& r : v_.walkable_area)
      for (std::size_t i = 0; i < r.size() && !overlaps; ++i) overlaps = StrictlyInside(region, r[i]);
    if (!overlaps)
      Problem("/slope/region", "the slope region lies wholly outside the walkable area, so the floor would slope "
                               "nowhere; expected a region that covers part of it");
  }

  template <typename Items>
  void CheckUnique(const Items& items, const std::string& key) {
    std::set<std::string, std::less<>> seen;
    for (std::size_t i = 0; i < items.size(); ++i)
      if (!seen.insert(items[i].id).second)
        Problem("/" + key + "/" + Index(i) + "/id", "id \"" + items[i].id + "\" is used twice in " + key +
                                                        "; expected unique ids");
  }

  void CheckIds() {
    CheckUnique(v_.obstacles, "obstacles");
    CheckUnique(v_.walls, "walls");
    CheckUnique(v_.exits, "exits");
    CheckUnique(v_.entries, "entries");
    CheckUnique(v_.measurement_areas, "measurement_areas");
    CheckUnique(v_.measurement_lines, "measurement_lines");
    CheckUnique(v_.targets, "targets");
  }

  void CheckTargets() {
    for (std::size_t i = 0; i < v_.targets.size(); ++i) {
      const Target& t = v_.targets[i];
      if (t.kind != Target::Kind::kExit) continue;
      const std::vector<std::string> ids = t.exit_ids.empty() ? std::vector<std::string>{t.exit_id} : t.exit_ids;
      for (std::size_t k = 0; k < ids.size(); ++k) {
        if (v_.FindExit(ids[k])) continue;
        std::string known;
        for (const Exit& e : v_.exits) known += (known.empty() ? "\"" : ", \"") + e.id + "\"";
        Problem("/targets/" + Index(i) + (t.exit_ids.size() > 1 ? "/exits/" + Index(k) : "/exit"),
                "target \"" + t.id + "\" names exit \"" + ids[k] + "\", which does not exist; expected one of " +
                    (known.empty() ? std::string("(no exits declared)") : known));
      }
    }
  }

  void CheckPeriodic() {
    if (v_.periodic.size() > 2)
      Problem("/periodic", "has " + Index(v_.periodic.size()) + " directions; expected at most 2");
    for (std::size_t i = 0; i < v_.periodic.size(); ++i) {
      const PeriodicDirection& p = v_.periodic[i];
      for (std::size_t j = 0; j < i; ++j)
        if (std::abs(Cross(p.direction, v_.periodic[j].direction)) < 1e-9)
          Problem("/periodic/" + Index(i) + "/direction", "is parallel to /periodic/" + Index(j) +
                                                              "; expected independent directions");
      // The period must be the extent of the area along the direction, or
      // people wrapping around would land outside it or overlap.
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const Ring& r : v_.walkable_area)
        for (Vec2 q : r) {
          lo = std::min(lo, Dot(q, p.direction));
          hi = std::max(hi, Dot(q, p.direction));
        }
      if (std::abs((hi - lo) - p.period_m) > kVenueTolerance_m)
        Problem("/periodic/" + Index(i) + "/period_m",
                "period " + FormatNumber(p.period_m) + " m differs from the extent of the walkable area along " +
                    PointText(p.direction) + ", " + FormatNumber(hi - lo) + " m; expected them equal");
    }
  }

  const Venue& v_;
  std::vector<std::string> problems_;
};

}  // namespace

std::vector<std::string> FindVenueProblems(const Venue& venue) { return Checker(venue).Run(); }

void ValidateVenue(const Venue& venue) {
  const std::vector<std::string> problems = FindVenueProblems(venue);
  if (problems.empty()) return;
  // Every problem up to a screenful: a plan in the wrong unit has one per ring.
  constexpr std::size_t kShown = 20;
  std::string message = problems.front();
  for (std::size_t i = 1; i < std::min(problems.size(), kShown); ++i) message += "\n" + problems[i];
  if (problems.size() > kShown)
    message += "\n(and " + std::to_string(problems.size() - kShown) + " more problems of the same venue)";
  throw GeometryError(message);
}

}  // namespace crowdrecon::geometry
