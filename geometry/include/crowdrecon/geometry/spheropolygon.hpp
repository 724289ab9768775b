// Spheropolygon: the shape of a pedestrian (and of a wall piece) in the model of
// Alonso-Marroquin et al.: the Minkowski sum of a polygon and a disk of radius
// r (the "sphero-radius"), i.e. every point within r of the polygon.
//
//   1 vertex   -> disk of radius r
//   2 vertices -> capsule (segment swept by a disk)
//   >= 3       -> rounded polygon, convex or not (vertices counter-clockwise)
//
// A Spheropolygon is a validated value: Create() rejects non-finite, repeated or
// collinear-degenerate vertices, self-intersecting or clockwise polygons and
// non-positive radii with a message saying what is wrong. Its mass properties are
// those of the *swept* shape, computed exactly: the boundary of the swept region
// (offset edges and vertex arcs, split where they cross, hidden pieces dropped)
// is integrated in closed form by Green's theorem, so overlaps of edge strips at
// reflex vertices and gaps narrower than 2r, which the sweep closes, are
// accounted for (see spheropolygon.cpp).
#pragma once

#include <string>
#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::geometry {

// Area, centroid and polar second moment of area of a plane region.
struct AreaProperties {
  double area_m2 = 0.0;
  Vec2 centroid_m;
  // Polar second moment of area about the centroid, J = integral |x - c|^2 dA (m^4).
  // The moment of inertia of a body of surface density rho is I = rho * J.
  double polar_moment_m4 = 0.0;
};

class Spheropolygon {
 public:
  // Validates and builds. Throws GeometryError naming the offending vertex or
  // edge. `what` prefixes messages (e.g. "body 'thorax'").
  static Spheropolygon Create(std::vector<Vec2> vertices, double radius_m,
                              const std::string& what = "spheropolygon");

  const std::vector<Vec2>& vertices() const { return vertices_; }
  double radius() const { return radius_; }
  std::size_t size() const { return vertices_.size(); }
  const AreaProperties& properties() const { return properties_; }
  double area() const { return properties_.area_m2; }
  Vec2 centroid() const { return properties_.centroid_m; }
  double polar_moment() const { return properties_.polar_moment_m4; }

  // Area of the core polygon alone (0 for disks and capsules).
  double CorePolygonArea() const;
  // Perimeter of the core polygon (twice the length for a capsule, 0 for a disk).
  double CorePerimeter() const;

  // Same shape moved so that its centroid is at the origin.
  Spheropolygon Centered() const;
  // Uniform scaling of the whole swept shape (vertices and radius) by s > 0;
  // mass properties scale analytically (area s^2, J s^4).
  Spheropolygon Scaled(double s) const;
  // Rotation about the origin by angle (radians, counter-clockwise).
  Spheropolygon Rotated(double angle_rad) const;
  Spheropolygon Translated(Vec2 offset) const;

  // Axis-aligned bounding box of the swept shape.
  Vec2 BoundsMin() const;
  Vec2 BoundsMax() const;

  // Signed distance from p to the core polygon (negative inside, for >= 3 vertices).
  double SignedDistanceToCore(Vec2 p) const;
  // Distance from p to the boundary of the swept shape (>= 0).
  double DistanceToBoundary(Vec2 p) const;
  // Points on the boundary of the swept shape, about `spacing_m` apart
  // (edge strips and vertex arcs, with points hidden inside the shape removed).
  std::vector<Vec2> SampleBoundary(double spacing_m) const;

 private:
  Spheropolygon(std::vector<Vec2> vertices, double radius, AreaProperties properties)
      : vertices_(std::move(vertices)), radius_(radius), properties_(properties) {}

  std::vector<Vec2> vertices_;
  double radius_ = 0.0;
  AreaProperties properties_;
};

// Closed forms used by tests and by the circle body (exposed for reuse).
AreaProperties DiskProperties(double radius_m);
AreaProperties CapsuleProperties(double length_m, double radius_m);

// Signed area of a closed polygon (positive when counter-clockwise).
double SignedArea(const std::vector<Vec2>& polygon);
// Area, centroid and polar moment of a simple polygon (no sweeping), closed form.
AreaProperties PolygonProperties(const std::vector<Vec2>& polygon);

// Hausdorff distance between two point sets; infinite if either is empty.
// Nearest neighbours through a k-d tree: O((|a| + |b|) log(|a| + |b|)).
double HausdorffDistance(const std::vector<Vec2>& a, const std::vector<Vec2>& b);

}  // namespace crowdrecon::geometry
