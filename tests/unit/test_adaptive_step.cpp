// The adaptive step (ModelParameters::time_step_mode = adaptive; issue 42,
// docs/decisions.md "An adaptive step"): the analytic checks of the engine
// with it (restitution over impact speeds, friction, momentum, energy, static
// loads), its determinism (threads, resume) and its bookkeeping (ticks, levels).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "crowdrecon/common/error.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::engine {
namespace {

using testing::DiskOnWall;
using testing::DiskShape;
using testing::PassiveWorld;
using testing::RandomGas;
using testing::SetMassFromShape;
using testing::SlideDuringSecondSecond;
using testing::ThoraxLikeShape;

void MakeAdaptive(WorldDef& def, double reference_speed = 1.0) {
  def.parameters.time_step_mode = TimeStepMode::kAdaptive;
  def.parameters.adaptive_reference_speed_m_per_s = reference_speed;
}

struct Collision {
  double restitution = 0.0;
  std::uint64_t top_level_steps = 0;
};

// Two chests meet head-on at relative speed `speed`; `gap` sets where within
// a step the contact begins. The measured restitution once they separate.
Collision HeadOn(double speed, double eps, double gap, TimeStepMode mode) {
  WorldDef def = PassiveWorld();
  def.parameters.restitution = eps;
  if (mode == TimeStepMode::kAdaptive) MakeAdaptive(def);
  def.shapes.push_back(ThoraxLikeShape());
  PersonDef a, b;
  SetMassFromShape(def.shapes[0], 1000.0, a);
  SetMassFromShape(def.shapes[0], 1000.0, b);
  b.mass_kg *= 1.3;
  b.inertia_kg_m2 *= 1.3;
  a.position_m = {-(0.07 + 0.05 + gap / 2), 0.0};
  b.position_m = {0.07 + 0.05 + gap / 2, 0.0};
  b.angle_rad = std::numbers::pi;
  a.velocity_m_per_s = {0.6 * speed, 0.0};
  b.velocity_m_per_s = {-0.4 * speed, 0.0};
  def.people = {a, b};
  Simulation sim(def);
  bool touched = false;
  for (int k = 0; k < 2000000; ++k) {
    sim.Step();
    if (!sim.contacts().empty()) touched = true;
    if (touched && sim.contacts().empty()) break;
  }
  EXPECT_TRUE(touched);
  const auto& v = sim.bodies().velocity_m_per_s;
  return {(v[1].x - v[0].x) / speed, sim.profile().steps_at_level[static_cast<std::size_t>(sim.max_step_level())]};
}

// The contract: a collision at the reference speed or faster keeps the fixed
// step's relative accuracy (2 %); a slower one may be computed with a longer
// step, but its velocity error, |eps' - eps| times the impact speed, never
// exceeds what the fixed step allows a collision at the reference speed.
TEST(AdaptiveStep, CollisionsKeepTheFixedStepsVelocityErrorAtEveryImpactSpeed) {
  const double reference = 1.0, fixed_error = 0.02;
  for (double eps : {0.1, 0.4})
    for (double speed : {0.005, 0.02, 0.1, 0.3, 1.0, 2.0}) {
      double worst = 0.0;
      std::uint64_t top = 0;
      for (int phase = 0; phase < 5; ++phase) {
        // Contact 20 ms after the start, plus a fifth of the longest step
        // (4 fixed steps of ~0.54 ms) per phase: phases across a step.
        const Collision c = HeadOn(speed, eps, speed * (0.02 + phase * 0.2 * 4 * 5.4e-4), TimeStepMode::kAdaptive);
        worst = std::max(worst, std::abs(c.restitution / eps - 1.0));
        top += c.top_level_steps;
      }
      const std::string what = "eps " + std::to_string(eps) + ", impact at " + std::to_string(speed) + " m/s";
      if (speed >= reference) {
        EXPECT_LT(worst, fixed_error) << what;
      } else {
        EXPECT_LE(worst * eps * speed, fixed_error * eps * reference) << what << ": relative error " << worst;
      }
      if (speed <= 0.02) {
        EXPECT_GT(top, 0u) << what << ": the slow collision was not given the longest step";
      }
    }
}

// The step must not change what friction holds: a body pressed onto a wall
// sticks below mu Fn and slides above it (EnginePhysics' scene, at rest, where
// the adaptive step is at its longest).
TEST(AdaptiveStep, FrictionSticksBelowMuFnAndSlidesAbove) {
  WorldDef def = PassiveWorld();
  MakeAdaptive(def);
  def = DiskOnWall(def);
  const int top = Simulation(def).max_step_level();
  ASSERT_GT(top, 0);
  Profile profile;
  const double stick = SlideDuringSecondSecond(def, 0.95, &profile);
  EXPECT_GT(profile.steps_at_level[static_cast<std::size_t>(top)], 0u) << "the contact at rest was not given the longest step";
  const double slide = SlideDuringSecondSecond(def, 1.05);
  EXPECT_LT(std::abs(stick), 1e-6) << stick;
  EXPECT_GT(slide, 1e-3) << slide;
}

TEST(AdaptiveStep, MomentumIsConservedAndEnergyNeverCreated) {
  WorldDef def = RandomGas(6, 0.48, 11, true);
  MakeAdaptive(def, 1.5);
  for (PersonDef& p : def.people) p.velocity_m_per_s *= 0.2;  // slow enough for longer steps
  Simulation sim(def);
  const Vec2 p0 = sim.LinearMomentum();
  double scale = 0.0;
  for (const PersonDef& p : def.people) scale += p.mass_kg * Length(p.velocity_m_per_s);
  double previous = sim.KineticEnergy() + sim.ElasticEnergy();
  const double e0 = previous;
  double worst_rise = 0.0;
  while (sim.time_s() < 2.0) {
    sim.Step();
    const double e = sim.KineticEnergy() + sim.ElasticEnergy();
    worst_rise = std::max(worst_rise, e - previous);
    previous = e;
  }
  EXPECT_LT(Length(sim.LinearMomentum() - p0), 1e-9 * scale);
  EXPECT_LT(previous, 0.8 * e0);
  EXPECT_LT(worst_rise, 1e-3 * e0) << worst_rise;
  std::uint64_t longer = 0;
  for (std::size_t l = 1; l < sim.profile().steps_at_level.size(); ++l) longer += sim.profile().steps_at_level[l];
  EXPECT_GT(longer, 0u) << "the gas never took a longer step";
}

// A row of people walking into a wall comes to rest pressing on it with the
// sum of their driving forces, m v0 / tau each (eq. 3 at v = 0): the static
// loads do not depend on the step, within 1 % of the analytic value.
TEST(AdaptiveStep, AJammedRowPressesOnTheWallAsWithTheFixedStep) {
  const auto wall_load = [](TimeStepMode mode, double* chest_loads, std::uint64_t* longer) {
    WorldDef def;
    def.parameters.ground_reaction = true;
    def.parameters.back_force_gamma = 0.0;  // (eq. 15 would add its push back to the load)
    // (Facing the walking velocity, a row at rest turns by the noise of its
    // velocities, friction pushes sideways and the row buckles.)
    def.parameters.facing_target = FacingTarget::kDesiredDirection;
    if (mode == TimeStepMode::kAdaptive) MakeAdaptive(def, 0.0);  // (the people's desired speed)
    def.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
    def.shapes.push_back(DiskShape(0.2));
    for (int i = 0; i < 6; ++i) {
      PersonDef p;
      SetMassFromShape(def.shapes[0], 1000.0, p);
      p.mass_kg *= 1.0 + 0.05 * i;
      p.position_m = {-0.45 * (i + 1), 0.0};
      p.desired_speed_m_per_s = 1.0 + 0.02 * i;
      def.people.push_back(p);
    }
    def.walls.push_back({{{0.0, -5.0}, {0.0, 5.0}}, false, 0.0});
    Simulation sim(def);
    sim.AdvanceTo(20.0);
    double load = 0.0;
    for (const Contact& c : sim.contacts())
      if (c.wall) load += c.Force().x;
    for (int i = 0; i < 6; ++i) chest_loads[i] = 0.0;
    for (const Contact& c : sim.contacts()) {
      chest_loads[c.a] += Length(c.Force());
      if (!c.wall) chest_loads[c.b] += Length(c.Force());
    }
    *longer = sim.profile().steps_at_level[static_cast<std::size_t>(sim.max_step_level())];
    return std::abs(load);
  };
  double expected = 0.0;
  {
    PersonDef p;
    SetMassFromShape(DiskShape(0.2), 1000.0, p);
    for (int i = 0; i < 6; ++i) expected += p.mass_kg * (1.0 + 0.05 * i) * (1.0 + 0.02 * i) / ModelParameters{}.relaxation_time_s;
  }
  double fixed_chest[6], adaptive_chest[6];
  std::uint64_t fixed_longer = 0, adaptive_longer = 0;
  const double fixed = wall_load(TimeStepMode::kFixed, fixed_chest, &fixed_longer);
  const double adaptive = wall_load(TimeStepMode::kAdaptive, adaptive_chest, &adaptive_longer);
  EXPECT_NEAR(fixed, expected, 0.01 * expected);
  EXPECT_NEAR(adaptive, expected, 0.01 * expected);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(adaptive_chest[i], fixed_chest[i], 0.01 * fixed_chest[i]) << "person " << i + 1;
  EXPECT_GT(adaptive_longer, 0u) << "the row at rest was not given the longest step";
}

TEST(AdaptiveStep, StepsLandOnTheGridOfTheirLengthAndSayWhatTheyCrossed) {
  WorldDef def = RandomGas(6, 0.45, 21, true);
  def.parameters.ground_reaction = true;
  def.parameters.facing_target = FacingTarget::kDesiredDirection;  // (settling: no turning to a noisy velocity)
  MakeAdaptive(def, 1.0);
  for (PersonDef& p : def.people) {  // from fast to slow: through every level
    p.velocity_m_per_s *= 0.3;
    p.desired_speed_m_per_s = 0.05;
  }
  Simulation sim(def);
  const int top = sim.max_step_level();
  ASSERT_EQ(top, AdaptiveStepLevels(def.parameters));
  ASSERT_EQ(top, 2) << "0.32 / 0.08: four times the fixed step";
  EXPECT_EQ(sim.tick_s(), sim.time_step_estimate().chosen_s);
  std::uint64_t reached_10 = 0;
  while (sim.time_s() < 6.0) {
    const std::uint64_t before = sim.tick_count();
    const std::uint64_t length = std::uint64_t{1} << sim.step_level();
    ASSERT_EQ(before % length, 0u) << "a step of " << length << " ticks began at tick " << before;
    sim.Step();
    ASSERT_EQ(sim.tick_count(), before + length);
    ASSERT_EQ(sim.time_s(), static_cast<double>(sim.tick_count()) * sim.tick_s());
    ASSERT_EQ(sim.last_step_s(), sim.tick_s() * static_cast<double>(length));
    ASSERT_EQ(sim.LastStepReached(10), before / 10 != sim.tick_count() / 10);
    reached_10 += sim.LastStepReached(10) ? 1 : 0;
  }
  EXPECT_EQ(reached_10, sim.tick_count() / 10);
  // Every level was used, and the levels' speeds fall with the step.
  for (int l = 0; l <= top; ++l) EXPECT_GT(sim.profile().steps_at_level[static_cast<std::size_t>(l)], 0u) << l;
  const std::vector<double>& speeds = sim.step_level_speeds();
  ASSERT_EQ(speeds.size(), static_cast<std::size_t>(top) + 1);
  for (int l = 1; l <= top; ++l) EXPECT_LT(speeds[static_cast<std::size_t>(l)], speeds[static_cast<std::size_t>(l) - 1]);
}

TEST(AdaptiveStep, ResultsDoNotDependOnTheThreadCountOrAResume) {
  WorldDef def = RandomGas(8, 0.45, 21, true);
  def.parameters.ground_reaction = true;
  def.parameters.facing_target = FacingTarget::kDesiredDirection;
  MakeAdaptive(def, 1.0);
  for (PersonDef& p : def.people) {
    p.velocity_m_per_s *= 0.3;
    p.desired_speed_m_per_s = 0.05;
  }
  std::vector<Vec2> reference;
  std::uint64_t steps = 0;
  for (int threads : {1, 2, 3}) {
    def.threads = threads;
    Simulation sim(def);
    sim.AdvanceTo(6.0);
    const auto& x = sim.bodies().position_m;
    if (reference.empty()) {
      reference = x;
      steps = sim.step_count();
      EXPECT_LT(steps, sim.tick_count()) << "no longer step was taken";
    } else {
      ASSERT_EQ(std::memcmp(reference.data(), x.data(), x.size() * sizeof(Vec2)), 0) << threads;
      ASSERT_EQ(sim.step_count(), steps);
    }
  }
  def.threads = 1;
  // Interrupted at several moments (at whatever level the step then is).
  for (double stop : {0.1, 3.5, 5.3}) {
    Simulation first(def);
    first.AdvanceTo(stop);
    const std::string state = first.SaveState();
    Simulation resumed(def);
    resumed.LoadState(state);
    EXPECT_EQ(resumed.step_level(), first.step_level());
    EXPECT_EQ(resumed.tick_count(), first.tick_count());
    resumed.AdvanceTo(6.0);
    ASSERT_EQ(resumed.step_count(), steps) << stop;
    ASSERT_EQ(std::memcmp(reference.data(), resumed.bodies().position_m.data(), reference.size() * sizeof(Vec2)), 0)
        << stop;
  }
}

TEST(AdaptiveStep, TheFixedStepsRunIsUnchangedAndTheModeCannotChangeMidRun) {
  WorldDef def = RandomGas(6, 0.45, 3, true);
  def.parameters.ground_reaction = true;
  Simulation sim(def);
  EXPECT_EQ(sim.max_step_level(), 0);
  for (int k = 0; k < 50; ++k) sim.Step();
  EXPECT_EQ(sim.tick_count(), sim.step_count());
  EXPECT_EQ(sim.time_step_s(), sim.tick_s());
  EXPECT_EQ(sim.profile().steps_at_level[0], 50u);
  ModelParameters p = def.parameters;
  p.time_step_mode = TimeStepMode::kAdaptive;
  try {
    sim.SetParameters(p);
    ADD_FAILURE() << "the step's mode changed mid-run";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("time step's settings are fixed for a run"), std::string::npos) << e.what();
  }
  p = def.parameters;
  p.integrator = Integrator::kGear5;
  p.time_step_mode = TimeStepMode::kAdaptive;
  std::string error;
  EXPECT_FALSE(p.IsValid(&error));
  EXPECT_NE(error.find("needs integrator = velocity_verlet"), std::string::npos) << error;
}

}  // namespace
}  // namespace crowdrecon::engine
