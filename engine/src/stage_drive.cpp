// Stage drive: ground reaction forces and torques (eqs. 3, 15, 16, 17) and the floor slope.
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
#include "simulation_internals.hpp"

#include <algorithm>
#include <cmath>

#include "crowdrecon/common/fast_math.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

void Simulation::Drive() {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kDrive)]);
  const Internals& in = *in_;
  std::vector<geometry::NavigationField::CellCache>& field_cache = in_->field_cache;
  const ModelParameters& mp = def_.parameters;
  // Loop invariants, so that the loop below divides only where it must.
  const double inverse_tau = 1.0 / mp.relaxation_time_s;
  const double back_factor = mp.back_force_gamma * inverse_tau;                                      // eq. (15): Gamma / tau
  const double torsion_factor = mp.torsion_stiffness_lambda * inverse_tau * inverse_tau;             // eq. (16): lambda / tau^2
  const double rotation_damping = 1.0 / mp.rotation_relaxation_time_s;                               // eq. (17)
  const bool face_velocity = mp.facing_target == FacingTarget::kVelocity;
  const bool averaged_trigger = mp.back_force_trigger == BackForceTrigger::kAveragedVelocity;
  const double slope_force_per_kg =
      def_.slope.gradient > 0.0 ? mp.gravity_m_per_s2 * def_.slope.gradient / std::sqrt(1.0 + def_.slope.gradient * def_.slope.gradient)
                                : 0.0;
  const Vec2 slope_acceleration = def_.slope.downhill * slope_force_per_kg;
  const std::int64_t n = static_cast<std::int64_t>(bodies_.size());
  // In blocks of bodies, in three passes: the motive torque's angle (eq. 16)
  // is a long chain of dependent operations (a division, a polynomial), so
  // the angles of a block are computed in a short loop of their own, whose
  // iterations the processor overlaps, between the passes that need them.
  constexpr std::int64_t kBlock = 64;
  const std::int64_t blocks = (n + kBlock - 1) / kBlock;
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (n >= kParallelBodies)
  for (std::int64_t block = 0; block < blocks; ++block) {
    const std::size_t first = static_cast<std::size_t>(block * kBlock);
    const std::size_t last = static_cast<std::size_t>(std::min(n, (block + 1) * kBlock));
    Vec2 direction[kBlock];
    double sine[kBlock], cosine[kBlock], gain[kBlock], angle[kBlock];
    bool driven[kBlock], turning[kBlock];
    // Pass 1: desired direction, and the angle's arguments: from the body's
    // orientation (cos, sin from PlaceShapes) to the facing direction.
    for (std::size_t i = first; i < last; ++i) {
      const std::size_t k = i - first;
      driven[k] = bodies_.state[i] == PersonState::kWalking && mp.ground_reaction;
      turning[k] = false;
      sine[k] = 0.0;
      cosine[k] = 1.0;
      gain[k] = 0.0;
      if (!driven[k]) continue;
      const Vec2 v = bodies_.velocity_m_per_s[i];
      direction[k] = def_.targets[bodies_.target[i]].Direction(bodies_.position_m[i], field_cache[i]);
      const double speed = Length(v);
      // Only the direction of `facing` matters to the angle (atan2 of two
      // products with it), so the velocity needs no normalising.
      const Vec2 facing = face_velocity ? v : direction[k];
      if (facing.x != 0.0 || facing.y != 0.0) {
        const Vec2 orientation{in.cos_angle[i], in.sin_angle[i]};
        turning[k] = true;
        sine[k] = Cross(orientation, facing);
        cosine[k] = Dot(orientation, facing);
        const double v0 = bodies_.desired_speed_m_per_s[i];
        gain[k] = v0 > 0.0 ? 1.0 - std::exp(-speed / v0) : 1.0;
      }
    }
    // Pass 2: theta_D - theta wrapped to (-pi, pi].
    for (std::size_t k = 0; k < last - first; ++k) angle[k] = Atan2(sine[k], cosine[k]);
    // Pass 3: forces and torques.
    for (std::size_t i = first; i < last; ++i) {
      const std::size_t k = i - first;
      if (bodies_.state[i] == PersonState::kRemoved) continue;  // no forces (zeroed when removed)
      Vec2 force = bodies_.contact_force_n[i] + bodies_.external_force_n[i];
      double torque = bodies_.contact_torque_n_m[i];
      if (driven[k]) {
        const double m = bodies_.mass_kg[i], inertia = bodies_.inertia_kg_m2[i];
        const double v0 = bodies_.desired_speed_m_per_s[i];
        const Vec2 v = bodies_.velocity_m_per_s[i];
        const Vec2 e = direction[k];
        force += (e * v0 - v) * (m * inverse_tau);  // eq. (3)
        // Back force, eq. (15): only when pushed backwards (Theta(x) = 1 for x > 0
        // only, ERRATA 9), along e plus e x k, which points to the person's right.
        // (With the averaged trigger, Theta reads u_i, see AverageBackForceTrigger.)
        const double along = averaged_trigger ? in.averaged_along[i] : Dot(e, v);
        // A group's own Gamma and lambda (Simulation::SetGroupDrive), if any.
        double back = back_factor, torsion = torsion_factor;
        if (const std::uint32_t g = bodies_.group[i]; g < in.group_gamma.size()) {
          if (!std::isnan(in.group_gamma[g])) back = in.group_gamma[g] * inverse_tau;
          if (!std::isnan(in.group_lambda[g])) torsion = in.group_lambda[g] * inverse_tau * inverse_tau;
        }
        if (-along > 0.0) force += (e + Vec2{e.y, -e.x}) * (back * m * v0);
        // Motive torque, eq. (16) with the restoring sign (ERRATA 4).
        if (turning[k]) torque += torsion * inertia * gain[k] * angle[k];
        // Rotational damping, eq. (17), with its own relaxation time (ERRATA 8).
        torque -= inertia * rotation_damping * bodies_.angular_velocity_rad_per_s[i];
        force += slope_acceleration * m;
      }
      bodies_.force_n[i] = force;
      bodies_.torque_n_m[i] = torque;
    }
  }
}

// u_i <- u_i + (1 - exp(-h/T)) (e_i . v_i - u_i): the exact update of
// du/dt = (e.v - u)/T for e.v constant over the step, once per step after
// the integrator (not in Drive, which also runs outside steps).
void Simulation::AverageBackForceTrigger() {
  const ModelParameters& mp = def_.parameters;
  if (mp.back_force_trigger != BackForceTrigger::kAveragedVelocity) return;
  std::vector<double>& u = in_->averaged_along;
  const double a = -std::expm1(-dt_s_ / mp.back_force_reaction_time_s);
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_.state[i] != PersonState::kWalking) continue;
    const Vec2 e = def_.targets[bodies_.target[i]].Direction(bodies_.position_m[i], in_->field_cache[i]);
    u[i] += a * (Dot(e, bodies_.velocity_m_per_s[i]) - u[i]);
  }
}

}  // namespace crowdrecon::engine
