// Small verification scenes for the engine tests.
#pragma once

#include <cmath>
#include <numbers>
#include <random>

#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/geometry/spheropolygon.hpp"

namespace crowdrecon::engine::testing {

// A thorax-like body: an 8-vertex rounded octagon 0.42 m wide and 0.24 m deep,
// chest facing +x, centroid at the origin.
inline BodyShape ThoraxLikeShape() {
  BodyShape s;
  s.radius_m = 0.05;
  const double hx = 0.07, hy = 0.16;
  s.vertices = {{hx, -hy * 0.55}, {hx, hy * 0.55}, {hx * 0.4, hy}, {-hx * 0.4, hy},
                {-hx, hy * 0.55}, {-hx, -hy * 0.55}, {-hx * 0.4, -hy}, {hx * 0.4, -hy}};
  return s;
}

inline BodyShape DiskShape(double radius_m) {
  BodyShape s;
  s.radius_m = radius_m;
  s.vertices = {{0.0, 0.0}};
  return s;
}

// Mass properties consistent with a shape at surface density rho.
inline void SetMassFromShape(const BodyShape& shape, double rho, PersonDef& p) {
  const auto sp = geometry::Spheropolygon::Create(shape.vertices, shape.radius_m);
  p.mass_kg = rho * sp.area();
  p.inertia_kg_m2 = rho * sp.polar_moment();
}

// One walker alone at the origin, at rest, thorax-like, heading `direction`
// (a unit vector) at `desired_speed_m_per_s`, with the paper's parameters.
inline WorldDef FreeWalker(Vec2 direction, double desired_speed_m_per_s) {
  WorldDef def;
  def.targets.push_back(geometry::NavigationField::Constant(direction));
  def.shapes.push_back(ThoraxLikeShape());
  PersonDef p;
  SetMassFromShape(def.shapes[0], 1000.0, p);
  p.desired_speed_m_per_s = desired_speed_m_per_s;
  def.people = {p};
  return def;
}

inline WorldDef PassiveWorld() {
  WorldDef def;
  def.parameters.ground_reaction = false;
  def.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
  return def;
}

// A disk that cannot roll (inertia 1e12) resting on a long wall along y = 0
// (friction scenes).
inline WorldDef DiskOnWall(WorldDef def = PassiveWorld()) {
  def.shapes.push_back(DiskShape(0.2));
  PersonDef p;
  SetMassFromShape(def.shapes.back(), 1000.0, p);
  p.shape = static_cast<std::uint32_t>(def.shapes.size() - 1);
  p.inertia_kg_m2 = 1e12;
  p.position_m = {0.0, 0.2};
  def.people = {p};
  def.walls.push_back({{{-50.0, 0.0}, {50.0, 0.0}}, false, 0.0});
  return def;
}

// The disk of DiskOnWall(def) pressed onto the wall by Fn = 500 N and pushed
// sideways by Ft = fraction mu Fn (loaded gradually, so that the spring does
// not overshoot): its displacement along the wall during the second second
// of pushing, after the tangential spring has loaded.
// `profile`, if given, receives the engine's profile (its steps by length).
inline double SlideDuringSecondSecond(const WorldDef& def, double push_fraction_of_mu_fn, Profile* profile = nullptr) {
  Simulation sim(def);
  const double fn = 500.0, mu = def.parameters.friction_coefficient;
  sim.SetExternalForce(0, {0.0, -fn});
  sim.AdvanceTo(1.0);  // settle onto the wall
  for (int k = 1; k <= 100; ++k) {
    sim.SetExternalForce(0, {push_fraction_of_mu_fn * mu * fn * k / 100.0, -fn});
    sim.AdvanceTo(1.0 + 0.01 * k);
  }
  sim.AdvanceTo(5.0);
  const double x0 = sim.bodies().position_m[0].x;
  sim.AdvanceTo(6.0);
  if (profile) *profile = sim.profile();
  return sim.bodies().position_m[0].x - x0;
}

// N thorax-like bodies on a jittered lattice in [0, L]^2 with random
// velocities and spins (no two overlapping at the start).
inline WorldDef RandomGas(int per_side, double spacing_m, unsigned seed, bool periodic) {
  WorldDef def = PassiveWorld();
  def.shapes.push_back(ThoraxLikeShape());
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < per_side; ++i)
    for (int j = 0; j < per_side; ++j) {
      PersonDef p;
      p.shape = 0;
      SetMassFromShape(def.shapes[0], 1000.0, p);
      p.mass_kg *= 1.0 + 0.2 * u(rng);
      p.inertia_kg_m2 *= 1.0 + 0.2 * u(rng);
      p.position_m = {(i + 0.5) * spacing_m + 0.02 * u(rng), (j + 0.5) * spacing_m + 0.02 * u(rng)};
      p.angle_rad = std::numbers::pi * u(rng);
      p.velocity_m_per_s = {1.5 * u(rng), 1.5 * u(rng)};
      p.angular_velocity_rad_per_s = 2.0 * u(rng);
      def.people.push_back(p);
    }
  if (periodic) {
    def.periodic.x = def.periodic.y = true;
    def.periodic.min_m = {0.0, 0.0};
    def.periodic.max_m = {per_side * spacing_m, per_side * spacing_m};
  }
  return def;
}

// Steps `wide` with the engine's wide instructions and `narrow` and `none`
// without them, in turn, `steps` times (leaving them allowed): the tests
// that the wide instructions give the scalar results bit for bit.
inline void StepWideAndNarrow(int steps, Simulation& wide, Simulation& narrow, Simulation& none) {
  for (int n = 0; n < steps; ++n) {
    UseWideInstructions(true);
    wide.Step();
    UseWideInstructions(false);
    narrow.Step();
    none.Step();
  }
  UseWideInstructions(true);
}

}  // namespace crowdrecon::engine::testing
