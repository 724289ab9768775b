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
CROWDRECON_HOST_DEVICE inline void AddContact(BodySums& s, const Contact& c, bool on_a, Vec2 centre) {
  const Vec2 f = c.Force();
  const Vec2 viscous = c.normal * c.viscous_normal_n + Perp(c.normal) * c.viscous_tangential_n;
  const Vec2 trailing = viscous * (c.trailing_fraction - 1.0);
  const Vec2 leading = viscous * (c.leading_fraction - 1.0);
  const Vec2 arm = c.point_m - centre;
  if (on_a) {
    s.force += f;
    s.torque += Cross(arm, f);
    s.trailing_force += trailing;
    s.trailing_torque += Cross(arm, trailing);
    s.leading_force += leading;
    s.leading_torque += Cross(arm, leading);
  } else {
    s.force -= f;
    s.torque -= Cross(arm, f);
    s.trailing_force -= trailing;
    s.trailing_torque -= Cross(arm, trailing);
    s.leading_force -= leading;
    s.leading_torque -= Cross(arm, leading);
  }
}

}  // namespace crowdrecon::engine::detail
