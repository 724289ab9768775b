// Analytic checks of the engine: restitution, friction threshold, momentum,
// action-reaction, relaxation, torque directions, energy, invariance, determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/fnv.hpp"
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

// Two bodies approach head-on along x; returns the measured restitution
// -(v2' - v1') / (v2 - v1) once they have separated. `gap` sets where within a
// time step the contact begins and ends.
double HeadOnRestitution(const BodyShape& shape, double eps, Integrator integrator, double safety,
                         double gap) {
  WorldDef def = PassiveWorld();
  def.parameters.restitution = eps;
  def.parameters.integrator = integrator;
  if (safety > 0.0) def.parameters.time_step_safety = safety;
  def.shapes.push_back(shape);
  PersonDef a, b;
  SetMassFromShape(shape, 1000.0, a);
  SetMassFromShape(shape, 1000.0, b);
  b.mass_kg *= 1.3;  // unequal masses: m_ij is the effective mass of eq. (14)
  b.inertia_kg_m2 *= 1.3;
  const double half_width = shape.vertices.size() == 1 ? 0.0 : 0.07;
  a.position_m = {-(half_width + shape.radius_m + gap / 2), 0.0};
  b.position_m = {half_width + shape.radius_m + gap / 2, 0.0};
  b.angle_rad = std::numbers::pi;  // chest to chest
  a.velocity_m_per_s = {0.6, 0.0};
  b.velocity_m_per_s = {-0.4, 0.0};
  def.people = {a, b};
  Simulation sim(def);
  const double approach = 1.0;
  bool touched = false;
  for (int k = 0; k < 200000; ++k) {
    sim.Step();
    if (!sim.contacts().empty()) touched = true;
    if (touched && sim.contacts().empty()) break;
  }
  EXPECT_TRUE(touched);
  const auto& v = sim.bodies().velocity_m_per_s;
  return (v[1].x - v[0].x) / approach;
}

// Worst relative restitution error over ten phases of the collision within a step.
double WorstRestitutionError(const BodyShape& shape, double eps, Integrator integrator, double safety) {
  double worst = 0.0;
  for (int k = 0; k < 10; ++k)
    worst = std::max(worst, std::abs(HeadOnRestitution(shape, eps, integrator, safety, 0.02 + 0.0013 * k) / eps - 1.0));
  return worst;
}

TEST(EnginePhysics, HeadOnCollisionsHaveTheConfiguredRestitution) {
  // Disks (one contact point) and flat chests (four points: the damping is
  // shared so that the pair keeps epsilon), with both integrators.
  const double default_safety = ModelParameters{}.time_step_safety;
  for (const BodyShape& shape : {DiskShape(0.2), ThoraxLikeShape()})
    for (double eps : {0.1, 0.3, 0.5}) {
      const std::string what = std::to_string(shape.vertices.size()) + " vertices, eps " + std::to_string(eps);
      EXPECT_LT(WorstRestitutionError(shape, eps, Integrator::kVelocityVerlet, default_safety), 0.02) << what;
      EXPECT_LT(WorstRestitutionError(shape, eps, Integrator::kVelocityVerlet, default_safety / 2), 0.005) << what;
      EXPECT_LT(WorstRestitutionError(shape, eps, Integrator::kGear5, default_safety), 0.02) << what << " gear5";
    }
}

TEST(EnginePhysics, FrictionSticksBelowMuFnAndSlidesAbove) {
  const double stick = SlideDuringSecondSecond(DiskOnWall(), 0.95);
  const double slide = SlideDuringSecondSecond(DiskOnWall(), 1.05);
  EXPECT_LT(std::abs(stick), 1e-6) << stick;  // static: the spring holds
  // Sliding: the elastic part is capped at mu Fn; the excess 0.05 mu Fn = 10 N
  // drives steady sliding against the tangential dashpot only.
  EXPECT_GT(slide, 1e-3) << slide;
}

TEST(EnginePhysics, MomentumIsConservedWithoutDriving) {
  // Linear momentum in a periodic box; angular momentum in open space (a
  // periodic box is not rotation invariant, so there it is not conserved).
  for (bool periodic : {true, false}) {
    WorldDef def = RandomGas(6, 0.5, 7, periodic);
    Simulation sim(def);
    const Vec2 p0 = sim.LinearMomentum();
    const double l0 = sim.AngularMomentum();
    double scale_p = 0.0, scale_l = 0.0;
    for (std::size_t i = 0; i < def.people.size(); ++i) {
      scale_p += def.people[i].mass_kg * Length(def.people[i].velocity_m_per_s);
      scale_l += def.people[i].mass_kg * Length(def.people[i].position_m) * Length(def.people[i].velocity_m_per_s) +
                 def.people[i].inertia_kg_m2 * std::abs(def.people[i].angular_velocity_rad_per_s);
    }
    std::size_t contacts = 0;
    for (int k = 0; k < 2000; ++k) {
      sim.Step();
      contacts += sim.contacts().size();
    }
    EXPECT_GT(contacts, 100u);
    EXPECT_LT(Length(sim.LinearMomentum() - p0), 1e-9 * scale_p);
    if (!periodic) {
      EXPECT_LT(std::abs(sim.AngularMomentum() - l0), 1e-9 * scale_l);
    }
  }
}

TEST(EnginePhysics, ContactForcesAreEqualAndOpposite) {
  WorldDef def = RandomGas(5, 0.42, 3, true);
  Simulation sim(def);
  for (int k = 0; k < 20000 && sim.contacts().size() < 3; ++k) sim.Step();
  ASSERT_GE(sim.contacts().size(), 3u);
  Vec2 total;
  double scale = 0.0;
  for (std::size_t i = 0; i < sim.bodies().size(); ++i) {
    total += sim.bodies().contact_force_n[i];
    scale += Length(sim.bodies().contact_force_n[i]);
  }
  EXPECT_LT(Length(total), 1e-12 * scale);
  // Per contact: the tangent is perpendicular to the normal and the force on b
  // is the negative of that on a (Contact::Force is applied with both signs).
  for (const Contact& c : sim.contacts()) EXPECT_NEAR(Length(c.normal), 1.0, 1e-12);
}

TEST(EnginePhysics, FreePersonRelaxesToDesiredVelocityWithTimeConstantTau) {
  const WorldDef def = testing::FreeWalker({0.6, 0.8}, 1.1);
  Simulation sim(def);
  const double tau = def.parameters.relaxation_time_s;
  for (double t : {0.5 * tau, tau, 3.0 * tau}) {
    sim.AdvanceTo(t);
    const double expected = 1.1 * (1.0 - std::exp(-sim.time_s() / tau));
    const Vec2 v = sim.bodies().velocity_m_per_s[0];
    EXPECT_NEAR(Length(v), expected, 2e-3 * 1.1) << "t = " << sim.time_s();
    EXPECT_NEAR(std::atan2(v.y, v.x), std::atan2(0.8, 0.6), 1e-9);
  }
}

TEST(EnginePhysics, MotiveTorqueTurnsTowardWalkingDirection) {
  for (FacingTarget facing : {FacingTarget::kVelocity, FacingTarget::kDesiredDirection}) {
    WorldDef def;
    def.parameters.facing_target = facing;
    def.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
    def.shapes.push_back(ThoraxLikeShape());
    PersonDef p;
    SetMassFromShape(def.shapes[0], 1000.0, p);
    p.velocity_m_per_s = {1.0, 0.0};
    p.angle_rad = 0.8;  // facing left of the walking direction
    def.people = {p};
    Simulation sim(def);
    EXPECT_LT(sim.bodies().torque_n_m[0], 0.0);  // clockwise, back toward theta_D = 0
    sim.AdvanceTo(5.0);
    EXPECT_LT(std::abs(sim.bodies().angle_rad[0]), 0.05) << ToString(facing);
    // Across the +-pi seam the torque takes the short way round: facing -3.0
    // rad, walking toward 3.0 rad, the short turn is clockwise (by 0.28 rad).
    def.targets[0] = geometry::NavigationField::Constant({std::cos(3.0), std::sin(3.0)});
    p.velocity_m_per_s = {std::cos(3.0), std::sin(3.0)};
    p.angle_rad = -3.0;
    def.people = {p};
    Simulation seam(def);
    EXPECT_LT(seam.bodies().torque_n_m[0], 0.0);
  }
}

TEST(EnginePhysics, BackForceActsOnlyWhenPushedBackwardsTowardTheRight) {
  const auto force_for = [](Vec2 velocity) {
    WorldDef def;
    def.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
    def.shapes.push_back(ThoraxLikeShape());
    PersonDef p;
    SetMassFromShape(def.shapes[0], 1000.0, p);
    p.desired_speed_m_per_s = 1.0;
    p.velocity_m_per_s = velocity;
    def.people = {p};
    Simulation sim(def);
    return std::pair{sim.bodies().force_n[0], p.mass_kg};
  };
  const double tau = 2.0 / 3.0, gamma = 1.2;
  {
    const auto [f, m] = force_for({0.5, 0.0});  // forward: eq. (3) only
    EXPECT_NEAR(f.x, m / tau * (1.0 - 0.5), 1e-9);
    EXPECT_NEAR(f.y, 0.0, 1e-12);
  }
  {
    const auto [f, m] = force_for({-0.5, 0.0});  // pushed back: eq. (3) + eq. (15)
    EXPECT_NEAR(f.x, m / tau * 1.5 + gamma * m / tau, 1e-9);
    EXPECT_NEAR(f.y, -gamma * m / tau, 1e-9);  // e x k = (0, -1): the person's right
  }
  {
    const auto [f, m] = force_for({0.0, 0.7});  // sideways: e.v = 0, no back force
    EXPECT_NEAR(f.y, -m / tau * 0.7, 1e-9);
  }
}

TEST(EnginePhysics, MechanicalEnergyNeverIncreasesWithoutDriving) {
  WorldDef def = RandomGas(6, 0.48, 11, true);
  Simulation sim(def);
  double previous = sim.KineticEnergy() + sim.ElasticEnergy();
  const double e0 = previous;
  double worst_rise = 0.0;
  for (int k = 0; k < 4000; ++k) {
    sim.Step();
    const double e = sim.KineticEnergy() + sim.ElasticEnergy();
    worst_rise = std::max(worst_rise, e - previous);
    previous = e;
  }
  EXPECT_LT(previous, 0.8 * e0);              // collisions dissipated energy
  EXPECT_LT(worst_rise, 1e-3 * e0) << worst_rise;  // and none was created beyond integration error
}

TEST(EnginePhysics, RotatingAndTranslatingTheSceneTransformsTheResult) {
  WorldDef def = RandomGas(4, 0.5, 5, false);
  def.parameters.ground_reaction = true;
  def.targets[0] = geometry::NavigationField::Constant({1.0, 0.0});
  def.walls.push_back({{{-1.0, -0.3}, {4.0, -0.3}}, false, 0.0});
  def.walls.push_back({{{4.0, 2.3}, {-1.0, 2.3}, {-1.5, 1.0}}, false, 0.05});
  const double angle = 0.7;
  const Vec2 shift{5.0, -3.0};
  WorldDef moved = def;
  const auto move = [&](Vec2 p) { return Rotated(p, angle) + shift; };
  for (PersonDef& p : moved.people) {
    p.position_m = move(p.position_m);
    p.velocity_m_per_s = Rotated(p.velocity_m_per_s, angle);
    p.angle_rad += angle;
  }
  for (Wall& w : moved.walls)
    for (Vec2& q : w.points) q = move(q);
  moved.targets[0] = geometry::NavigationField::Constant(Rotated(Vec2{1.0, 0.0}, angle));
  Simulation a(def), b(moved);
  ASSERT_EQ(a.time_step_s(), b.time_step_s());
  std::size_t contacts = 0;
  while (a.time_s() < 0.5) {
    a.Step();
    b.Step();
    contacts += a.contacts().size();
  }
  ASSERT_GT(contacts, 10u);
  for (std::size_t i = 0; i < def.people.size(); ++i) {
    const Vec2 expected = move(a.bodies().position_m[i]);
    EXPECT_NEAR(b.bodies().position_m[i].x, expected.x, 1e-9);
    EXPECT_NEAR(b.bodies().position_m[i].y, expected.y, 1e-9);
    EXPECT_NEAR(b.bodies().angle_rad[i], a.bodies().angle_rad[i] + angle, 1e-9);
  }
}

TEST(EnginePhysics, ResultsDoNotDependOnTheThreadCount) {
  WorldDef def = RandomGas(8, 0.45, 21, true);
  def.parameters.ground_reaction = true;
  std::vector<Vec2> reference;
  for (int threads : {1, 2, 3}) {
    def.threads = threads;
    Simulation sim(def);
    sim.AdvanceTo(0.2);
    const auto& x = sim.bodies().position_m;
    if (reference.empty()) {
      reference = x;
    } else {
      ASSERT_EQ(std::memcmp(reference.data(), x.data(), x.size() * sizeof(Vec2)), 0) << threads;
    }
  }
}

TEST(EnginePhysics, ResultsOfALargeCrowdDoNotDependOnTheThreadCount) {
  // Enough people and contacts (>= 512 each) for every stage to split its
  // work between threads: the neighbour list built in parts, the contacts
  // filed per body in parts, the per-body stages. Positions and the whole
  // contact list must be the same, bit for bit, on 1, 2 and 3 threads.
  WorldDef def = RandomGas(26, 0.38, 7, true);
  def.parameters.ground_reaction = true;
  std::vector<Vec2> reference;
  std::vector<Contact> reference_contacts;
  std::vector<Vec2> reference_forces;
  for (int threads : {1, 2, 3}) {
    def.threads = threads;
    Simulation sim(def);
    sim.AdvanceTo(0.05);
    sim.RebuildNeighbourList();  // at least one rebuild with every thread count
    sim.AdvanceTo(0.1);
    const auto& x = sim.bodies().position_m;
    const auto& contacts = sim.contacts();
    if (reference.empty()) {
      ASSERT_GE(x.size(), 512u);
      ASSERT_GE(contacts.size(), 512u) << "too few contacts to split the filing between threads";
      reference = x;
      reference_contacts = contacts;
      reference_forces = sim.bodies().contact_force_n;
      continue;
    }
    ASSERT_EQ(std::memcmp(reference.data(), x.data(), x.size() * sizeof(Vec2)), 0) << threads;
    ASSERT_EQ(contacts.size(), reference_contacts.size()) << threads;
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      const Contact& c = contacts[k];
      const Contact& r = reference_contacts[k];
      ASSERT_TRUE(c.a == r.a && c.b == r.b && c.wall == r.wall && c.feature == r.feature) << threads << " " << k;
      ASSERT_EQ(std::memcmp(&c.normal_force_n, &r.normal_force_n, sizeof(double)), 0) << threads << " " << k;
      ASSERT_EQ(std::memcmp(&c.tangential_force_n, &r.tangential_force_n, sizeof(double)), 0) << threads << " " << k;
    }
    const auto& f = sim.bodies().contact_force_n;  // gathered from the contacts filed per body
    ASSERT_EQ(std::memcmp(reference_forces.data(), f.data(), f.size() * sizeof(Vec2)), 0) << threads;
  }
}

TEST(EnginePhysics, RememberingWhatIsStillApartChangesNothing) {
  // The narrow phase skips pairs and vertices that cannot touch yet (pair
  // and vertex clearances against a bound on how far bodies moved): the
  // results must be those of measuring every listed pair at every step, bit
  // for bit, for person pairs (periodic crowd) and person-wall pairs (a
  // crowd pushed against walls), with contacts made and broken.
  for (bool periodic : {true, false}) {
    WorldDef def = RandomGas(8, 0.45, 33, periodic);
    def.parameters.ground_reaction = true;
    if (!periodic) {
      def.walls.push_back({{{-0.3, -0.3}, {3.9, -0.3}, {3.9, 3.9}, {-0.3, 3.9}, {-0.3, -0.3}}, false, 0.1});
      def.walls.push_back({{{1.0, 1.8}, {2.6, 1.9}}, false, 0.1});
      std::erase_if(def.people, [](const PersonDef& p) { return std::abs(p.position_m.y - 1.85) < 0.4; });
    }
    Simulation remembering(def), measuring(def);
    measuring.SetPairMemory(false);
    std::size_t touching_steps = 0, changes = 0, previous = 0, wall_contacts = 0;
    while (remembering.time_s() < 0.3) {
      remembering.Step();
      measuring.Step();
      const auto& a = remembering.contacts();
      const auto& b = measuring.contacts();
      ASSERT_EQ(a.size(), b.size()) << "periodic " << periodic << " t " << remembering.time_s();
      for (std::size_t k = 0; k < a.size(); ++k) {
        ASSERT_EQ(a[k].a, b[k].a);
        ASSERT_EQ(a[k].b, b[k].b);
        ASSERT_EQ(a[k].feature, b[k].feature);
        ASSERT_EQ(a[k].normal_force_n, b[k].normal_force_n);
        ASSERT_EQ(a[k].tangential_force_n, b[k].tangential_force_n);
        wall_contacts += a[k].wall ? 1 : 0;
      }
      touching_steps += a.empty() ? 0 : 1;
      changes += a.size() != previous ? 1 : 0;
      previous = a.size();
    }
    const auto& x = remembering.bodies();
    const auto& y = measuring.bodies();
    EXPECT_EQ(std::memcmp(x.position_m.data(), y.position_m.data(), x.size() * sizeof(Vec2)), 0);
    EXPECT_EQ(std::memcmp(x.angle_rad.data(), y.angle_rad.data(), x.size() * sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(x.velocity_m_per_s.data(), y.velocity_m_per_s.data(), x.size() * sizeof(Vec2)), 0);
    // The scene does what it is for: contacts all along, made and broken.
    EXPECT_GT(touching_steps, remembering.step_count() * 9 / 10);
    EXPECT_GT(changes, 50u);
    if (!periodic) {
      EXPECT_GT(wall_contacts, 100u);
    }
  }
}

TEST(EnginePhysics, PeopleMovingTogetherAreNotMeasuredAgain) {
  // Person pairs are skipped on a bound of how far their two bodies moved
  // relative to each other (not of how far each moved): a crowd translating
  // as one rigid block, apart, never needs its pairs measured again until the
  // neighbour list is rebuilt. By the sum of the two travels, a pair 5 cm
  // apart would be measured again every ~30 steps at these speeds.
  WorldDef def = RandomGas(10, 0.5, 4, true);  // bounding circles 0.45 m: never touching
  for (PersonDef& p : def.people) {
    p.velocity_m_per_s = {1.5, 0.5};
    p.angular_velocity_rad_per_s = 0.0;
  }
  Simulation sim(def);
  ASSERT_GT(sim.neighbour_pair_count(), 0u);
  std::size_t quiet_steps = 0;
  while (sim.time_s() < 0.5) {
    const Profile before = sim.profile();
    sim.Step();
    const Profile& after = sim.profile();
    ASSERT_TRUE(sim.contacts().empty());
    if (after.pair_rebuilds != before.pair_rebuilds) continue;  // a rebuild forgets what was known
    EXPECT_EQ(after.pairs_measured, before.pairs_measured) << "t " << sim.time_s();
    ++quiet_steps;
  }
  EXPECT_GT(quiet_steps, sim.step_count() / 2);
  // The same crowd with everyone's velocity different: pairs must be
  // measured again as they approach (the bound is not simply zero).
  WorldDef mixed = RandomGas(10, 0.5, 4, true);
  Simulation moving(mixed);
  const std::uint64_t at_start = moving.profile().pairs_measured;
  moving.AdvanceTo(0.1);
  EXPECT_GT(moving.profile().pairs_measured - at_start, moving.neighbour_pair_count());
}

TEST(EnginePhysics, RestoredCheckpointContinuesBitForBit) {
  for (Integrator integrator : {Integrator::kVelocityVerlet, Integrator::kGear5}) {
    WorldDef def = RandomGas(6, 0.42, 9, true);
    def.parameters.ground_reaction = true;
    def.parameters.integrator = integrator;
    Simulation straight(def);
    straight.AdvanceTo(0.4);
    Simulation first(def);
    first.AdvanceTo(0.2);
    const std::string state = first.SaveState();
    Simulation resumed(def);
    resumed.LoadState(state);
    resumed.AdvanceTo(0.4);
    ASSERT_EQ(resumed.step_count(), straight.step_count());
    const auto& a = straight.bodies();
    const auto& b = resumed.bodies();
    EXPECT_EQ(std::memcmp(a.position_m.data(), b.position_m.data(), a.size() * sizeof(Vec2)), 0);
    EXPECT_EQ(std::memcmp(a.velocity_m_per_s.data(), b.velocity_m_per_s.data(), a.size() * sizeof(Vec2)), 0);
    EXPECT_EQ(std::memcmp(a.angle_rad.data(), b.angle_rad.data(), a.size() * sizeof(double)), 0);
    // A damaged state is refused.
    std::string damaged = state;
    damaged[damaged.size() / 2] ^= 1;
    Simulation other(def);
    EXPECT_THROW(other.LoadState(damaged), InputError);
  }
}

// A state that passes its checksum yet holds what no run reaches (a contact
// naming a person the run lacks, a position that is not a number) is refused
// with what is wrong, before a step could index past the arrays (found by
// fuzz_checkpoint; its reproducers are replayed by ctest).
TEST(EnginePhysics, ACheckpointWithImpossibleValuesIsRefusedSayingWhat) {
  WorldDef def = RandomGas(6, 0.42, 9, true);
  Simulation sim(def);
  sim.AdvanceTo(0.2);
  ASSERT_FALSE(sim.contacts().empty());
  const std::string state = sim.SaveState();
  // Replaces the bytes of `from` (found once in the state) and re-signs it.
  const auto patched = [&](const void* from, std::size_t size, const void* to) {
    std::string s = state.substr(0, state.size() - 8);
    const std::size_t at = s.find(std::string(static_cast<const char*>(from), size));
    EXPECT_NE(at, std::string::npos);
    EXPECT_EQ(s.find(std::string(static_cast<const char*>(from), size), at + 1), std::string::npos);
    s.replace(at, size, static_cast<const char*>(to), size);
    const std::uint64_t checksum = Fnv1a(s.data(), s.size());
    return s.append(reinterpret_cast<const char*>(&checksum), sizeof checksum);
  };
  const auto refused = [&](const std::string& bad, const std::string& expected) {
    Simulation other(def);
    try {
      other.LoadState(bad);
      ADD_FAILURE() << "accepted; expected: " << expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  Contact c = sim.contacts().front();
  const Contact original = c;
  c.b = 999;
  refused(patched(&original, sizeof original, &c), "damaged contact 0: names person");
  const Vec2 p = sim.bodies().position_m[3], nan{std::nan(""), 0.0};
  refused(patched(&p, sizeof p, &nan), "position of slot 3 is not a finite number");
  // The untouched state still loads.
  Simulation again(def);
  EXPECT_NO_THROW(again.LoadState(state));
}

TEST(EnginePhysics, InterpenetrationStopsWithTheNamesAndTheTime) {
  // Two chests meeting at 60 m/s: the contact cannot stop them before the
  // cores pass into each other; the run must stop and say who and when.
  WorldDef def = PassiveWorld();
  def.shapes.push_back(ThoraxLikeShape());
  PersonDef a, b;
  SetMassFromShape(def.shapes[0], 1000.0, a);
  SetMassFromShape(def.shapes[0], 1000.0, b);
  a.position_m = {-0.5, 0.0};
  b.position_m = {0.5, 0.0};
  b.angle_rad = std::numbers::pi;
  a.velocity_m_per_s = {30.0, 0.0};
  b.velocity_m_per_s = {-30.0, 0.0};
  def.people = {a, b};
  Simulation sim(def);
  try {
    sim.AdvanceTo(1.0);
    FAIL() << "expected a SimulationError";
  } catch (const SimulationError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("overlap of person 1 and person 2"), std::string::npos) << what;
    EXPECT_NE(what.find("at t = "), std::string::npos) << what;
    EXPECT_EQ(e.person(), 0);
    EXPECT_EQ(e.other(), 1);
    EXPECT_GT(e.time_s(), 0.0);
  }
}

TEST(EnginePhysics, UnstableTimeStepIsRefusedWithTheLimit) {
  WorldDef def = RandomGas(3, 0.5, 1, false);
  def.parameters.time_step_s = 0.05;
  try {
    Simulation sim(def);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("above the stability limit"), std::string::npos) << e.what();
  }
}

TEST(EnginePhysics, RestitutionFormulaRoundTrips) {
  for (double eps : {0.1, 0.3, 0.4, 0.5, 0.9}) {
    const double gamma = DampingRateFromRestitution(eps, 1e5, 20.0);
    EXPECT_NEAR(RestitutionFromDampingRate(gamma, 1e5, 20.0), eps, 1e-12);
  }
  // ERRATA 2: eps = 0.3 with kn = 1e5 N/m and m_ij = 20 kg needs gamma_n of about 51 1/s.
  EXPECT_NEAR(DampingRateFromRestitution(0.3, 1e5, 20.0), 50.6, 0.1);
}

}  // namespace
}  // namespace crowdrecon::engine
