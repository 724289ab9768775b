// The sums of the contact forces and torques on one body (eq. 2, third term;
// eq. 18, last term), with the dashpot corrections of contacts that begin or
// end within a step (ContactLaw). Shared, as source, by the processor's
// Gather (simulation.cpp) and the CUDA force computation (cuda_collide.cu):
// a body's contacts are added in contact order on both, with the same
// expressions, so the sums are the same bit for bit.
#pragma once

#include "crowdrecon/engine/contact.hpp"
#include "host_device.hpp"

namespace crowdrecon::engine::detail {

struct BodySums {
  Vec2 force;
  double torque = 0.0;
  Vec2 trailing_force;
  double trailing_torque = 0.0;
  Vec2 leading_force;
  double leading_torque = 0.0;
};

// Adds contact c to the sums of one of its two bodies: body a (`on_a`) or
// body b, whose centre in the contact's frame (a's periodic image) is
// `centre` (ERRATA 11: each contact acts on both bodies, equal and opposite,
// each with its own branch vector).
//
// A contact that lasted the whole step both sides of this evaluation (both
// fractions 1, nearly every contact) has no corrections: its terms would be
// zeros (+0 or -0), which leave any sum as it is (a sum that starts at +0
// never becomes -0 in round-to-nearest), so they are not added at all.
CROWDRECON_HOST_DEVICE inline void AddContact(BodySums& s, const Contact& c, bool on_a, Vec2 centre) {
  const Vec2 f = c.Force();
  const Vec2 arm = c.point_m - centre;
  const double sign = on_a ? 1.0 : -1.0;
  s.force += f * sign;
  s.torque += Cross(arm, f) * sign;
  if (c.trailing_fraction == 1.0 && c.leading_fraction == 1.0) return;
  const Vec2 viscous = c.normal * c.viscous_normal_n + Perp(c.normal) * c.viscous_tangential_n;
  const Vec2 trailing = viscous * (c.trailing_fraction - 1.0);
  const Vec2 leading = viscous * (c.leading_fraction - 1.0);
  s.trailing_force += trailing * sign;
  s.trailing_torque += Cross(arm, trailing) * sign;
  s.leading_force += leading * sign;
  s.leading_torque += Cross(arm, leading) * sign;
}

}  // namespace crowdrecon::engine::detail
