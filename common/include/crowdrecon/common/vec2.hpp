// Vec2: a plain 2D vector of doubles, the coordinate type of every module.
// Deliberately tiny (no Eigen, no CGAL) so that the engine's hot arrays hold
// plain structs and its headers stay free of heavy library types.
#pragma once

#include <cmath>

namespace crowdrecon {

struct Vec2 {
  double x = 0.0;  // metres (or pixels where a function says so)
  double y = 0.0;

  constexpr Vec2() = default;
  constexpr Vec2(double x_, double y_) : x(x_), y(y_) {}

  constexpr Vec2 operator+(Vec2 o) const { return {x + o.x, y + o.y}; }
  constexpr Vec2 operator-(Vec2 o) const { return {x - o.x, y - o.y}; }
  constexpr Vec2 operator-() const { return {-x, -y}; }
  constexpr Vec2 operator*(double s) const { return {x * s, y * s}; }
  constexpr Vec2 operator/(double s) const { return {x / s, y / s}; }
  constexpr Vec2& operator+=(Vec2 o) { x += o.x; y += o.y; return *this; }
  constexpr Vec2& operator-=(Vec2 o) { x -= o.x; y -= o.y; return *this; }
  constexpr Vec2& operator*=(double s) { x *= s; y *= s; return *this; }
  constexpr bool operator==(const Vec2&) const = default;
};

constexpr Vec2 operator*(double s, Vec2 v) { return {s * v.x, s * v.y}; }
constexpr double Dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
// z-component of the 3D cross product (a, 0) x (b, 0).
constexpr double Cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
// Rotates by +90 degrees (counter-clockwise).
constexpr Vec2 Perp(Vec2 a) { return {-a.y, a.x}; }
constexpr double LengthSquared(Vec2 a) { return Dot(a, a); }
// sqrt rather than std::hypot: several times faster, and the lengths here
// (metres, newtons) are nowhere near overflow.
inline double Length(Vec2 a) { return std::sqrt(a.x * a.x + a.y * a.y); }
inline Vec2 Normalized(Vec2 a) { return a / Length(a); }
inline Vec2 Rotated(Vec2 a, double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  return {c * a.x - s * a.y, s * a.x + c * a.y};
}

// Distance from point p to the segment [a, b].
inline double DistanceToSegment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double len2 = LengthSquared(ab);
  double t = len2 > 0.0 ? Dot(p - a, ab) / len2 : 0.0;
  t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  return Length(p - (a + ab * t));
}

}  // namespace crowdrecon
