// Keeping a distance (issue 64): the behaviour term headway (the
// collision-free speed model's two rules, Tordeux, Chraibi and Seyfried 2016)
// against what its equations give: a file of walkers in a ring walks at the
// model's fundamental diagram, min(v0, (1/rho - l) / T); the desired
// heading is turned away from a person beside by exactly a exp((l - d)/D);
// a walker meeting a standing person never touches them; off, the paper's
// model bit for bit; the same on any thread count and after a resume.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

#include "crowdrecon/engine/simulation.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::engine {
namespace {

using testing::SetMassFromShape;
using testing::ThoraxLikeShape;

ModelParameters KeepingDistance() {
  ModelParameters p;
  p.headway = Headway::kTimeGap;
  return p;  // JuPedSim's values: T 1 s, l 0.4 m, a 8, D 0.1 m
}

// `count` walkers in a file along x at `spacing_m`, in a ring (periodic in x),
// heading +x at `v0`, facing it, at rest.
WorldDef File(int count, double spacing_m, double v0, const ModelParameters& parameters) {
  WorldDef def;
  def.parameters = parameters;
  def.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
  def.shapes.push_back(ThoraxLikeShape());
  for (int i = 0; i < count; ++i) {
    PersonDef p;
    SetMassFromShape(def.shapes[0], 1000.0, p);
    p.position_m = {(i + 0.5) * spacing_m, 0.0};
    p.desired_speed_m_per_s = v0;
    def.people.push_back(p);
  }
  def.periodic.x = true;
  def.periodic.min_m = {0.0, -5.0};
  def.periodic.max_m = {count * spacing_m, 5.0};
  return def;
}

TEST(Headway, AFileInARingWalksAtTheModelsFundamentalDiagram) {
  const ModelParameters p = KeepingDistance();
  for (const double spacing : {0.6, 1.0, 1.3, 2.0}) {
    const double v0 = 1.2;
    const double expected = std::min(v0, (spacing - p.headway_length_m) / p.headway_time_gap_s);
    Simulation sim(File(12, spacing, v0, p));
    sim.AdvanceTo(20.0);  // many relaxation times
    for (std::size_t i = 0; i < sim.bodies().size(); ++i) {
      EXPECT_NEAR(sim.bodies().velocity_m_per_s[i].x, expected, 1e-6) << "spacing " << spacing << ", person " << i;
      EXPECT_NEAR(sim.bodies().velocity_m_per_s[i].y, 0.0, 1e-9);
    }
    EXPECT_TRUE(sim.contacts().empty()) << "spacing " << spacing;
  }
}

TEST(Headway, TheHeadingTurnsAwayFromAPersonBesideAsTheModelSays) {
  // A walker at rest at the origin heading +x, a standing person 0.5 m to its
  // left: at rest eq. (3)'s force is m/tau v0 e', e' = (1, 0) - a e^((l-d)/D) (0, 1) normalised.
  WorldDef def = File(1, 10.0, 1.0, KeepingDistance());
  def.periodic = PeriodicBox{};
  def.people[0].position_m = {0.0, 0.0};
  PersonDef beside = def.people[0];
  beside.position_m = {0.0, 0.5};
  beside.desired_speed_m_per_s = 0.0;
  beside.state = PersonState::kFallen;  // (an obstacle: it does not move itself)
  def.people.push_back(beside);
  const Simulation sim(def);
  const ModelParameters& p = def.parameters;
  const double push = p.headway_repulsion_strength * std::exp((p.headway_length_m - 0.5) / p.headway_repulsion_range_m);
  const Vec2 expected = Normalized(Vec2{1.0, -push});
  const Vec2 f = sim.bodies().force_n[0];
  EXPECT_NEAR(f.x / Length(f), expected.x, 1e-12);
  EXPECT_NEAR(f.y / Length(f), expected.y, 1e-12);
  // Its size: m/tau v0 (no cap: the person beside is not ahead).
  EXPECT_NEAR(Length(f), def.people[0].mass_kg / p.relaxation_time_s * 1.0, 1e-9);
}

// A walker meeting a standing person on its line: the paper's walker runs
// into them; keeping a distance, it slows to a stop short of them (the cap),
// is turned back by them within l + D ln a (0.61 m), and the back force of
// eq. (15), which that first step back triggers, takes it round them to its
// right (e x k): it never touches them, and walks on.
TEST(Headway, AWalkerMeetingAStandingPersonNeverTouchesThem) {
  for (const bool keep : {false, true}) {
    WorldDef def = File(1, 10.0, 1.2, keep ? KeepingDistance() : ModelParameters{});
    def.periodic = PeriodicBox{};
    def.people[0].position_m = {0.0, 0.0};
    PersonDef ahead = def.people[0];
    ahead.position_m = {3.0, 0.0};
    ahead.desired_speed_m_per_s = 0.0;
    def.people.push_back(ahead);
    Simulation sim(def);
    bool touched = false;
    double closest = 3.0, slowest_before_passing = 1.2;
    while (sim.time_s() < 10.0) {
      sim.Step();
      touched = touched || !sim.contacts().empty();
      const Vec2 d = sim.bodies().position_m[1] - sim.bodies().position_m[0];
      closest = std::min(closest, Length(d));
      if (d.x > 0.0) slowest_before_passing = std::min(slowest_before_passing, Length(sim.bodies().velocity_m_per_s[0]));
    }
    if (keep) {
      EXPECT_FALSE(touched);
      EXPECT_GT(closest, KeepingDistance().headway_length_m);  // the cap stops it before l
      EXPECT_LT(slowest_before_passing, 0.05);                 // it stopped first
      EXPECT_LT(sim.bodies().position_m[0].y, -0.4);           // then went round to its right
      EXPECT_GT(sim.bodies().position_m[0].x, 5.0);            // and walked on
    } else {
      EXPECT_TRUE(touched);  // the paper's walker runs into the person ahead
    }
  }
}

TEST(Headway, OffIsThePapersModelBitForBit) {
  ModelParameters off;  // headway none, its numbers changed: nothing changes
  off.headway_time_gap_s = 2.0;
  off.headway_length_m = 0.9;
  WorldDef a = testing::RandomGas(6, 0.45, 5, true), b = a;
  a.parameters.ground_reaction = b.parameters.ground_reaction = true;
  b.parameters.headway_time_gap_s = off.headway_time_gap_s;
  b.parameters.headway_length_m = off.headway_length_m;
  Simulation sa(a), sb(b);
  sa.AdvanceTo(0.4);
  sb.AdvanceTo(0.4);
  const std::size_t bytes = sa.bodies().size() * sizeof(Vec2);
  EXPECT_EQ(std::memcmp(sa.bodies().position_m.data(), sb.bodies().position_m.data(), bytes), 0);
  EXPECT_EQ(sb.profile().seconds(Stage::kNeighbours), 0.0);  // and the neighbour stage costs nothing
}

// 576 walkers at 1.2 m/s with `parameters` (the drive runs on threads): the
// same positions on one thread and two, and after a resume at half of `end_s`.
void ExpectTheSameOnAnyThreadCountAndAfterAResume(const ModelParameters& parameters, double end_s, const char* what) {
  WorldDef def = testing::RandomGas(24, 0.5, 3, true);
  def.parameters = parameters;
  for (PersonDef& p : def.people) p.desired_speed_m_per_s = 1.2;
  def.threads = 1;
  Simulation one(def);
  one.AdvanceTo(end_s / 2.0);
  const std::string state = one.SaveState();
  one.AdvanceTo(end_s);
  def.threads = 2;
  Simulation two(def), resumed(def);
  two.AdvanceTo(end_s);
  resumed.LoadState(state);
  resumed.AdvanceTo(end_s);
  const std::size_t bytes = one.bodies().size() * sizeof(Vec2);
  EXPECT_EQ(std::memcmp(one.bodies().position_m.data(), two.bodies().position_m.data(), bytes), 0) << what;
  EXPECT_EQ(std::memcmp(one.bodies().position_m.data(), resumed.bodies().position_m.data(), bytes), 0) << what;
}

TEST(Headway, SameOnAnyThreadCountAndAfterAResume) {
  ExpectTheSameOnAnyThreadCountAndAfterAResume(KeepingDistance(), 0.2, "headway");
}

// The social force (issue 64): a walker at rest with one person on its line,
// ahead or behind, at a distance or overlapping: eq. (3)'s m/tau v0 plus
// exactly A exp((r - d)/B) (ahead) or lambda times it (behind), A once the
// bounding circles overlap.
TEST(SocialForce, ThePushOfOnePersonIsTheModelsExactly) {
  ModelParameters p;
  p.social_force = SocialForce::kCircular;
  p.social_force_anisotropy = 0.3;
  for (const double at : {0.7, -0.7, 0.2}) {
    WorldDef def = File(1, 10.0, 1.0, p);
    def.periodic = PeriodicBox{};
    def.people[0].position_m = {0.0, 0.0};
    PersonDef other = def.people[0];
    other.position_m = {at, 0.0};
    other.state = PersonState::kFallen;  // (an obstacle: no push of its own)
    def.people.push_back(other);
    const Simulation sim(def);
    const BodyShape& shape = sim.definition().shapes[0];  // (its core radius filled by the engine)
    const double bound = shape.core_radius_m + shape.radius_m;
    const double distance = std::abs(at);
    const double weight = at > 0.0 ? 1.0 : p.social_force_anisotropy;
    const double push = p.social_force_strength_n * std::exp(std::min(0.0, 2.0 * bound - distance) / p.social_force_range_m) * weight;
    const double drive = def.people[0].mass_kg / p.relaxation_time_s * 1.0;
    const Vec2 f = sim.bodies().force_n[0] - sim.bodies().contact_force_n[0];
    EXPECT_NEAR(f.x, drive + (at > 0.0 ? -push : push), 1e-9 * (drive + push)) << "other at " << at;
    EXPECT_NEAR(f.y, 0.0, 1e-9);
    if (distance < 2.0 * bound) {
      EXPECT_NEAR(push, p.social_force_strength_n * weight, 1e-9);
    }
  }
}

TEST(SocialForce, OffIsThePapersModelAndOnIsTheSameOnAnyThreadCountAndAfterAResume) {
  WorldDef paper = testing::RandomGas(6, 0.45, 5, true), numbers = paper;
  paper.parameters.ground_reaction = numbers.parameters.ground_reaction = true;
  numbers.parameters.social_force_strength_n = 50.0;  // off: its numbers change nothing
  Simulation sa(paper), sb(numbers);
  sa.AdvanceTo(0.3);
  sb.AdvanceTo(0.3);
  const std::size_t bytes = sa.bodies().size() * sizeof(Vec2);
  EXPECT_EQ(std::memcmp(sa.bodies().position_m.data(), sb.bodies().position_m.data(), bytes), 0);
  ModelParameters on;
  on.social_force = SocialForce::kCircular;
  ExpectTheSameOnAnyThreadCountAndAfterAResume(on, 0.1, "social force");
}


// A walker at the origin moving +x at `speed` (desired speed v0) with one
// fallen person (at rest, facing +x) at (at, 0): the force of the terms on
// the walker, less eq. (3)'s m/tau (v0 - speed) along +x.
Vec2 TermForceOnAWalker(const ModelParameters& p, double speed, double v0, double at, double* mass = nullptr) {
  WorldDef def = File(1, 10.0, v0, p);
  def.periodic = PeriodicBox{};
  def.people[0].position_m = {0.0, 0.0};
  def.people[0].velocity_m_per_s = {speed, 0.0};
  PersonDef other = def.people[0];
  other.position_m = {at, 0.0};
  other.velocity_m_per_s = {0.0, 0.0};
  other.state = PersonState::kFallen;
  def.people.push_back(other);
  const Simulation sim(def);
  if (mass != nullptr) *mass = def.people[0].mass_kg;
  const double drive = def.people[0].mass_kg / p.relaxation_time_s * (v0 - speed);
  return sim.bodies().force_n[0] - sim.bodies().contact_force_n[0] - Vec2{drive, 0.0};
}

// The generalized centrifugal force (issue 64): a walker at 1 m/s (its
// desired speed) heads for a person at rest. Its ellipse reaches a_min +
// tau_a (0.71 m) ahead, theirs a_min (0.18 m) back, so the gap is at - 0.89 m;
// K = 1, the closing speed 1 m/s: f(gap) = m (eta + 1)^2 / gap exactly
// between the interpolations, f_m f(r_eps) at touching ellipses and beyond,
// the far interpolation's midpoint and zero past r_c; nothing from a person
// behind, nothing on a walker at rest.
TEST(Centrifugal, TheRepulsionOfOnePersonIsTheModelsExactly) {
  ModelParameters p;
  p.centrifugal = Centrifugal::kGeneralized;
  const double reach = p.centrifugal_a_min_m + p.centrifugal_a_time_s * 1.0 + p.centrifugal_a_min_m;
  double m = 0.0;
  TermForceOnAWalker(p, 1.0, 1.0, 5.0, &m);
  const double scale = m * (p.centrifugal_strength + 1.0) * (p.centrifugal_strength + 1.0);
  const double eps = p.centrifugal_interpolation_m, rc = p.centrifugal_cutoff_m;
  struct Case {
    double gap, expected;
  };
  const double x0 = rc - eps;
  const double far_mid = (scale / x0) / 2.0 + eps * (-scale / (x0 * x0)) / 8.0;  // a cubic Hermite at t = 1/2
  for (const Case c : {Case{1.11, scale / 1.11}, Case{0.5, scale / 0.5}, Case{eps, scale / eps},
                       Case{x0, scale / x0}, Case{x0 + eps / 2.0, far_mid}, Case{rc + 0.01, 0.0},
                       Case{0.0, p.centrifugal_max_factor * scale / eps},
                       Case{-0.05, p.centrifugal_max_factor * scale / eps}}) {
    const Vec2 f = TermForceOnAWalker(p, 1.0, 1.0, reach + c.gap);
    EXPECT_NEAR(f.x, -c.expected, 1e-9 * (1.0 + c.expected)) << "gap " << c.gap;
    EXPECT_NEAR(f.y, 0.0, 1e-9) << "gap " << c.gap;
  }
  // Continuous across the interpolations' ends.
  for (const double joint : {eps, x0}) {
    const double below = -TermForceOnAWalker(p, 1.0, 1.0, reach + joint - 1e-7).x;
    const double above = -TermForceOnAWalker(p, 1.0, 1.0, reach + joint + 1e-7).x;
    EXPECT_NEAR(below, above, 1e-4 * above) << "at gap " << joint;
  }
  // It rises toward touching ellipses, monotonically.
  double previous = 0.0;
  for (double gap = 0.3; gap >= 0.0; gap -= 0.01) {
    const double f = -TermForceOnAWalker(p, 1.0, 1.0, reach + gap).x;
    EXPECT_GT(f, previous) << "gap " << gap;
    previous = f;
  }
  EXPECT_EQ(Length(TermForceOnAWalker(p, 1.0, 1.0, -1.0)), 0.0);  // behind
  EXPECT_EQ(Length(TermForceOnAWalker(p, 0.0, 1.0, 0.8)), 0.0);   // a walker at rest
}

// Anticipation by time to collision (issue 64): a walker at speed u heads
// for a person at rest at distance d on its line: tau = (d - R) / u, R the
// two bounding radii, and the force is m k e^(-tau/tau0) tau^-2 (2/tau +
// 1/tau0) / u backwards, exactly, up to its ceiling m a_max; nothing from a
// person it passes by (offset beyond R) or moves away from.
TEST(Anticipation, TheForceOfOneCollisionCourseIsTheModelsExactly) {
  ModelParameters p;
  p.anticipation = Anticipation::kTimeToCollision;
  WorldDef probe = File(1, 10.0, 1.0, p);
  const Simulation shape_probe(probe);
  const BodyShape& shape = shape_probe.definition().shapes[0];
  const double reach = 2.0 * (shape.core_radius_m + shape.radius_m);
  for (const double u : {0.6, 1.3}) {
    for (const double d : {1.5, 2.5, 4.0, 4.9}) {
      double m = 0.0;
      const Vec2 f = TermForceOnAWalker(p, u, 1.0, d, &m);
      const double tau = (d - reach) / u;
      const double k = p.anticipation_strength_m2, t0 = p.anticipation_horizon_s;
      const double a = std::min(k * std::exp(-tau / t0) / (tau * tau) * (2.0 / tau + 1.0 / t0) / u,
                                p.anticipation_max_acceleration_m_per_s2);
      EXPECT_NEAR(f.x, -m * a, 1e-9 * m * a) << "u " << u << ", d " << d;
      EXPECT_NEAR(f.y, 0.0, 1e-9);
    }
  }
  double m = 0.0;
  const double at_the_ceiling = -TermForceOnAWalker(p, 1.0, 1.0, reach + 0.05, &m).x;
  EXPECT_NEAR(at_the_ceiling, m * p.anticipation_max_acceleration_m_per_s2, 1e-9 * m);  // the ceiling
  EXPECT_EQ(Length(TermForceOnAWalker(p, 1.0, 1.0, -2.0)), 0.0);             // moving away
  EXPECT_EQ(Length(TermForceOnAWalker(p, 1.0, 1.0, p.anticipation_radius_m + 0.1)), 0.0);  // beyond the radius
  // Passing by: the other person 2 m ahead and R + 1 cm to the side.
  WorldDef def = File(1, 10.0, 1.0, p);
  def.periodic = PeriodicBox{};
  def.people[0].position_m = {0.0, 0.0};
  def.people[0].velocity_m_per_s = {1.0, 0.0};
  PersonDef other = def.people[0];
  other.position_m = {2.0, reach + 0.01};
  other.velocity_m_per_s = {0.0, 0.0};
  other.state = PersonState::kFallen;
  def.people.push_back(other);
  const Simulation sim(def);
  EXPECT_NEAR(sim.bodies().force_n[0].y, 0.0, 1e-12);
}

// A walker in a crowd (some 600 candidates, several of the term's chunks):
// its force is the sum, in the order of the people, of the force of each
// other person within the radius by the formula of one collision course
// (the candidates are picked without branches, then summed: no one missed,
// no one twice, nobody beyond the radius or moving away).
TEST(Anticipation, ACrowdsForceIsTheSumOfEachPersonsInTheirOrder) {
  ModelParameters p;
  p.anticipation = Anticipation::kTimeToCollision;
  WorldDef def = File(1, 10.0, 1.0, p);
  def.periodic = PeriodicBox{};
  def.people[0].position_m = {0.0, 0.0};
  def.people[0].velocity_m_per_s = {1.0, 0.0};  // its desired velocity: no drive
  std::uint64_t state = 12345;
  const auto uniform = [&state] {  // (a fixed sequence, the same on every compiler)
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  for (int n = 0; n < 700; ++n) {
    PersonDef other = def.people[0];
    const double r = 0.8 + 5.2 * std::sqrt(uniform()), angle = 6.283185307179586 * uniform();
    other.position_m = {r * std::cos(angle), r * std::sin(angle)};
    other.velocity_m_per_s = {2.0 * uniform() - 1.0, 2.0 * uniform() - 1.0};
    other.state = PersonState::kFallen;  // (obstacles: they do not move themselves)
    def.people.push_back(other);
  }
  const Simulation sim(def);
  const BodyState& b = sim.bodies();
  const BodyShape& shape = sim.definition().shapes[0];
  const double reach = 2.0 * (shape.core_radius_m + shape.radius_m);
  const double k = p.anticipation_strength_m2, t0 = p.anticipation_horizon_s;
  Vec2 expected{};
  int within = 0, acting = 0;
  for (std::size_t j = 1; j < b.size(); ++j) {
    const Vec2 x = b.position_m[0] - b.position_m[j], v = b.velocity_m_per_s[0] - b.velocity_m_per_s[j];
    if (Dot(x, x) > p.anticipation_radius_m * p.anticipation_radius_m) continue;
    ++within;
    const double a = Dot(v, v), bb = Dot(x, v), c = Dot(x, x) - reach * reach, disc = bb * bb - a * c;
    if (!(c > 0.0 && bb < 0.0 && disc > 0.0)) continue;
    ++acting;
    const double tau = c / (std::sqrt(disc) - bb);
    const double size = k * std::exp(-tau / t0) / (tau * tau) * (2.0 / tau + 1.0 / t0) / std::sqrt(disc);
    expected += (x + v * tau) * (std::min(size * reach, p.anticipation_max_acceleration_m_per_s2) / reach);
  }
  ASSERT_GT(within, 400);  // several chunks of candidates
  ASSERT_GT(acting, 20);
  const Vec2 on_walker = (b.force_n[0] - b.contact_force_n[0]) * (1.0 / def.people[0].mass_kg);
  EXPECT_NEAR(on_walker.x, expected.x, 1e-9 * Length(expected)) << within << " within, " << acting << " acting";
  EXPECT_NEAR(on_walker.y, expected.y, 1e-9 * Length(expected));
}

// The anticipation's clock (anticipation_interval_s, issue 66). A periodic
// crowd of 64 walkers, half heading +x, half -x, at 1.2 m/s, anticipating.
WorldDef CrossingCrowd(double interval_s, unsigned seed = 7, int per_side = 8, double spacing_m = 1.3) {
  WorldDef def = testing::RandomGas(per_side, spacing_m, seed, true);
  def.parameters = ModelParameters{};
  def.parameters.anticipation = Anticipation::kTimeToCollision;
  def.parameters.anticipation_interval_s = interval_s;
  def.targets.push_back(geometry::NavigationField::Constant({-1.0, 0.0}));
  for (std::size_t i = 0; i < def.people.size(); ++i) {  // (a checkerboard: head on along each row)
    const bool east = (i + i / static_cast<std::size_t>(per_side)) % 2 == 0;
    def.people[i].desired_speed_m_per_s = 1.2;
    def.people[i].target = east ? 0 : 1;
    def.people[i].velocity_m_per_s = {east ? 1.0 : -1.0, 0.2 * def.people[i].velocity_m_per_s.y};
  }
  return def;
}

bool SameBodies(const Simulation& a, const Simulation& b) {
  const auto& x = a.bodies().position_m;
  const auto& y = b.bodies().position_m;
  const auto& u = a.bodies().velocity_m_per_s;
  const auto& w = b.bodies().velocity_m_per_s;
  return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(Vec2)) == 0 &&
         std::memcmp(u.data(), w.data(), u.size() * sizeof(Vec2)) == 0;
}

// Steps each simulation `steps` times, in turn.
void StepEach(int steps, std::initializer_list<Simulation*> simulations) {
  for (int n = 0; n < steps; ++n)
    for (Simulation* sim : simulations) sim->Step();
}

// The wide instructions (AVX2) pick the same collision courses, and give
// them the same forces, as the scalar loop: a crowd crossing in a periodic
// box (minimum images across it) and in the open, with someone fallen and
// an empty slot, is the same run bit for bit either way (and it is a run
// where the term acts: without it, another).
TEST(Anticipation, TheWideInstructionsPickTheSameCollisionCoursesBitForBit) {
  if (!WideInstructions()) GTEST_SKIP() << "this processor has no AVX2";
  for (const bool periodic : {true, false}) {
    WorldDef def = CrossingCrowd(0.0);
    if (!periodic) def.periodic = PeriodicBox{};
    def.people[5].state = PersonState::kFallen;
    def.people[9].state = PersonState::kRemoved;
    WorldDef without = def;
    without.parameters.anticipation = Anticipation::kNone;
    Simulation wide(def), narrow(def), none(without);
    testing::StepWideAndNarrow(600, wide, narrow, none);
    EXPECT_TRUE(SameBodies(wide, narrow)) << (periodic ? "periodic" : "open");
    EXPECT_FALSE(SameBodies(wide, none));
  }
}

// Each pair once (issue 66; the term's head): the run that walks each
// person's whole list, bit for bit — a crowd of 576 crossing at 1.2 /m2
// (enough for the drive's threads), periodic (minimum images across the
// box) and in the open, with people fallen, gone and standing by choice
// (each only the partner of a pair), on 1 to 3 threads; and a run where
// the term acts (without it, another).
TEST(Anticipation, EachPairOnceIsTheRunOfEachPersonsWholeListBitForBit) {
  for (const bool periodic : {true, false}) {
    WorldDef def = CrossingCrowd(0.0, 11, 24, 0.9);
    if (!periodic) def.periodic = PeriodicBox{};
    for (std::size_t i = 3; i < def.people.size(); i += 37) def.people[i].state = PersonState::kFallen;
    for (std::size_t i = 5; i < def.people.size(); i += 53) def.people[i].state = PersonState::kRemoved;
    for (std::size_t i = 7; i < def.people.size(); i += 41) def.people[i].desired_speed_m_per_s = 0.0;
    WorldDef without = def;
    without.parameters.anticipation = Anticipation::kNone;
    Simulation whole(def), none(without);
    std::vector<Simulation> halves;
    for (const int threads : {1, 2, 3}) {
      def.threads = threads;
      halves.emplace_back(def);
    }
    for (int n = 0; n < 300; ++n) {
      UseHalfPairs(false);
      whole.Step();
      UseHalfPairs(true);
      for (Simulation& half : halves) half.Step();
      none.Step();
    }
    for (const Simulation& half : halves)
      EXPECT_TRUE(SameBodies(whole, half)) << (periodic ? "periodic, " : "open, ") << half.definition().threads;
    EXPECT_FALSE(SameBodies(whole, none));
  }
}

// An interval shorter than the step is an evaluation at every step: the run
// made without the clock, bit for bit; a longer one is another run.
TEST(AnticipationClock, AnIntervalShorterThanTheStepIsEveryStep) {
  Simulation every(CrossingCrowd(0.0)), clocked(CrossingCrowd(1e-6)), coarse(CrossingCrowd(0.05));
  ASSERT_LT(1e-6, every.time_step_s());
  StepEach(600, {&every, &clocked, &coarse});
  EXPECT_TRUE(SameBodies(every, clocked));
  EXPECT_FALSE(SameBodies(every, coarse));
}

// Within an interval each walker's anticipation force per unit mass is the
// one of the interval's first step; the next interval evaluates it anew. A
// walker alone with people lying ahead of it (out of reach of any contact),
// at its desired speed and with a long relaxation time (eq. 3's drive, m /
// tau (v0 e - v) with the velocity the forces were evaluated with, the
// step's second half kick before, is then small and subtracted).
TEST(AnticipationClock, TheForceIsKeptThroughAnIntervalAndEvaluatedAnewAtTheNext) {
  for (const double interval : {0.0, 0.02}) {
    ModelParameters p;
    p.anticipation = Anticipation::kTimeToCollision;
    p.anticipation_interval_s = interval;
    p.relaxation_time_s = 100.0;
    WorldDef def = File(1, 10.0, 1.0, p);
    def.periodic = PeriodicBox{};
    def.people[0].position_m = {0.0, 0.0};
    def.people[0].velocity_m_per_s = {1.0, 0.0};
    for (int k = 0; k < 3; ++k) {
      PersonDef lying = def.people[0];
      lying.position_m = {3.0 + k, 0.3 * (k - 1)};
      lying.velocity_m_per_s = {0.0, 0.0};
      lying.state = PersonState::kFallen;
      def.people.push_back(lying);
    }
    Simulation sim(def);
    const double m = def.people[0].mass_kg, h = sim.time_step_s();
    std::vector<std::pair<double, Vec2>> per_step;  // (time the forces were evaluated at, the force / m)
    while (sim.time_s() < 0.1) {
      sim.Step();
      const BodyState& b = sim.bodies();
      ASSERT_TRUE(sim.contacts().empty());
      const Vec2 v_evaluated = b.velocity_m_per_s[0] - b.force_n[0] * (h / (2.0 * m));
      const Vec2 drive = (Vec2{1.0, 0.0} - v_evaluated) * (m / p.relaxation_time_s);
      per_step.push_back({sim.time_s(), (b.force_n[0] - drive) * (1.0 / m)});
    }
    int kept = 0, anew = 0;
    for (std::size_t n = 1; n < per_step.size(); ++n) {
      const Vec2 d = per_step[n].second - per_step[n - 1].second;
      const bool same_interval = interval > 0.0 && std::floor(per_step[n].first / interval) ==
                                                       std::floor(per_step[n - 1].first / interval);
      if (same_interval) {
        EXPECT_LT(Length(d), 1e-7) << "t " << per_step[n].first;
        ++kept;
      } else {
        EXPECT_GT(Length(d), 1e-6) << "t " << per_step[n].first << ", interval " << interval;
        ++anew;
      }
    }
    EXPECT_GT(anew, interval > 0.0 ? 3 : 100);
    if (interval > 0.0) {
      EXPECT_GT(kept, 10 * anew);
    }
  }
}

// The kept forces are the term's state: a clocked run saved in the middle of
// an interval and loaded into a new simulation goes on as the run made in
// one go, on one thread or two.
TEST(AnticipationClock, AResumeInTheMiddleOfAnIntervalIsTheRunMadeInOneGo) {
  for (const double near : {0.0, 1.5}) {  // (every pair on the clock; the split by distance)
    WorldDef def = CrossingCrowd(0.05);
    def.parameters.anticipation_near_m = near;
    Simulation whole(def);
    while (whole.time_s() < 0.23) whole.Step();  // (0.2 + 0.03: within an interval)
    const std::string saved = whole.SaveState();
    for (int n = 0; n < 300; ++n) whole.Step();
    for (const int threads : {1, 2}) {
      WorldDef d = def;
      d.threads = threads;
      Simulation resumed(d);
      resumed.LoadState(saved);
      for (int n = 0; n < 300; ++n) resumed.Step();
      EXPECT_TRUE(SameBodies(whole, resumed)) << threads << " thread(s), near " << near;
    }
  }
  // (without the kept forces, the resumed run would evaluate at once: another run)
}

// The split by distance (anticipation_near_m): with every pair nearer than
// the switch (a group of 16 within 3 m), every force is evaluated at every
// step from the near list, and the run is the exact one, bit for bit; with
// a near radius inside the group, another run.
TEST(AnticipationClock, WithEveryPairNearTheSplitIsTheExactRun) {
  auto group = [](double interval, double near) {
    WorldDef def = CrossingCrowd(interval);
    def.periodic = PeriodicBox{};
    def.people.resize(16);
    for (std::size_t i = 0; i < def.people.size(); ++i)
      def.people[i].position_m = {0.7 * static_cast<double>(i % 4), 0.7 * static_cast<double>(i / 4)};
    def.parameters.anticipation_near_m = near;
    return def;
  };
  Simulation exact(group(0.0, 0.0)), all_near(group(0.05, 5.0)), split(group(0.05, 1.0));
  StepEach(300, {&exact, &all_near, &split});  // (a quarter of a second: the group stays within 4 m)
  EXPECT_TRUE(SameBodies(exact, all_near));
  EXPECT_FALSE(SameBodies(exact, split));
}

// The clock keeps state: switching it on or off during a run is refused
// (its length may change).
TEST(AnticipationClock, ItCannotBeSwitchedOnOrOffDuringARun) {
  Simulation sim(CrossingCrowd(0.0));
  ModelParameters p = sim.definition().parameters;
  p.anticipation_interval_s = 0.02;
  EXPECT_THROW(sim.SetParameters(p), InputError);
  Simulation clocked(CrossingCrowd(0.02));
  p.anticipation_interval_s = 0.04;
  EXPECT_NO_THROW(clocked.SetParameters(p));
  p.anticipation_interval_s = 0.0;
  EXPECT_THROW(clocked.SetParameters(p), InputError);
}

// Anticipation is a walker's: a person who stands by choice (desired speed
// 0, waiting for a pre-movement time) does not dodge a walker heading at
// them; the walker dodges them all the same, and a person who wants to walk
// (standing still for the moment) dodges too.
TEST(Anticipation, PeopleWhoStandByChoiceDoNotDodge) {
  ModelParameters p;
  p.anticipation = Anticipation::kTimeToCollision;
  for (const double desired : {0.0, 0.5}) {
    WorldDef def = File(1, 10.0, 1.0, p);
    def.periodic = PeriodicBox{};
    def.people[0].position_m = {0.0, 0.0};
    def.people[0].velocity_m_per_s = {1.0, 0.0};
    PersonDef other = def.people[0];
    other.position_m = {2.0, 0.05};
    other.velocity_m_per_s = {0.0, 0.0};
    other.desired_speed_m_per_s = desired;
    def.people.push_back(other);
    const Simulation sim(def);
    const Vec2 on_walker = sim.bodies().force_n[0] - sim.bodies().contact_force_n[0];
    EXPECT_LT(on_walker.x, -1.0) << "desired " << desired;  // the walker brakes and turns
    const double drive = def.people[1].mass_kg / p.relaxation_time_s * desired;  // toward +x from rest
    const Vec2 on_standing = sim.bodies().force_n[1] - sim.bodies().contact_force_n[1] - Vec2{drive, 0.0};
    if (desired == 0.0)
      EXPECT_EQ(Length(on_standing), 0.0);
    else
      EXPECT_GT(Length(on_standing), 1.0);
  }
}

// Two walkers meeting head on, their lines 0.1 m apart: with the paper's
// model they collide; with either term they pass each other.
// Two walkers 8 m apart heading for each other at 1.2 m/s (their desired
// speed), the second `offset_m` to the side (+y) of the first's line.
WorldDef HeadOn(const ModelParameters& p, double offset_m) {
  WorldDef def = File(1, 10.0, 1.2, p);
  def.periodic = PeriodicBox{};
  def.targets.push_back(geometry::NavigationField::Constant({-1.0, 0.0}));
  def.people[0].position_m = {0.0, 0.0};
  def.people[0].velocity_m_per_s = {1.2, 0.0};
  PersonDef other = def.people[0];
  other.position_m = {8.0, offset_m};
  other.velocity_m_per_s = {-1.2, 0.0};
  other.angle_rad = 3.14159265358979;
  other.target = 1;
  def.people.push_back(other);
  return def;
}

TEST(KeepingDistance, TwoWalkersMeetingHeadOnPassWithTheCentrifugalForceOrAnticipation) {
  ModelParameters centrifugal, anticipation;
  centrifugal.centrifugal = Centrifugal::kGeneralized;
  anticipation.anticipation = Anticipation::kTimeToCollision;
  const std::vector<const ModelParameters*> cases{nullptr, &centrifugal, &anticipation};
  for (const ModelParameters* p : cases) {
    Simulation sim(HeadOn(p != nullptr ? *p : ModelParameters{}, 0.1));
    bool touched = false;
    while (sim.time_s() < 12.0) {
      sim.Step();
      touched = touched || !sim.contacts().empty();
    }
    const bool passed = sim.bodies().position_m[0].x > 8.0 && sim.bodies().position_m[1].x < 0.0;
    if (p == nullptr) {
      EXPECT_TRUE(touched) << "the paper's model";
    } else {
      EXPECT_FALSE(touched) << (p == &centrifugal ? "centrifugal" : "anticipation");
      EXPECT_TRUE(passed) << (p == &centrifugal ? "centrifugal" : "anticipation");
    }
  }
}

// The side preference (issue 64): the braking part of the anticipation
// force, -F.e_i, turned by the share s into a step to the right of e_i: on a
// walker heading +x for a person at rest on its line, F = (-m a, -s m a)
// exactly (a the force per unit mass of one collision course, the same as
// without it); a negative share steps to the left; nothing where nothing
// brakes (moving away, beyond the radius).
TEST(Anticipation, TheSidePreferenceTurnsTheBrakingPartToTheRight) {
  ModelParameters p;
  p.anticipation = Anticipation::kTimeToCollision;
  for (const double d : {1.5, 2.5, 4.0}) {
    double m = 0.0;
    const Vec2 straight = TermForceOnAWalker(p, 1.0, 1.0, d, &m);
    ASSERT_LT(straight.x, 0.0);
    for (const double side : {0.4, -0.25, 1.0}) {
      ModelParameters q = p;
      q.anticipation_side_preference = side;
      const Vec2 f = TermForceOnAWalker(q, 1.0, 1.0, d);
      EXPECT_EQ(f.x, straight.x) << "d " << d << ", side " << side;
      EXPECT_NEAR(f.y, side * straight.x, 1e-12 * m) << "d " << d << ", side " << side;  // -s m a: to the right of +x
    }
  }
  // Gated (slowed): times max(0, 1 - v.e / v0): none at the desired speed,
  // 0.5 of it at half of it (a walker at 0.6 m/s wanting 1.2).
  ModelParameters gated = p;
  gated.anticipation_side_preference = 0.4;
  gated.anticipation_side_gate = SidePreferenceGate::kSlowed;
  for (const double d : {1.5, 2.5}) {
    const Vec2 at_pace = TermForceOnAWalker(gated, 1.0, 1.0, d), ungated_at_pace = TermForceOnAWalker(p, 1.0, 1.0, d);
    EXPECT_EQ(at_pace.x, ungated_at_pace.x);
    EXPECT_EQ(at_pace.y, 0.0) << "d " << d;
    double m = 0.0;
    const Vec2 slowed = TermForceOnAWalker(gated, 0.6, 1.2, d, &m), straight = TermForceOnAWalker(p, 0.6, 1.2, d);
    EXPECT_EQ(slowed.x, straight.x);
    EXPECT_NEAR(slowed.y, 0.4 * 0.5 * straight.x, 1e-12 * m) << "d " << d;
  }
  ModelParameters q = p;
  q.anticipation_side_preference = 0.5;
  EXPECT_EQ(Length(TermForceOnAWalker(q, 1.0, 1.0, -2.0)), 0.0);                             // moving away
  EXPECT_EQ(Length(TermForceOnAWalker(q, 1.0, 1.0, q.anticipation_radius_m + 0.1)), 0.0);  // beyond the radius
}

// Two walkers meeting head on exactly on one line (no jitter): without a
// side preference nothing tells them apart sideways, they brake and stand
// face to face, neither passing; with it each steps to its own right (the
// one heading +x to -y, the one heading -x to +y) and they pass without
// touching; with a negative share each to its left. Whichever way, the same on any thread
// count and after a resume.
TEST(KeepingDistance, TwoWalkersHeadOnOnOneLineEachStepToTheirOwnRight) {
  for (const double side : {0.0, 0.3, -0.3}) {
    ModelParameters p;
    p.anticipation = Anticipation::kTimeToCollision;
    p.anticipation_side_preference = side;
    Simulation sim(HeadOn(p, 0.0));
    bool touched = false;
    double y0_at_passing = 0.0, y1_at_passing = 0.0;
    while (sim.time_s() < 12.0) {
      sim.Step();
      touched = touched || !sim.contacts().empty();
      const BodyState& b = sim.bodies();
      if (b.position_m[0].x < b.position_m[1].x) y0_at_passing = b.position_m[0].y, y1_at_passing = b.position_m[1].y;
    }
    const BodyState& b = sim.bodies();
    const bool passed = b.position_m[0].x > 8.0 && b.position_m[1].x < 0.0;
    if (side == 0.0) {
      EXPECT_FALSE(passed) << "no side preference: a standoff";
      EXPECT_EQ(b.position_m[0].y, 0.0) << "no side preference: nobody steps aside";
    } else {
      EXPECT_FALSE(touched) << "side " << side;
      EXPECT_TRUE(passed) << "side " << side;
      const double right = side > 0.0 ? 1.0 : -1.0;
      EXPECT_LT(right * y0_at_passing, -0.1) << "the walker heading +x: to its right (-y) for side > 0";
      EXPECT_GT(right * y1_at_passing, 0.1) << "the walker heading -x: to its right (+y) for side > 0";
    }
  }
  ModelParameters p;
  p.anticipation = Anticipation::kTimeToCollision;
  p.anticipation_side_preference = 0.3;
  ExpectTheSameOnAnyThreadCountAndAfterAResume(p, 0.1, "side preference");
}

TEST(KeepingDistance, TheCentrifugalForceAndAnticipationOffAreThePapersModelAndOnTheSameOnAnyThreadCountAndAfterAResume) {
  WorldDef paper = testing::RandomGas(6, 0.45, 5, true), numbers = paper;
  paper.parameters.ground_reaction = numbers.parameters.ground_reaction = true;
  numbers.parameters.centrifugal_strength = 2.0;  // off: their numbers change nothing
  numbers.parameters.anticipation_strength_m2 = 9.0;
  Simulation sa(paper), sb(numbers);
  sa.AdvanceTo(0.3);
  sb.AdvanceTo(0.3);
  const std::size_t bytes = sa.bodies().size() * sizeof(Vec2);
  EXPECT_EQ(std::memcmp(sa.bodies().position_m.data(), sb.bodies().position_m.data(), bytes), 0);
  ModelParameters centrifugal, anticipation;
  centrifugal.centrifugal = Centrifugal::kGeneralized;
  anticipation.anticipation = Anticipation::kTimeToCollision;
  ExpectTheSameOnAnyThreadCountAndAfterAResume(centrifugal, 0.1, "centrifugal");
  ExpectTheSameOnAnyThreadCountAndAfterAResume(anticipation, 0.1, "anticipation");
}

}  // namespace
}  // namespace crowdrecon::engine
