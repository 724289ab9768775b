// Stage drive: ground reaction forces and torques (eqs. 3, 15, 16, 17) and the floor slope.
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
#include "simulation_internals.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "crowdrecon/common/fast_math.hpp"
#include "crowdrecon/common/polygon.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

namespace {

// SplitMix64's finaliser (Steele, Lea and Flood, OOPSLA 2014): a 64-bit
// hash whose outputs pass statistical tests as random numbers.
std::uint64_t Mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
double UnitInterval(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }  // [0, 1)

// Cosines per axis of a person's gait jitter: four give a nearly Gaussian
// sum (its kurtosis is 3 - 3/(2K) = 2.63 instead of 3) at 8 cosines a person.
constexpr int kJitterComponents = 4;

// u_i(t) of the gait jitter (ModelParameters::gait_jitter): per axis
// sigma sqrt(2/K) sum_k cos(2 pi (f_k t + phi_k)), f_k uniform in the band
// and phi_k uniform in [0, 1), drawn from the seed and the person's id. A
// sum of cosines with random phases and frequencies drawn from a spectrum
// is the spectral representation of a stationary random process
// (Shinozuka and Deodatis, Appl. Mech. Rev. 44:191, 1991): its variance is
// sigma^2 and its expected spectrum flat in the band. It is a function of
// time alone: no state to save, the same on any thread count and resume.
Vec2 JitterVelocity(std::uint64_t seed, std::uint32_t id, double t_s, const ModelParameters& mp) {
  const double amplitude = mp.gait_jitter_velocity_m_per_s * std::sqrt(2.0 / kJitterComponents);
  const double f_low = mp.gait_jitter_band_low_hz, f_span = mp.gait_jitter_band_high_hz - mp.gait_jitter_band_low_hz;
  std::uint64_t h = Mix(seed ^ Mix(std::uint64_t{id} + 1));
  double axis_sum[2];
  for (double& sum : axis_sum) {
    sum = 0.0;
    for (int k = 0; k < kJitterComponents; ++k) {
      h = Mix(h);
      const double frequency = f_low + f_span * UnitInterval(h);
      h = Mix(h);
      const double cycles = frequency * t_s + UnitInterval(h);
      double sine, cosine;
      SinCos(2.0 * std::numbers::pi * (cycles - std::floor(cycles)), sine, cosine);
      sum += cosine;
    }
  }
  return Vec2{axis_sum[0], axis_sum[1]} * amplitude;
}

// Yielding (ModelParameters::yielding): per person, the sum over their
// contacts with people ahead of the parts that push them back against e_i
// (<= 0; `desired` receives each walking person's e_i). Walls do not count:
// a door's jamb guides a person through, it does not make them wait; people
// beside and behind do not count either. "Ahead": the contact point within
// 45 degrees of e_i seen from the person's centre (the person in front, not
// the shoulders beside, which would make everyone at a door wait for
// everyone). One pass over the contact list in its order: the same sums on
// any thread count, and from the restored contacts after a resume.
// Each walking person's desired direction e_i (zero for the others), for
// the extensions that need everyone's before the per-person pass.
void DesiredDirections(const BodyState& bodies, const WorldDef& def,
                       std::vector<geometry::NavigationField::CellCache>& field_cache, std::vector<Vec2>& desired) {
  desired.assign(bodies.size(), Vec2{});
  for (std::size_t i = 0; i < bodies.size(); ++i)
    if (bodies.state[i] == PersonState::kWalking)
      desired[i] = def.targets[bodies.target[i]].Direction(bodies.position_m[i], field_cache[i]);
}

// The facing of a blocked person who turns a shoulder into the way: e
// rotated by the turn (cos, sin) to whichever side is nearer `orientation`.
Vec2 ShoulderFacing(Vec2 e, Vec2 turn, Vec2 orientation) {
  const Vec2 left{e.x * turn.x - e.y * turn.y, e.x * turn.y + e.y * turn.x};
  const Vec2 right{e.x * turn.x + e.y * turn.y, -e.x * turn.y + e.y * turn.x};
  return Dot(orientation, left) >= Dot(orientation, right) ? left : right;
}

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
  const std::vector<Vec2>& slope_region = def_.slope.region;  // (empty: the whole floor)
  const bool slope_held = mp.slope_response == SlopeResponse::kHeld && slope_force_per_kg > 0.0;
  const bool yielding = mp.yielding == Yielding::kWhenBlocked;
  const bool shoulder_turn = mp.shoulder_turn == ShoulderTurn::kWhenBlocked;
  const bool blocked_known = yielding || shoulder_turn;
  const bool giving_way = mp.give_way == GiveWay::kWhereRoom;
  const bool lagged = mp.drive_reaction == DriveReaction::kLagged;
  if (blocked_known) HeldBackByPeopleAhead(bodies_, contacts_, def_, field_cache, in_->yield_direction, in_->held_back_n);
  // The shoulder's turn as a rotation of e_i (cos, sin of the turn angle).
  const double turn_rad = mp.shoulder_turn_angle_deg * (std::numbers::pi / 180.0);
  const Vec2 turn = shoulder_turn ? Vec2{std::cos(turn_rad), std::sin(turn_rad)} : Vec2{};
  const bool jitter = mp.gait_jitter == GaitJitter::kIsotropic && mp.gait_jitter_velocity_m_per_s > 0.0;
  const auto jitter_seed = static_cast<std::uint64_t>(mp.gait_jitter_seed);
  const double drive_time_s = in.drive_time_s;
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
      // (Yielding and the shoulder's turn have looked every walking person's direction up already.)
      direction[k] = blocked_known ? in.yield_direction[i]
                                   : def_.targets[bodies_.target[i]].Direction(bodies_.position_m[i], field_cache[i]);
      // Giving way (issue 39, off by default): the way of the people they gave way to.
      if (giving_way && in.give_way_left_s[i] > 0.0) direction[k] = in.give_way_direction[i];
      const double speed = Length(v);
      const Vec2 orientation{in.cos_angle[i], in.sin_angle[i]};
      // Turning the shoulder (issue 39, off by default): a blocked person
      // turns e_i by the turn angle to the nearer side, on purpose (full
      // gain, not eq. 16's share of the speed).
      const bool turn_shoulder = shoulder_turn && in.held_back_n[i] < 0.0;
      // Only the direction of `facing` matters to the angle (atan2 of two
      // products with it), so the velocity needs no normalising.
      const Vec2 facing = turn_shoulder ? ShoulderFacing(direction[k], turn, orientation)
                                        : face_velocity ? v : direction[k];
      if (facing.x != 0.0 || facing.y != 0.0) {
        turning[k] = true;
        sine[k] = Cross(orientation, facing);
        cosine[k] = Dot(orientation, facing);
        const double v0 = bodies_.desired_speed_m_per_s[i];
        gain[k] = turn_shoulder ? 1.0 : v0 > 0.0 ? 1.0 - std::exp(-speed / v0) : 1.0;
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
        // Yielding (issue 39, off by default): held up by the people ahead,
        // the person drives toward a share of v0 (eq. 3's v0 e_i, scaled).
        double pace = yielding && in.held_back_n[i] < 0.0 ? v0 * mp.yielding_push_share : v0;
        // (The region is looked up only where the floor slopes at all.)
        const bool on_slope =
            slope_region.empty() || (slope_force_per_kg > 0.0 && PointInPolygon(slope_region, bodies_.position_m[i]));
        // A held slope (issue 43, off by default): the legs hold its pull,
        // and the pace follows the grade along e (Tobler's hiking function).
        if (slope_held && on_slope) pace *= SlopeWalkingFactor(-def_.slope.gradient * Dot(e, def_.slope.downhill));
        // A reaction time (issue 39, off by default): eq. (3) from the perceived velocity w_i.
        const Vec2 from = lagged ? in.perceived_velocity[i] : v;
        force += (e * pace - from) * (m * inverse_tau);  // eq. (3)
        // Gait jitter (issue 39, off by default): eq. (3)'s desired velocity plus u_i(t).
        if (jitter) force += JitterVelocity(jitter_seed, bodies_.id[i], drive_time_s, mp) * (m * inverse_tau);
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
        if (!slope_held && on_slope) force += slope_acceleration * m;
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

// w_i <- w_i + (1 - exp(-h/T)) (v_i - w_i): the exact update of the
// perceived velocity's dw/dt = (v - w)/T for v constant over the step, once
// per step after the integrator (as the back force's averaged trigger).
// People who are not walking perceive that they stand (SetPersonState).
void Simulation::UpdatePerceivedVelocity() {
  const ModelParameters& mp = def_.parameters;
  if (mp.drive_reaction != DriveReaction::kLagged) return;
  std::vector<Vec2>& w = in_->perceived_velocity;
  const double a = -std::expm1(-dt_s_ / mp.drive_reaction_time_s);
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_.state[i] == PersonState::kWalking) w[i] += (bodies_.velocity_m_per_s[i] - w[i]) * a;
}

// Giving way (ModelParameters::give_way), once per step after the
// integrator, in one serial pass (the same on any thread count; its state is
// in the checkpoint): per walking person, the velocity along e_i averaged
// over 1 s (the exact update of du/dt = (e.v - u)/T, as the back force's
// trigger), the time it has stayed below the threshold, and, once that time
// reaches give_way_blocked_s, whether to give way: touching at most
// give_way_max_contacts people (room to turn) whose desired directions sum
// against e_i (most of them head the other way). Then the person walks that
// way for give_way_duration_s, and starts afresh.
void Simulation::UpdateGiveWay() {
  const ModelParameters& mp = def_.parameters;
  if (mp.give_way != GiveWay::kWhereRoom) return;
  Internals& in = *in_;
  const std::size_t n = bodies_.size();
  // Each walking person's own desired direction, then, per person, the
  // people they touch and the sum of those people's directions.
  std::vector<Vec2>& desired = in.yield_direction;
  DesiredDirections(bodies_, def_, in.field_cache, desired);
  std::vector<int>& touching = in.give_way_touching;
  std::vector<Vec2>& their_way = in.give_way_their_way;
  touching.assign(n, 0);
  their_way.assign(n, Vec2{});
  std::uint32_t last_a = UINT32_MAX, last_b = UINT32_MAX;
  for (const Contact& c : contacts_) {
    if (c.wall || (c.a == last_a && c.b == last_b)) continue;  // a pair once, whatever its features
    last_a = c.a;
    last_b = c.b;
    ++touching[c.a];
    ++touching[c.b];
    their_way[c.a] += desired[c.b];
    their_way[c.b] += desired[c.a];
  }
  const double h = dt_s_;
  const double a = -std::expm1(-h / 1.0);  // averaged over 1 s
  for (std::size_t i = 0; i < n; ++i) {
    if (bodies_.state[i] != PersonState::kWalking) continue;
    const Vec2 e = desired[i];
    in.give_way_along[i] += a * (Dot(e, bodies_.velocity_m_per_s[i]) - in.give_way_along[i]);
    if (in.give_way_left_s[i] > 0.0) {
      in.give_way_left_s[i] = std::max(0.0, in.give_way_left_s[i] - h);
      continue;
    }
    in.give_way_blocked_s[i] = in.give_way_along[i] < mp.give_way_speed_m_per_s ? in.give_way_blocked_s[i] + h : 0.0;
    if (in.give_way_blocked_s[i] < mp.give_way_blocked_s) continue;
    const Vec2 way = their_way[i];
    if (touching[i] > static_cast<int>(mp.give_way_max_contacts) || !(Dot(way, e) < 0.0)) continue;
    in.give_way_direction[i] = way * (1.0 / Length(way));
    in.give_way_left_s[i] = mp.give_way_duration_s;
    in.give_way_blocked_s[i] = 0.0;
  }
}

}  // namespace crowdrecon::engine
