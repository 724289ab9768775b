// Contact: one contact point of a step with its forces, as the engine keeps
// it (every contact of every step: force network, injury risk). Its own
// header, with nothing but Vec2, so that code built by other compilers (the
// CUDA force computation) shares the record's layout with the engine.
#pragma once

#include <cstdint>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::engine {

// A contact between person `a` and person `b`, or between person `a` and wall
// segment `b` when `wall` is true. Forces are those acting on `a`; `b` feels
// the opposite. Every contact of the step is kept (force network, injury risk).
struct Contact {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  bool wall = false;
  // The bytes between `wall` and `feature`, named so that they are zero: a
  // checkpoint writes contacts as they lie in memory, and unnamed padding
  // held whatever was there (the same state gave different bytes).
  std::uint8_t padding_[3] = {};
  std::uint32_t feature = 0;      // owning vertex within (a, b), see narrow_phase.hpp
  Vec2 point_m;                   // application point (in a's periodic image)
  Vec2 normal;                    // unit, from b to a
  double overlap_m = 0.0;         // delta_n
  double normal_force_n = 0.0;    // along `normal` (elastic + viscous, eqs. 8, 11)
  double tangential_force_n = 0.0;  // along Perp(normal) (eqs. 9, 12)
  double tangential_spring_m = 0.0;  // delta_t, elastic tangential displacement (eqs. 9-10)
  // The viscous parts of the two forces above (eqs. 11, 12), and the fractions
  // of the half steps before and after this evaluation during which the
  // contact existed (see "contact onset and end within a step" in docs/model.md).
  double viscous_normal_n = 0.0;
  double viscous_tangential_n = 0.0;
  double trailing_fraction = 1.0;
  double leading_fraction = 1.0;
  constexpr Vec2 Force() const { return normal * normal_force_n + Perp(normal) * tangential_force_n; }
};

// The key that orders contacts by pair (the contact list is sorted by it,
// then by feature): person pairs by (a, b), then person-wall pairs.
inline constexpr std::uint64_t kWallPairBit = std::uint64_t{1} << 63;
constexpr std::uint64_t PairKey(bool wall, std::uint32_t a, std::uint32_t b) {
  return (wall ? kWallPairBit : 0) | (std::uint64_t{a} << 32) | b;
}
constexpr std::uint64_t PairKey(const Contact& c) { return PairKey(c.wall, c.a, c.b); }

}  // namespace crowdrecon::engine
