// The contact law (paper, eqs. 8-12 and 19): the forces of one contact point
// from its overlap, the relative velocity there and its tangential spring.
//
// Internal to the engine. Shared, as source, by the engine's force
// computation on the processor (simulation.cpp) and by its CUDA one
// (cuda_collide.cu): the same expressions in the same order, compiled without
// contraction of a*b+c on both sides, give the same forces bit for bit.
#pragma once

#include <algorithm>
#include <cmath>

#include "crowdrecon/engine/contact.hpp"
#include "crowdrecon/engine/parameters.hpp"
#include "host_device.hpp"

namespace crowdrecon::engine::detail {

// The state a contact inherits from the previous evaluation's contact of the
// same pair and vertex, if there was one.
struct ContactHistory {
  bool exists = false;
  double tangential_spring_m = 0.0;
  double leading_fraction = 1.0;
};

struct ContactLaw {
  double kn, kt, mu, dt;
  double damping_factor;  // 2L/sqrt(pi^2+L^2): gamma = factor * sqrt(k / m_ij)
  TangentialDamping tangential_mode;
  double tangential_rate;
  bool tensile;
  bool advance_springs;
  bool spring_history = true;  // false: TangentialSpring::kNone, no elastic tangential displacement
  // What of the spring a step keeps: exp(-dt / T) for TangentialSpring::kCreeping
  // (issue 39), 1 otherwise (then the product below is the spring itself, bit for bit).
  double spring_keep = 1.0;
  // The step after this evaluation (the leading fraction's half step): dt
  // itself with the fixed step; with the adaptive step, the one chosen for it.
  double dt_next = 0.0;

  // Restitution per pair. A pair touching at several points (a flat face) acts
  // as one spring of stiffness k_eff kn along the normal, and the pair's
  // restitution should be epsilon whatever the number of points. The pair
  // damping rate follows from eq. (19) with k_eff kn, and is shared among the
  // points in proportion to their overlaps. k_eff = (sum delta)^2 / sum delta^2
  // counts points weighted by overlap, so that a point that starts touching
  // joins the sum continuously. `weight` = delta_i / sum delta; for a single
  // point weight = k_eff = 1 and this is eq. (19) as written (docs/model.md).
  //
  // The pair's damping rates (before the sharing by `weight`) are the same for
  // all its points: PairRates, once per pair.
  struct Rates {
    double normal = 0.0, tangential = 0.0;
  };
  CROWDRECON_HOST_DEVICE Rates PairRates(double effective_mass, double k_eff) const {
    Rates r;
    r.normal = damping_factor * std::sqrt(k_eff * kn / effective_mass);  // eq. (19) inverted
    switch (tangential_mode) {
      case TangentialDamping::kFromRestitution: r.tangential = damping_factor * std::sqrt(k_eff * kt / effective_mass); break;
      case TangentialDamping::kEqualToNormal: r.tangential = r.normal; break;
      case TangentialDamping::kFixed: r.tangential = tangential_rate; break;
    }
    return r;
  }

  // Fills the forces of contact c given the relative velocity at the contact
  // point and what it inherits from the previous evaluation.
  CROWDRECON_HOST_DEVICE void Apply(Contact& c, Vec2 relative_velocity, double effective_mass,
                                    const ContactHistory& previous, double weight, Rates rates) const {
    const double previous_spring = previous.exists ? previous.tangential_spring_m : 0.0;
    const Vec2 t = Perp(c.normal);
    const double vn = Dot(relative_velocity, c.normal);  // > 0: separating
    const double vt = Dot(relative_velocity, t);
    const double gamma_n = rates.normal * weight;
    const double gamma_t = rates.tangential * weight;
    const double elastic_n = kn * c.overlap_m;                      // eq. (8)
    double fn = elastic_n - effective_mass * gamma_n * vn;           // + eq. (11)
    if (!tensile && fn < 0.0) fn = 0.0;
    // Tangential elastic displacement (eq. 9), accumulated while the contact
    // persists and capped by Coulomb's condition on the elastic parts (eq. 10).
    // With creep (issue 39) the displacement relaxes over T while it lasts:
    // a Maxwell element, spring and dashpot in series.
    double spring = spring_history ? previous_spring * (advance_springs ? spring_keep : 1.0) + (advance_springs ? vt * dt : 0.0)
                                   : 0.0;
    const double cap = mu * elastic_n;
    if (kt * std::abs(spring) > cap) spring = std::copysign(cap / kt, spring);
    c.tangential_spring_m = spring;
    c.normal_force_n = fn;
    c.viscous_normal_n = fn - elastic_n;
    c.viscous_tangential_n = -effective_mass * gamma_t * vt;
    c.tangential_force_n = -kt * spring + c.viscous_tangential_n;  // eqs. (9) + (12)
    // Onset and end within a step. The dashpots jump at delta = 0 (eqs. 11-12),
    // so kicks that apply them for whole half steps bias the restitution by
    // O(gamma h). The time since onset (new contact, up to a whole step ago)
    // and until the end (separating contact, if before the next evaluation)
    // are estimated from delta and v_n, and the dashpot impulse of the
    // adjacent half kick is scaled to it, by up to two (docs/model.md).
    if (!previous.exists) {
      c.trailing_fraction = vn < 0.0 ? std::min(2.0, 2.0 * c.overlap_m / (-vn * dt)) : 1.0;
    } else {
      // The last leading kick already covered the time it expected the contact to last beyond its half step.
      c.trailing_fraction = previous.leading_fraction > 1.0 ? 2.0 - previous.leading_fraction : 1.0;
    }
    const double until_end = vn > 0.0 ? 2.0 * c.overlap_m / (vn * dt_next) : 2.0;
    c.leading_fraction = until_end < 2.0 ? until_end : 1.0;
  }
};

}  // namespace crowdrecon::engine::detail
