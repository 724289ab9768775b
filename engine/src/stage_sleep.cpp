// Stage sleep: who falls asleep and who wakes (ModelParameters::
// sleep_speed_m_per_s > 0; docs/model.md, "Sleeping"; issue 66).
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
//
// Box2D puts islands of touching bodies to sleep when all of them have been
// at rest for a while. A crowd's gridlock is one island whose edges never
// rest (people there keep shifting), so here each person sleeps on their own:
// still for sleep_time_s. A sleeper is held where it is (the integrate stage
// skips it), its drive is frozen (the drive stage adds the force and torque
// that held its mean load while it was still: see Sleep),
// and its contacts with other sleepers and with walls are carried from step
// to step (the collide stage); its contacts with the awake are computed at
// every step, and they are what wakes it: the net force on a sleeper (frozen
// drive plus every contact) or the torque grows past the bound. A change
// that concerns a sleeper (its target, desired speed, external force,
// state, its group's drive, the parameters, a wall) wakes it at once.
#include "simulation_internals.hpp"

#include <algorithm>
#include <cmath>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

// Everyone awake with no still spell; nothing at all with sleeping off.
void Simulation::SetUpSleeping() {
  Internals& in = *in_;
  const std::size_t n = def_.parameters.sleep_speed_m_per_s > 0.0 ? bodies_.size() : 0;
  in.asleep.assign(n, 0);
  in.still_s.assign(n, 0.0);
  in.sleep_drive_force.assign(n, Vec2{});
  in.sleep_drive_torque.assign(n, 0.0);
  in.sleep_anchor.assign(n, Vec2{});
  in.sleep_anchor_angle.assign(n, 0.0);
}

void Simulation::Wake(std::uint32_t person) {  // (a new still spell begins at its next Sleep)
  Internals& in = *in_;
  if (in.asleep.empty()) return;
  in.asleep[person] = 0;
  in.still_s[person] = 0.0;
}

void Simulation::WakeAll() {
  Internals& in = *in_;
  std::fill(in.asleep.begin(), in.asleep.end(), std::uint8_t{0});
  std::fill(in.still_s.begin(), in.still_s.end(), 0.0);
}

std::size_t Simulation::asleep_count() const {
  return static_cast<std::size_t>(std::count(in_->asleep.begin(), in_->asleep.end(), std::uint8_t{1}));
}

bool Simulation::asleep(std::uint32_t person) const { return person < bodies_.size() && in_->Asleep(person); }

// Each person on their own, from the forces of the step's last evaluation
// and the positions at its end: the same on any thread count.
//
// Still means staying put: within sleep_speed_m_per_s x sleep_time_s of
// where the still spell began (and turned by no more than that at the
// body's rim) for sleep_time_s. Not the velocity of one step: a person held
// in a packed crowd vibrates at its contacts' frequency (with the gait's
// jitter, at centimetres per second) while going nowhere. Nor the force of
// one step: the paper's back force switches on and off at every step for a
// person at rest (eq. 15's Theta of a velocity that changes sign). A body
// that stayed put for T_s felt a net force near zero on average, and what a
// sleeper holds is the mean of its load (contacts and external force) over
// its still spell; its frozen drive is that mean turned round, so the net
// force on a sleeper is how far its load has moved from it, and past
// sleep_wake_force_n it wakes.
void Simulation::Sleep() {
  Internals& in = *in_;
  if (in.asleep.empty()) return;
  ScopedTimer timer(profile_.stage_s[Index(Stage::kSleep)]);
  const ModelParameters& mp = def_.parameters;
  const double reach = mp.sleep_speed_m_per_s * mp.sleep_time_s, bound = mp.sleep_wake_force_n;
  const double h = last_step_s();
  const std::int64_t count = static_cast<std::int64_t>(bodies_.size());
  std::uint64_t walking = 0, sleeping = 0;
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies) \
    reduction(+ : walking, sleeping)
  for (std::int64_t ii = 0; ii < count; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    if (bodies_.state[i] != PersonState::kWalking) {
      in.asleep[i] = 0;
      in.still_s[i] = 0.0;
      continue;
    }
    ++walking;
    const double arm = in.rotation_arm_m[i];
    if (in.asleep[i] != 0) {
      if (LengthSquared(bodies_.force_n[i]) > bound * bound || std::abs(bodies_.torque_n_m[i]) > bound * arm) {
        in.asleep[i] = 0;
        in.still_s[i] = 0.0;
      } else {
        ++sleeping;
      }
      continue;
    }
    const Vec2 x = bodies_.position_m[i];
    const double angle = bodies_.angle_rad[i];
    const Vec2 held = -(bodies_.contact_force_n[i] + bodies_.external_force_n[i]);
    const double held_torque = -bodies_.contact_torque_n_m[i];
    const bool put = in.still_s[i] > 0.0 && LengthSquared(Separation(x, in.sleep_anchor[i])) <= reach * reach &&
                     std::abs(angle - in.sleep_anchor_angle[i]) * arm <= reach;
    if (!put) {  // a still spell begins here
      in.sleep_anchor[i] = x;
      in.sleep_anchor_angle[i] = angle;
      in.still_s[i] = h;
      in.sleep_drive_force[i] = held;
      in.sleep_drive_torque[i] = held_torque;
      continue;
    }
    // The mean load of the spell (time-weighted: the steps may differ),
    // kept turned round as the drive a sleep would freeze.
    in.still_s[i] += h;
    const double share = h / in.still_s[i];
    in.sleep_drive_force[i] += (held - in.sleep_drive_force[i]) * share;
    in.sleep_drive_torque[i] += (held_torque - in.sleep_drive_torque[i]) * share;
    if (in.still_s[i] < mp.sleep_time_s) continue;
    in.asleep[i] = 1;
    ++sleeping;
    bodies_.velocity_m_per_s[i] = {};
    bodies_.angular_velocity_rad_per_s[i] = 0.0;
    // (Its force of this evaluation, as the drive stage now sums it.)
    bodies_.force_n[i] = bodies_.contact_force_n[i] + bodies_.external_force_n[i] + in.sleep_drive_force[i];
    bodies_.torque_n_m[i] = bodies_.contact_torque_n_m[i] + in.sleep_drive_torque[i];
  }
  profile_.walking_person_steps += walking;
  profile_.sleeping_person_steps += sleeping;
}

}  // namespace crowdrecon::engine
