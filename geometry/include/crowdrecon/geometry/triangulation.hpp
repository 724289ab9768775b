// Triangulation of a walkable region (CGAL constrained Delaunay triangulation,
// faces inside the domain only) and uniform random placement on it.
//
//   auto tri = geometry::AreaTriangulation::OfWalkableArea(venue);
//   std::mt19937_64 rng(seed);
//   Vec2 p = tri.Sample(rng);      // uniform over the walkable area
//
// The triangles are plain values; CGAL stays in triangulation.cpp.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::geometry {

struct Triangle {
  Vec2 a, b, c;  // counter-clockwise
  double area_m2() const { return 0.5 * Cross(b - a, c - a); }
};

// A region given as outer rings and holes (holes inside outer rings, all
// disjoint, as a validated venue guarantees).
struct RegionRings {
  std::vector<Ring> outer;
  std::vector<Ring> holes;
};

class AreaTriangulation {
 public:
  // Triangulates the region; faces are "in the domain" when they are nested an
  // odd number of times inside the constraint rings (the usual CGAL recipe).
  // Throws GeometryError if the region has no area.
  static AreaTriangulation Build(const RegionRings& region);
  // The walkable area of a venue (outer rings, obstacles as holes).
  static AreaTriangulation OfWalkableArea(const Venue& venue);
  // An entry zone, minus the obstacles inside it.
  static AreaTriangulation OfEntryZone(const Venue& venue, std::size_t entry_index);

  const std::vector<Triangle>& triangles() const { return triangles_; }
  double area_m2() const { return area_m2_; }

  // A point uniformly distributed over the region for u uniform in [0,1)^3:
  // u0 picks a triangle with probability proportional to its area, (u1, u2)
  // a point in it (square-root warping of barycentric coordinates).
  Vec2 Sample(double u0, double u1, double u2) const;
  // The same with three draws of the generator. The mapping from the
  // generator's integers to [0,1) is written out here (not
  // std::uniform_real_distribution, whose output differs between standard
  // libraries), so a seed gives the same points everywhere.
  Vec2 Sample(std::mt19937_64& rng) const;

 private:
  std::vector<Triangle> triangles_;
  std::vector<double> cumulative_area_m2_;  // cumulative_area_m2_[i] = sum of areas 0..i
  double area_m2_ = 0.0;
};

// Uniform double in [0, 1) from the top 53 bits of one draw.
inline double UniformFromBits(std::uint64_t bits) {
  return static_cast<double>(bits >> 11) * 0x1.0p-53;
}

}  // namespace crowdrecon::geometry
