// Triangulation of a region with CGAL's constrained Delaunay triangulation.
// Faces are classified by nesting level (the recipe of CGAL's
// "Triangulating a Polygonal Domain" example): flood-fill from the infinite
// face, incrementing the level each time a constrained edge is crossed; faces
// at odd levels are inside the domain.
#include "crowdrecon/geometry/triangulation.hpp"

// GCC's -Wnull-dereference fires inside CGAL's inlined triangulation and
// container code after optimisation, where the system-header exemption no
// longer applies (CGAL's own sentinels); silence it for this file only.
#pragma GCC diagnostic ignored "-Wnull-dereference"

#include <algorithm>
#include <list>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::geometry {

namespace {

struct FaceInfo {
  int nesting_level = -1;
  bool InDomain() const { return nesting_level % 2 == 1; }
};

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_2<Kernel>;
using Fbb = CGAL::Triangulation_face_base_with_info_2<FaceInfo, Kernel>;
using Fb = CGAL::Constrained_triangulation_face_base_2<Kernel, Fbb>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
// Exact_predicates_tag: constraints may meet at vertices (rings touching at a
// point are rejected by validation, but entry zones may share vertices with
// the area's boundary).
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;

void MarkDomain(Cdt& cdt, Cdt::Face_handle start, int level, std::list<Cdt::Edge>& border) {
  if (start->info().nesting_level != -1) return;
  std::list<Cdt::Face_handle> queue{start};
  while (!queue.empty()) {
    Cdt::Face_handle fh = queue.front();
    queue.pop_front();
    if (fh->info().nesting_level != -1) continue;
    fh->info().nesting_level = level;
    for (int i = 0; i < 3; ++i) {
      const Cdt::Edge e(fh, i);
      Cdt::Face_handle n = fh->neighbor(i);
      if (n->info().nesting_level != -1) continue;
      if (cdt.is_constrained(e)) border.push_back(e);
      else queue.push_back(n);
    }
  }
}

void MarkDomains(Cdt& cdt) {
  std::list<Cdt::Edge> border;
  MarkDomain(cdt, cdt.infinite_face(), 0, border);
  while (!border.empty()) {
    const Cdt::Edge e = border.front();
    border.pop_front();
    Cdt::Face_handle n = e.first->neighbor(e.second);
    if (n->info().nesting_level == -1) MarkDomain(cdt, n, e.first->info().nesting_level + 1, border);
  }
}

void InsertRing(Cdt& cdt, const Ring& ring) {
  std::vector<Kernel::Point_2> points;
  points.reserve(ring.size());
  for (Vec2 p : ring) points.emplace_back(p.x, p.y);
  cdt.insert_constraint(points.begin(), points.end(), /*close=*/true);
}

}  // namespace

AreaTriangulation AreaTriangulation::Build(const RegionRings& region) {
  Cdt cdt;
  for (const Ring& r : region.outer) InsertRing(cdt, r);
  for (const Ring& r : region.holes) InsertRing(cdt, r);
  MarkDomains(cdt);

  AreaTriangulation t;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!f->info().InDomain()) continue;
    Triangle tri;
    const auto& p0 = f->vertex(0)->point();
    const auto& p1 = f->vertex(1)->point();
    const auto& p2 = f->vertex(2)->point();
    tri.a = {p0.x(), p0.y()};
    tri.b = {p1.x(), p1.y()};
    tri.c = {p2.x(), p2.y()};
    if (tri.area_m2() < 0.0) std::swap(tri.b, tri.c);  // CGAL faces are CCW; keep the promise regardless
    t.area_m2_ += tri.area_m2();
    t.triangles_.push_back(tri);
    t.cumulative_area_m2_.push_back(t.area_m2_);
  }
  if (t.triangles_.empty() || !(t.area_m2_ > 0.0))
    throw GeometryError("triangulation: the region has no area; expected at least one polygon of positive area");
  return t;
}

AreaTriangulation AreaTriangulation::OfWalkableArea(const Venue& venue) {
  RegionRings region;
  region.outer = venue.walkable_area;
  for (const Obstacle& o : venue.obstacles) region.holes.push_back(o.polygon);
  return Build(region);
}

AreaTriangulation AreaTriangulation::OfEntryZone(const Venue& venue, std::size_t entry_index) {
  const EntryZone& entry = venue.entries.at(entry_index);
  RegionRings region;
  region.outer.push_back(entry.polygon);
  // Validation guarantees that no obstacle crosses the zone's edges, so an
  // obstacle is inside the zone if one of its vertices is.
  for (const Obstacle& o : venue.obstacles)
    if (PointInRing(entry.polygon, o.polygon.front())) region.holes.push_back(o.polygon);
  return Build(region);
}

Vec2 AreaTriangulation::Sample(double u0, double u1, double u2) const {
  const double target = std::clamp(u0, 0.0, 1.0) * area_m2_;
  auto it = std::upper_bound(cumulative_area_m2_.begin(), cumulative_area_m2_.end(), target);
  if (it == cumulative_area_m2_.end()) --it;
  const Triangle& t = triangles_[static_cast<std::size_t>(it - cumulative_area_m2_.begin())];
  // Uniform point in a triangle: with s = sqrt(u1), the point
  // (1 - s) a + s (1 - u2) b + s u2 c has a uniform density (Osada et al. 2002).
  const double s = std::sqrt(std::clamp(u1, 0.0, 1.0));
  const double v = std::clamp(u2, 0.0, 1.0);
  return (1.0 - s) * t.a + s * (1.0 - v) * t.b + s * v * t.c;
}

Vec2 AreaTriangulation::Sample(std::mt19937_64& rng) const {
  const double u0 = UniformFromBits(rng());
  const double u1 = UniformFromBits(rng());
  const double u2 = UniformFromBits(rng());
  return Sample(u0, u1, u2);
}

}  // namespace crowdrecon::geometry
