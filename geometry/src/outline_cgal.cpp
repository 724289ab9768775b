// The only body-pipeline file that includes CGAL (compile time, and the style
// rule of keeping heavy library types at the edges). Epick is enough for both
// algorithms: the polyline simplification runs on a constrained Delaunay
// triangulation with exact predicates, and the straight skeleton filters its
// predicates and constructs offset vertices with interval arithmetic internally.
#include "outline_cgal.hpp"

// GCC's -Wnull-dereference fires inside CGAL's inlined container code
// (In_place_list, Compact_container, the skeleton's vertex base) after
// optimisation, where the system-header exemption no longer applies. The
// pointers are CGAL's own list sentinels; silence it for this file only.
#pragma GCC diagnostic ignored "-Wnull-dereference"

#include <algorithm>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_plus_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/Polyline_simplification_2/simplify.h>
#include <CGAL/create_offset_polygons_2.h>

namespace crowdrecon::geometry::detail {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_2;
using Polygon = CGAL::Polygon_2<Kernel>;
namespace PS = CGAL::Polyline_simplification_2;

Polygon ToPolygon(const std::vector<Vec2>& ring) {
  Polygon polygon;
  for (const Vec2& p : ring) polygon.push_back(Point(p.x, p.y));
  return polygon;
}

std::vector<Vec2> ToRing(const Polygon& polygon) {
  std::vector<Vec2> ring;
  ring.reserve(polygon.size());
  for (auto it = polygon.vertices_begin(); it != polygon.vertices_end(); ++it)
    ring.push_back({CGAL::to_double(it->x()), CGAL::to_double(it->y())});
  return ring;
}

}  // namespace

bool IsSimpleRing(const std::vector<Vec2>& ring) {
  if (ring.size() < 3) return false;
  return ToPolygon(ring).is_simple();
}

std::vector<Vec2> SimplifyRingToTolerance(const std::vector<Vec2>& ring, double tolerance) {
  // The stop predicate compares squared costs.
  return ToRing(PS::simplify(ToPolygon(ring), PS::Squared_distance_cost(),
                             PS::Stop_above_cost_threshold(tolerance * tolerance)));
}

std::vector<Vec2> SimplifyRingToCount(const std::vector<Vec2>& ring, std::size_t count) {
  if (ring.size() <= count) return ring;
  return ToRing(PS::simplify(ToPolygon(ring), PS::Squared_distance_cost(),
                             PS::Stop_below_count_threshold(count)));
}

std::vector<std::vector<Vec2>> InwardOffsetPieces(const std::vector<Vec2>& ring, double distance) {
  const Polygon polygon = ToPolygon(ring);
  const auto offsets = CGAL::create_interior_skeleton_and_offset_polygons_2(distance, polygon);
  std::vector<std::vector<Vec2>> pieces;
  for (const auto& piece : offsets) {
    if (!piece || piece->size() < 3) continue;
    Polygon p = *piece;
    if (p.orientation() == CGAL::CLOCKWISE) p.reverse_orientation();
    pieces.push_back(ToRing(p));
  }
  const auto area = [](const std::vector<Vec2>& r) {
    double twice = 0.0;
    for (std::size_t i = 0; i < r.size(); ++i) twice += Cross(r[i], r[(i + 1) % r.size()]);
    return twice / 2.0;
  };
  std::stable_sort(pieces.begin(), pieces.end(),
                   [&](const auto& a, const auto& b) { return area(a) > area(b); });
  return pieces;
}

}  // namespace crowdrecon::geometry::detail
