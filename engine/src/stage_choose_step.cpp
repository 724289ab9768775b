// Stage choose_step: the adaptive step (TimeStepMode::kAdaptive; issue 42,
// docs/decisions.md "An adaptive step").
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
//
// The fixed step is chosen so that a collision's restitution is right within
// ~2 % at any impact speed (ERRATA 12). What a wrong restitution costs is a
// velocity error of that share of the impact speed: a collision at 0.05 m/s
// suffers a twentieth of the error of one at 1 m/s at the same step. So the
// step may double while every approach is slow: a step of level l (2^l fixed
// steps) is taken only while every pair of people, or person and wall, that
// may touch before two of the largest steps have passed approaches at most at
// level_speed_[l] = v_ref err(h) / err(2^l h), where err is the restitution
// error measured at each step (RestitutionErrorAtStep). No collision then
// ends with a larger velocity error than the fixed step gives one at v_ref.
//
// The bounds are conservative and cheap: a pair "may touch" when the gap of
// its bounding circles is at most its speed times the reach, and its speed is
// |v_a - v_b| + r_a |w_a| + r_b |w_b| (every point of a relative to every
// point of b, r the bounding radius), the approach speed of any contact it
// could make. Velocities are those the contact law will see (after the
// drift), positions the step's end: the step after this one is chosen from
// the state at its start. Levels go down at once (a finer step always fits
// the tick grid) and up only where the ticks are a multiple of the new step,
// so steps never straddle a frame that is a multiple of the largest step.
// The choice reads the state only, in a fixed way (a maximum), so it is the
// same on any number of threads and after a resume (the level is saved).
#include "simulation_internals.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

void Simulation::SetUpAdaptiveStep() {
  const ModelParameters& mp = def_.parameters;
  max_level_ = 0;
  level_ = next_level_ = 0;
  level_speed_.assign(1, std::numeric_limits<double>::infinity());
  if (mp.time_step_mode != TimeStepMode::kAdaptive) return;
  // The levels the parameters allow, fewer if the fixed step was given
  // larger than time_step_safety of the limit.
  const int allowed = AdaptiveStepLevels(mp);
  while (max_level_ < allowed &&
         std::ldexp(tick_s_, max_level_ + 1) <= mp.adaptive_max_safety * dt_estimate_.stability_limit_s * (1.0 + 1e-12))
    ++max_level_;
  reference_speed_m_per_s_ = mp.adaptive_reference_speed_m_per_s;
  if (reference_speed_m_per_s_ == 0.0)
    for (const PersonDef& p : def_.people) reference_speed_m_per_s_ = std::max(reference_speed_m_per_s_, p.desired_speed_m_per_s);
  level_speed_ = AdaptiveLevelSpeeds(def_, tick_s_, max_level_, reference_speed_m_per_s_);
  // The longest collision: the heaviest person against a wall (one contact
  // point, m_ij = m), half a damped period. A collision's impact speed is
  // remembered that long, and then fades over as long again.
  double heaviest = 0.0;
  for (const PersonDef& p : def_.people) heaviest = std::max(heaviest, p.mass_kg);
  const double omega = std::sqrt(mp.normal_stiffness_n_per_m / std::max(heaviest, 1.0));
  const double l = -std::log(std::min(mp.restitution, mp.wall_restitution));
  const double zeta = l / std::sqrt(std::numbers::pi * std::numbers::pi + l * l);
  collision_s_ = std::numbers::pi / (omega * std::sqrt(1.0 - zeta * zeta));
}

void Simulation::ChooseStep(std::uint64_t ticks_after) {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kChooseStep)]);
  const Internals& in = *in_;
  const std::vector<Vec2>& x = bodies_.position_m;
  const std::vector<Vec2>& v = bodies_.velocity_m_per_s;
  const std::vector<double>& w = bodies_.angular_velocity_rad_per_s;
  const double reach = 2.0 * LargestStep();
  const auto removed = [&](std::uint32_t i) { return bodies_.state[i] == PersonState::kRemoved; };
  double fastest = 0.0;
  const std::int64_t pair_count = static_cast<std::int64_t>(in.pairs.size());
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (pair_count >= 8 * kParallelBodies) \
    reduction(max : fastest)
  for (std::int64_t k = 0; k < pair_count; ++k) {
    const auto [a, b] = in.pairs[static_cast<std::size_t>(k)];
    if (removed(a) || removed(b)) continue;
    const double speed = Length(v[a] - v[b]) + in.bound_m[a] * std::abs(w[a]) + in.bound_m[b] * std::abs(w[b]);
    if (!(speed > fastest)) continue;
    const double gap = Length(detail::Separation(def_.periodic, x[a], x[b])) - in.bound_m[a] - in.bound_m[b];
    if (gap <= speed * reach) fastest = speed;
  }
  for (const auto& [a, wall_index] : in.wall_pairs) {
    if (removed(a) || !WallEnabled(wall_index)) continue;
    const double speed = Length(v[a]) + in.bound_m[a] * std::abs(w[a]);
    if (!(speed > fastest)) continue;
    const Wall& wall = def_.walls[wall_index];
    const std::size_t segments = wall.closed ? wall.points.size() : wall.points.size() - 1;
    const double reach_m = in.bound_m[a] + wall.radius_m + speed * reach;
    for (std::size_t seg = 0; seg < segments; ++seg)
      if (DistanceToSegment(x[a], wall.points[seg], wall.points[(seg + 1) % wall.points.size()]) <= reach_m) {
        fastest = speed;
        break;
      }
  }
  // The recent past's fastest approach: held for a collision's length, then fading.
  approach_age_s_ += dt_s_;  // (the step being taken)
  const double remembered = approach_age_s_ <= collision_s_
                                ? approach_memory_m_per_s_
                                : approach_memory_m_per_s_ * std::exp(-(approach_age_s_ - collision_s_) / collision_s_);
  if (fastest >= remembered) {
    approach_memory_m_per_s_ = fastest;
    approach_age_s_ = 0.0;
  } else {
    fastest = remembered;
  }
  // The largest level whose speed allows the fastest approach, and up only
  // onto the grid of its own step.
  int level = 0;
  while (level < max_level_ && fastest <= level_speed_[static_cast<std::size_t>(level) + 1]) ++level;
  while (level > level_ && ticks_after % (std::uint64_t{1} << level) != 0) --level;
  next_level_ = level;
  next_dt_s_ = std::ldexp(tick_s_, level);
}

}  // namespace crowdrecon::engine
