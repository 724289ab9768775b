// Stage drive: the ground reaction forces and torques of the run's behaviour
// terms (behaviour.hpp: eqs. 3, 15, 16, 17, the floor slope, the extensions).
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
#include "simulation_internals.hpp"

#include "behaviour.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "crowdrecon/common/fast_math.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

namespace {

// Per walking person, the sum over their contacts with people ahead of the
// parts that push them back against e_i (<= 0; `desired` receives each
// walking person's e_i): what yielding and the shoulder's turn read
// (BehaviourTerm::needs_people_ahead). Walls do not count: a door's jamb
// guides a person through, it does not make them wait; people beside and
// behind do not count either. "Ahead": the contact point within 45 degrees
// of e_i seen from the person's centre (the person in front, not the
// shoulders beside, which would make everyone at a door wait for everyone).
// One pass over the contact list in its order: the same sums on any thread
// count, and from the restored contacts after a resume.
void HeldBackByPeopleAhead(const BodyState& bodies, const std::vector<Contact>& contacts, const WorldDef& def,
                           std::vector<geometry::NavigationField::CellCache>& field_cache, std::vector<Vec2>& desired,
                           std::vector<double>& held) {
  held.assign(bodies.size(), 0.0);
  DesiredDirections(bodies, def, field_cache, desired);
  constexpr double kAheadCosine = 0.70710678118654752;  // cos 45 degrees
  const auto ahead = [](Vec2 arm, Vec2 e) { return Dot(arm, e) >= kAheadCosine * Length(arm); };
  for (const Contact& c : contacts) {
    if (c.wall) continue;
    const Vec2 f = c.Force();  // on a; -f on b
    const Vec2 xa = bodies.position_m[c.a];
    const Vec2 xb = xa - Separation(def.periodic, xa, bodies.position_m[c.b]);  // b's image near a
    if (ahead(c.point_m - xa, desired[c.a])) held[c.a] += std::min(0.0, Dot(f, desired[c.a]));
    if (ahead(c.point_m - xb, desired[c.b])) held[c.b] += std::min(0.0, -Dot(f, desired[c.b]));
  }
}

}  // namespace

double SlopeWalkingFactor(double grade) {
  // Tobler (1993): W = 6 exp(-3.5 |s + 0.05|) km/h, relative to the level's.
  return std::exp(-3.5 * (std::abs(grade + 0.05) - 0.05));
}

// The drive asks the run's behaviour terms (behaviour.hpp) for each block of
// people, phase by phase, and knows none of them by name.
void Simulation::Drive() {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kDrive)]);
  Internals& in = *in_;
  const ActiveTerms& terms = in.terms;
  const ModelParameters& mp = def_.parameters;
  if (terms.people_ahead)
    HeldBackByPeopleAhead(bodies_, contacts_, def_, in.field_cache, in.desired_direction, in.held_back_n);
  const DriveInputs inputs{bodies_,        def_,          1.0 / mp.relaxation_time_s, in.drive_time_s,
                           in.cos_angle,   in.sin_angle,  in.held_back_n,             in.group_gamma,
                           in.group_lambda, in.neighbours};
  for (const BehaviourTerm* t : terms.prepare) t->Prepare(inputs);
  std::vector<geometry::NavigationField::CellCache>& field_cache = in.field_cache;
  const std::int64_t n = static_cast<std::int64_t>(bodies_.size());
  constexpr auto kBlock = static_cast<std::int64_t>(kDriveBlock);
  const std::int64_t blocks = (n + kBlock - 1) / kBlock;
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (n >= kParallelBodies)
  for (std::int64_t block = 0; block < blocks; ++block) {
    DriveBlock b;
    b.first = static_cast<std::size_t>(block * kBlock);
    b.count = static_cast<std::size_t>(std::min(n, (block + 1) * kBlock)) - b.first;
    // A block of empty slots (a timeline's engine keeps hundreds, filled
    // from the lowest): nothing to drive, nothing written.
    bool anyone = false;
    for (std::size_t k = 0; k < b.count && !anyone; ++k) anyone = bodies_.state[b.first + k] != PersonState::kRemoved;
    if (!anyone) continue;
    // What every person starts from: their target's direction (looked up
    // already where the terms needed people ahead), v0, v, no facing, and
    // the forces of the contacts and the external force.
    for (std::size_t k = 0; k < b.count; ++k) {
      const std::size_t i = b.first + k;
      // (A sleeper's drive is frozen: added below, docs/model.md "Sleeping".)
      b.driven[k] = bodies_.state[i] == PersonState::kWalking && mp.ground_reaction && !in.Asleep(i);
      b.force[k] = bodies_.contact_force_n[i] + bodies_.external_force_n[i];
      b.torque[k] = bodies_.contact_torque_n_m[i];
      b.facing[k] = Vec2{};
      b.gain[k] = 0.0;
      if (!b.driven[k]) continue;
      b.direction[k] = terms.people_ahead ? in.desired_direction[i]
                                          : def_.targets[bodies_.target[i]].Direction(bodies_.position_m[i], field_cache[i]);
      b.pace[k] = bodies_.desired_speed_m_per_s[i];
      b.from[k] = bodies_.velocity_m_per_s[i];
    }
    for (const BehaviourTerm* t : terms.direction) t->Direction(inputs, b);
    for (std::size_t k = 0; k < b.count; ++k) b.heading[k] = b.direction[k];
    for (const BehaviourTerm* t : terms.steer) t->Steer(inputs, b);
    for (const BehaviourTerm* t : terms.desire) t->Desire(inputs, b);
    for (const BehaviourTerm* t : terms.facing) t->Facing(inputs, b);
    // theta_D - theta wrapped to (-pi, pi], from the body's orientation (cos,
    // sin from place_shapes) to the facing: a long chain of dependent
    // operations (a division, a polynomial), in a short loop of its own,
    // whose iterations the processor overlaps.
    double sine[kDriveBlock], cosine[kDriveBlock];
    for (std::size_t k = 0; k < b.count; ++k) {
      const std::size_t i = b.first + k;
      const Vec2 facing = b.facing[k];
      b.turning[k] = b.driven[k] && (facing.x != 0.0 || facing.y != 0.0);
      const Vec2 orientation{in.cos_angle[i], in.sin_angle[i]};
      sine[k] = b.turning[k] ? Cross(orientation, facing) : 0.0;
      cosine[k] = b.turning[k] ? Dot(orientation, facing) : 1.0;
    }
    for (std::size_t k = 0; k < b.count; ++k) b.angle[k] = Atan2(sine[k], cosine[k]);
    for (const BehaviourTerm* t : terms.force) t->Force(inputs, b);
    for (std::size_t k = 0; k < b.count; ++k) {
      const std::size_t i = b.first + k;
      if (bodies_.state[i] == PersonState::kRemoved) continue;  // no forces (zeroed when removed)
      bodies_.force_n[i] = b.force[k];
      bodies_.torque_n_m[i] = b.torque[k];
      if (in.Asleep(i)) {
        bodies_.force_n[i] += in.sleep_drive_force[i];
        bodies_.torque_n_m[i] += in.sleep_drive_torque[i];
      }
    }
  }
}

std::vector<std::string> Simulation::BehaviourTermNames() const {
  std::vector<std::string> names;
  for (const ActiveTerms::Active& t : in_->terms.terms) names.emplace_back(t.entry->name);
  return names;
}

// The terms' updates after each step (their per-person state), in the list's
// order, serially (after the integrator; not in Drive, which also runs
// outside steps).
void Simulation::UpdateBehaviourTerms() {
  const StepInputs inputs{bodies_, def_, contacts_, in_->field_cache, dt_s_};
  for (BehaviourTerm* t : in_->terms.after_step) t->AfterStep(inputs);
}

}  // namespace crowdrecon::engine
