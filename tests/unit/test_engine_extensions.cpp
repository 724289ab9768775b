// The model's extensions beyond the paper (issue 39; docs/decisions.md,
// "Issue 39"): each off by default, each verified against what it claims.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "crowdrecon/engine/simulation.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::engine {
namespace {

using testing::RandomGas;
using testing::SetMassFromShape;
using testing::ThoraxLikeShape;

// People far apart (no contacts), walking +x at 1 m/s, with the gait jitter on.
WorldDef WalkingApart(int count, double sigma_m_per_s) {
  WorldDef def;
  def.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
  def.shapes.push_back(ThoraxLikeShape());
  def.parameters.gait_jitter = GaitJitter::kIsotropic;
  def.parameters.gait_jitter_velocity_m_per_s = sigma_m_per_s;
  def.parameters.gait_jitter_seed = 7;
  for (int i = 0; i < count; ++i) {
    PersonDef p;
    SetMassFromShape(def.shapes[0], 1000.0, p);
    p.mass_kg *= 0.8 + 0.4 * (i % 7) / 6.0;  // the jitter is an acceleration: mass must not matter
    p.inertia_kg_m2 *= 0.8 + 0.4 * (i % 7) / 6.0;
    p.position_m = {5.0 * (i % 10), 5.0 * (i / 10)};
    p.desired_speed_m_per_s = 1.0;  // all along +x at the same speed: they keep apart
    def.people.push_back(p);
  }
  return def;
}

// The paper's crowd (a periodic gas of walkers) and the same crowd with
// `same` and with `different` applied to its parameters: `same` must leave
// every position bit for bit as the paper's, `different` must change them.
template <typename Same, typename Different>
void ExpectOnlyTheExtensionActs(Same same, Different different) {
  WorldDef paper = RandomGas(6, 0.42, 5, true);
  paper.parameters.ground_reaction = true;
  Simulation a(paper);
  a.AdvanceTo(0.4);
  const std::size_t bytes = a.bodies().size() * sizeof(Vec2);
  for (const auto& change : same) {
    WorldDef def = paper;
    change(def.parameters);
    Simulation b(def);
    b.AdvanceTo(0.4);
    EXPECT_EQ(std::memcmp(a.bodies().position_m.data(), b.bodies().position_m.data(), bytes), 0);
  }
  WorldDef on = paper;
  different(on.parameters);
  Simulation d(on);
  d.AdvanceTo(0.4);
  EXPECT_NE(std::memcmp(a.bodies().position_m.data(), d.bodies().position_m.data(), bytes), 0);  // and on, it acts
}

// `on` (an extension switched on) run to 0.5 s is the same bit for bit as
// `one_thread` (the same world on one thread, run to 0.5 s) on two threads
// and after a resume from a checkpoint at 0.25 s.
void ExpectSameOnTwoThreadsAndAfterAResume(WorldDef on, const Simulation& one_thread) {
  const std::size_t bytes = one_thread.bodies().size() * sizeof(Vec2);
  on.threads = 2;
  Simulation two(on);
  two.AdvanceTo(0.5);
  EXPECT_EQ(std::memcmp(one_thread.bodies().position_m.data(), two.bodies().position_m.data(), bytes), 0);
  Simulation first(on);
  first.AdvanceTo(0.25);
  Simulation resumed(on);
  resumed.LoadState(first.SaveState());
  resumed.AdvanceTo(0.5);
  EXPECT_EQ(std::memcmp(one_thread.bodies().position_m.data(), resumed.bodies().position_m.data(), bytes), 0);
}

using ParameterChange = std::function<void(ModelParameters&)>;

// Eq. (3) with the jitter, m dv/dt = m/tau (u - v), filters u by
// 1/(1 + i w tau); for u of variance sigma^2 spread evenly over [f1, f2] the
// velocity's variance per axis is
//   sigma^2/(f2 - f1) * integral_f1^f2 df/(1 + (2 pi f tau)^2)
//   = sigma^2/(f2 - f1) * [atan(2 pi f tau)/(2 pi tau)]_f1^f2.
TEST(GaitJitter, FreePeopleMoveWithTheAnalyticVarianceOfEquation3) {
  const double sigma = 0.3;
  WorldDef def = WalkingApart(100, sigma);
  const ModelParameters& mp = def.parameters;
  const double tau = mp.relaxation_time_s, f1 = mp.gait_jitter_band_low_hz, f2 = mp.gait_jitter_band_high_hz;
  const double w = 2.0 * std::numbers::pi * tau;
  const double expected = sigma * sigma / (f2 - f1) * (std::atan(w * f2) - std::atan(w * f1)) / w;
  Simulation sim(def);
  sim.AdvanceTo(5.0 * tau);  // the start from rest decays
  double sum = 0.0, sum_sq = 0.0;
  long samples = 0;
  for (int k = 1; k <= 1500; ++k) {  // 60 s sampled every 0.04 s
    sim.AdvanceTo(5.0 * tau + 0.04 * k);
    for (const Vec2& v : sim.bodies().velocity_m_per_s) {  // (about the desired velocity (1, 0) m/s)
      sum += (v.x - 1.0) + v.y;
      sum_sq += (v.x - 1.0) * (v.x - 1.0) + v.y * v.y;
      samples += 2;
    }
  }
  const double mean = sum / double(samples), variance = sum_sq / double(samples) - mean * mean;
  EXPECT_NEAR(mean, 0.0, 0.02 * std::sqrt(expected));
  EXPECT_NEAR(variance, expected, 0.05 * expected) << "expected " << expected << " (m/s)^2 per axis";
  // Nobody met anybody: the people walked 5 m apart and swayed centimetres.
  EXPECT_TRUE(sim.contacts().empty());
}

// The jitter is the gait's: a person who stands by choice (desired speed 0:
// waiting for a pre-movement time) does not sway; one who wants to walk does.
TEST(GaitJitter, PeopleWhoStandByChoiceDoNotSway) {
  WorldDef def = WalkingApart(4, 0.3);
  def.people[0].desired_speed_m_per_s = 0.0;
  def.people[1].desired_speed_m_per_s = 0.0;
  Simulation sim(def);
  sim.AdvanceTo(5.0);
  for (int i : {0, 1}) {
    EXPECT_EQ(sim.bodies().position_m[i].x, def.people[i].position_m.x) << "person " << i;
    EXPECT_EQ(sim.bodies().position_m[i].y, def.people[i].position_m.y) << "person " << i;
  }
  EXPECT_NE(sim.bodies().position_m[2].y, def.people[2].position_m.y);  // walking, it sways across
}

// Off, the strength and band change nothing: the paper's model bit for bit.
// On with a zero strength, the same.
TEST(GaitJitter, OffIsThePapersModelBitForBit) {
  ExpectOnlyTheExtensionActs(
      std::vector<ParameterChange>{[](ModelParameters& p) {
                                     p.gait_jitter_velocity_m_per_s = 2.0;
                                     p.gait_jitter_band_low_hz = 3.0;
                                     p.gait_jitter_band_high_hz = 4.0;
                                     p.gait_jitter_seed = 99;
                                   },
                                   [](ModelParameters& p) {
                                     p.gait_jitter = GaitJitter::kIsotropic;
                                     p.gait_jitter_velocity_m_per_s = 0.0;
                                   }},
      [](ModelParameters& p) { p.gait_jitter = GaitJitter::kIsotropic; });
}

// The jitter is a function of time, the seed and the person's id: the same
// on any thread count and after a resume; another seed gives another jitter.
TEST(GaitJitter, SameOnAnyThreadCountAndAfterAResumeAndItsSeedMatters) {
  for (Integrator integrator : {Integrator::kVelocityVerlet, Integrator::kGear5}) {
    WorldDef def = RandomGas(6, 0.42, 9, true);
    def.parameters.ground_reaction = true;
    def.parameters.integrator = integrator;
    def.parameters.gait_jitter = GaitJitter::kIsotropic;
    def.parameters.gait_jitter_seed = 3;
    Simulation straight(def);
    straight.AdvanceTo(0.4);
    def.threads = 2;
    Simulation two_threads(def);
    two_threads.AdvanceTo(0.4);
    Simulation first(def);
    first.AdvanceTo(0.2);
    Simulation resumed(def);
    resumed.LoadState(first.SaveState());
    resumed.AdvanceTo(0.4);
    const std::size_t bytes = straight.bodies().size() * sizeof(Vec2);
    ASSERT_EQ(resumed.step_count(), straight.step_count());
    EXPECT_EQ(std::memcmp(straight.bodies().position_m.data(), two_threads.bodies().position_m.data(), bytes), 0);
    EXPECT_EQ(std::memcmp(straight.bodies().position_m.data(), resumed.bodies().position_m.data(), bytes), 0);
    EXPECT_EQ(std::memcmp(straight.bodies().velocity_m_per_s.data(), resumed.bodies().velocity_m_per_s.data(), bytes), 0);
    def.parameters.gait_jitter_seed = 4;
    Simulation other_seed(def);
    other_seed.AdvanceTo(0.4);
    EXPECT_NE(std::memcmp(straight.bodies().position_m.data(), other_seed.bodies().position_m.data(), bytes), 0);
  }
}

// The wide instructions (AVX2) give the scalar cosines bit for bit: 100
// walkers swaying for 40 s (arguments in every quadrant, phases far from the
// first cycle), the one run stepped with them and the other without, and a
// slot filled anew (its draws are another person's); the jitter acts.
TEST(GaitJitter, TheWideInstructionsGiveTheScalarCosinesBitForBit) {
  if (!WideInstructions()) GTEST_SKIP() << "this processor has no AVX2";
  WorldDef def = WalkingApart(100, 0.3);
  WorldDef still = def;
  still.parameters.gait_jitter_velocity_m_per_s = 0.0;
  Simulation wide(def), narrow(def), none(still);
  testing::StepWideAndNarrow(static_cast<int>(40.0 / wide.time_step_s()), wide, narrow, none);
  const std::size_t bytes = def.people.size() * sizeof(Vec2);
  EXPECT_EQ(std::memcmp(wide.bodies().velocity_m_per_s.data(), narrow.bodies().velocity_m_per_s.data(), bytes), 0);
  EXPECT_NE(std::memcmp(wide.bodies().velocity_m_per_s.data(), none.bodies().velocity_m_per_s.data(), bytes), 0);
}

TEST(GaitJitter, ImpossibleSettingsAreRefusedSayingWhy) {
  ModelParameters p;
  std::string error;
  p.gait_jitter_band_low_hz = 2.0;
  p.gait_jitter_band_high_hz = 1.0;
  EXPECT_FALSE(p.IsValid(&error));
  EXPECT_NE(error.find("gait_jitter_band_high_hz = 1, expected at least gait_jitter_band_low_hz = 2"), std::string::npos)
      << error;
  p = ModelParameters();
  p.gait_jitter_seed = 1.5;
  EXPECT_FALSE(p.IsValid(&error));
  EXPECT_NE(error.find("gait_jitter_seed = 1.5, expected a whole number"), std::string::npos) << error;
  p = ModelParameters();
  p.gait_jitter_velocity_m_per_s = -0.1;
  EXPECT_FALSE(p.IsValid(&error));
  EXPECT_NE(error.find("gait_jitter_velocity_m_per_s"), std::string::npos) << error;
}

// A row of people walking into a wall along a corridor one body wide (disks, so that nothing turns; no
// back force, which acts only on people moving backwards and would flicker
// at rest): at rest, the wall carries the sum of what each person drives
// with, m v0/tau for the paper's eq. (3). Yielding, everyone held up by the
// person ahead drives with push_share m v0/tau; the first in the row is held
// up by the wall only, which does not make anyone yield, and drives fully.
double WallLoadOfARow(Yielding yielding, double push_share, double* expected_paper_n, double* first_n = nullptr) {
  WorldDef def;
  def.parameters.back_force_gamma = 0.0;
  def.parameters.yielding = yielding;
  def.parameters.yielding_push_share = push_share;
  def.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
  def.shapes.push_back(testing::DiskShape(0.2));
  *expected_paper_n = 0.0;
  for (int i = 0; i < 5; ++i) {
    PersonDef p;
    SetMassFromShape(def.shapes[0], 1000.0, p);
    p.mass_kg *= 1.0 + 0.1 * i;
    p.position_m = {-0.45 * i - 0.25, 0.0};
    p.desired_speed_m_per_s = 0.9 + 0.05 * i;
    const double drive_n = p.mass_kg * p.desired_speed_m_per_s / def.parameters.relaxation_time_s;
    *expected_paper_n += drive_n;
    if (i == 0 && first_n) *first_n = drive_n;
    def.people.push_back(p);
  }
  def.walls.push_back({{{0.0, -2.0}, {0.0, 2.0}}, false, 0.0});
  // A corridor one body wide keeps them in single file (a row of disks
  // pushed end-on buckles otherwise and everyone reaches the wall).
  def.walls.push_back({{{-5.0, -0.205}, {0.0, -0.205}}, false, 0.0});
  def.walls.push_back({{{-5.0, 0.205}, {0.0, 0.205}}, false, 0.0});
  Simulation sim(def);
  sim.AdvanceTo(20.0);  // walk in, settle
  double load = 0.0;
  int samples = 0;
  for (int k = 1; k <= 200; ++k) {  // the mean over 2 s
    sim.AdvanceTo(20.0 + 0.01 * k);
    for (const Contact& c : sim.contacts())
      if (c.wall && c.b == 0) load += -Dot(c.Force(), Vec2{1.0, 0.0});  // Force() acts on the person
    ++samples;
  }
  return load / samples;
}

TEST(Yielding, ABlockedRowLeansOnTheWallWithItsShareOfTheDrive) {
  double paper_n = 0.0, first_n = 0.0;
  const double paper = WallLoadOfARow(Yielding::kNone, 0.3, &paper_n);
  EXPECT_NEAR(paper, paper_n, 0.01 * paper_n) << "the paper's eq. (3): every drive adds up at the wall";
  for (double share : {1.0, 0.5, 0.25, 0.0}) {
    const double load = WallLoadOfARow(Yielding::kWhenBlocked, share, &paper_n, &first_n);
    const double expected = first_n + share * (paper_n - first_n);
    EXPECT_NEAR(load, expected, 0.01 * paper_n) << "push share " << share;
  }
}

// Off, the share changes nothing: the paper's model bit for bit; a share of
// 1 is the paper's push too.
TEST(Yielding, OffOrAFullShareIsThePapersModelBitForBit) {
  ExpectOnlyTheExtensionActs(std::vector<ParameterChange>{[](ModelParameters& p) { p.yielding_push_share = 0.2; },
                                                          [](ModelParameters& p) {
                                                            p.yielding = Yielding::kWhenBlocked;
                                                            p.yielding_push_share = 1.0;
                                                          }},
                             [](ModelParameters& p) { p.yielding = Yielding::kWhenBlocked; });
}

// A disk pressed onto a wall and pushed along it below the friction limit:
// with the paper's spring it sticks; with a creeping spring (a Maxwell
// element: spring kt in series with the relaxation over T, beside the
// tangential dashpot m gamma_t) it slides at the steady velocity where the
// push balances kt delta + m gamma_t v with d(delta)/dt = v - delta/T = 0:
//   v = F_t / (kt T + m gamma_t).
TEST(TangentialSpringCreep, AHeldContactSlidesAtTheMaxwellElementsVelocity) {
  for (double relaxation_s : {0.5, 2.0, 8.0}) {
    WorldDef def = testing::PassiveWorld();
    def.parameters.tangential_spring = TangentialSpring::kCreeping;
    def.parameters.tangential_spring_relaxation_time_s = relaxation_s;
    def = testing::DiskOnWall(def);  // (no rolling: isolates sliding)
    const PersonDef& p = def.people[0];
    Simulation sim(def);
    const double fn = 500.0, ft = 0.5 * def.parameters.friction_coefficient * fn;  // half the Coulomb limit
    sim.SetExternalForce(0, {0.0, -fn});
    sim.AdvanceTo(1.0);
    sim.SetExternalForce(0, {ft, -fn});
    sim.AdvanceTo(1.0 + 6.0 * relaxation_s);  // the spring's transient decays
    const double x0 = sim.bodies().position_m[0].x, t0 = sim.time_s();
    sim.AdvanceTo(t0 + relaxation_s);
    const double measured = (sim.bodies().position_m[0].x - x0) / (sim.time_s() - t0);
    const double kt = def.parameters.tangential_stiffness_n_per_m;
    const double gamma_t = DampingRateFromRestitution(def.parameters.wall_restitution, kt, p.mass_kg);
    const double expected = ft / (kt * relaxation_s + p.mass_kg * gamma_t);
    EXPECT_NEAR(measured, expected, 0.01 * expected) << "T = " << relaxation_s << " s";
  }
  // The paper's spring holds the same push: it only rings down from the
  // sudden load (tens of micrometres), where the slowest creep above slides
  // 2.5 mm in the same 2 s.
  const WorldDef def = testing::DiskOnWall();
  Simulation sim(def);
  sim.SetExternalForce(0, {0.0, -500.0});
  sim.AdvanceTo(1.0);
  sim.SetExternalForce(0, {0.5 * def.parameters.friction_coefficient * 500.0, -500.0});
  sim.AdvanceTo(3.0);
  const double x0 = sim.bodies().position_m[0].x;
  sim.AdvanceTo(5.0);
  EXPECT_LT(std::abs(sim.bodies().position_m[0].x - x0), 1e-4);
}

// The creep changes nothing unless chosen: the paper's spring bit for bit,
// whatever T; and like every option the same on any thread count and after
// a resume.
TEST(TangentialSpringCreep, OffIsThePapersModelAndOnIsDeterministic) {
  WorldDef paper = RandomGas(6, 0.42, 5, true);
  paper.parameters.ground_reaction = true;
  WorldDef off = paper;
  off.parameters.tangential_spring_relaxation_time_s = 0.01;
  WorldDef on = paper;
  on.parameters.tangential_spring = TangentialSpring::kCreeping;
  on.parameters.tangential_spring_relaxation_time_s = 0.05;
  Simulation a(paper), b(off), c(on);
  for (Simulation* s : {&a, &b, &c}) s->AdvanceTo(0.5);
  const std::size_t bytes = a.bodies().size() * sizeof(Vec2);
  EXPECT_EQ(std::memcmp(a.bodies().position_m.data(), b.bodies().position_m.data(), bytes), 0);
  EXPECT_NE(std::memcmp(a.bodies().position_m.data(), c.bodies().position_m.data(), bytes), 0);
  ExpectSameOnTwoThreadsAndAfterAResume(on, c);
}

// Two people facing each other on the axis of a corridor `width_m` wide,
// `distance_m` from its middle, each walking toward the other's side; the
// second `spread` heavier and faster, and both `offset_m` off the axis on
// opposite sides.
WorldDef TwoPeopleHeadOn(const ModelParameters& parameters, double width_m, double distance_m, double offset_m,
                         double spread) {
  WorldDef def;
  def.parameters = parameters;
  def.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
  def.targets.push_back(geometry::NavigationField::Constant({-1.0, 0.0}));
  def.shapes.push_back(ThoraxLikeShape());
  for (int i = 0; i < 2; ++i) {
    PersonDef p;
    SetMassFromShape(def.shapes[0], 1000.0, p);
    p.mass_kg *= 1.0 + spread * i;
    p.position_m = {i == 0 ? -distance_m : distance_m, i == 0 ? offset_m : -offset_m};
    p.angle_rad = i == 0 ? 0.0 : std::numbers::pi;
    p.target = static_cast<std::uint32_t>(i);
    p.desired_speed_m_per_s = 1.0 + spread * i;
    def.people.push_back(p);
  }
  def.walls.push_back({{{-20.0, -0.5 * width_m}, {20.0, -0.5 * width_m}}, false, 0.0});
  def.walls.push_back({{{-20.0, 0.5 * width_m}, {20.0, 0.5 * width_m}}, false, 0.0});
  return def;
}

// Two people meet head-on in a corridor narrower than their two breadths
// (0.6 m against 2 x 0.42 m) and wider than their two depths (2 x 0.24 m):
// Yamamoto et al. (Transp. Res. B 122:486, 2019) saw people in this
// situation turn their bodies and pass. Returns the time (s) at which both
// have passed each other's starting point (negative: not by 30 s);
// *level_turn_rad receives the smaller of their turns away from the
// corridor's axis at the moment their centres are level.
double HeadOnInANarrowCorridor(ShoulderTurn turn, double* level_turn_rad) {
  ModelParameters parameters;
  parameters.shoulder_turn = turn;
  const WorldDef def = TwoPeopleHeadOn(parameters, 0.6, 1.5, 0.01, 0.1);
  Simulation sim(def);
  *level_turn_rad = -1.0;
  for (int k = 1; k <= 30000; ++k) {
    sim.AdvanceTo(0.001 * k);
    const auto& b = sim.bodies();
    if (*level_turn_rad < 0.0 && b.position_m[0].x >= b.position_m[1].x) {
      // |sin| of the angle: the share of the breadth turned out of the way.
      *level_turn_rad = std::min(std::asin(std::abs(std::sin(b.angle_rad[0]))), std::asin(std::abs(std::sin(b.angle_rad[1]))));
    }
    if (b.position_m[0].x > 1.5 && b.position_m[1].x < -1.5) return sim.time_s();
  }
  return -1.0;
}

TEST(ShoulderTurn, TwoPeopleMeetingInACorridorTooNarrowForBothTurnAndPass) {
  double paper_turn = 0.0, turn = 0.0;
  const double paper_s = HeadOnInANarrowCorridor(ShoulderTurn::kNone, &paper_turn);
  const double passed_s = HeadOnInANarrowCorridor(ShoulderTurn::kWhenBlocked, &turn);
  std::printf("paper: passed at %.2f s, turn when level %.2f rad; turning: passed at %.2f s, turn when level %.2f rad\n",
              paper_s, paper_turn, passed_s, turn);
  ASSERT_GT(passed_s, 0.0) << "turned sideways, they fit";
  EXPECT_TRUE(paper_s < 0.0 || passed_s < paper_s) << "turning on purpose passes sooner than being turned by the contacts";
  EXPECT_GT(turn, 1.0) << "both pass with a shoulder first";
}

// An extension's settings (`off`) change nothing while it is off: the
// paper's model bit for bit; switched on (`on`), it acts, and the same on
// two threads and after a resume.
void ExpectOffIsThePapersModelAndOnIsDeterministic(const ParameterChange& off, const ParameterChange& on_change) {
  ExpectOnlyTheExtensionActs(std::vector<ParameterChange>{off}, on_change);
  WorldDef on = RandomGas(6, 0.42, 5, true);
  on.parameters.ground_reaction = true;
  on_change(on.parameters);
  Simulation one(on);
  one.AdvanceTo(0.5);
  ExpectSameOnTwoThreadsAndAfterAResume(on, one);
}

// Off, the angle changes nothing: the paper's model bit for bit.
TEST(ShoulderTurn, OffIsThePapersModelBitForBitAndOnIsDeterministic) {
  ExpectOffIsThePapersModelAndOnIsDeterministic([](ModelParameters& p) { p.shoulder_turn_angle_deg = 30.0; },
                                                [](ModelParameters& p) { p.shoulder_turn = ShoulderTurn::kWhenBlocked; });
}

// Two people meet head-on in a corridor too narrow to pass at all (0.45 m:
// less than two depths, more than a breadth). Returns the lowest velocity
// along its own desired direction that the person heading +x reached after
// the first 3 s (negative: it walked back), and the world's end state.
double HeadOnWithNoWayPast(const ModelParameters& parameters, int threads, std::vector<Vec2>* end_positions) {
  WorldDef def = TwoPeopleHeadOn(parameters, 0.45, 1.0, 0.0, 0.0);
  def.threads = threads;
  Simulation sim(def);
  double lowest = 1e9;
  for (int k = 1; k <= 120; ++k) {
    if (k == 80) {  // while giving way (from about 6 s), resume from a checkpoint: the same run
      Simulation resumed(def);
      resumed.LoadState(sim.SaveState());
      resumed.AdvanceTo(0.1 * k);
      sim.AdvanceTo(0.1 * k);
      EXPECT_EQ(std::memcmp(sim.bodies().position_m.data(), resumed.bodies().position_m.data(), 2 * sizeof(Vec2)), 0);
      continue;
    }
    sim.AdvanceTo(0.1 * k);
    if (k > 30) lowest = std::min(lowest, sim.bodies().velocity_m_per_s[0].x);  // after their collision's bounce
  }
  *end_positions = sim.bodies().position_m;
  return lowest;
}

TEST(GiveWay, APersonBlockedByPeopleHeadingTheOtherWayGivesWayOnlyWhereThereIsRoom) {
  ModelParameters paper;
  std::vector<Vec2> paper_end, no_room_end, room_end, two_threads_end;
  const double paper_lowest = HeadOnWithNoWayPast(paper, 1, &paper_end);
  EXPECT_GT(paper_lowest, -0.05) << "the paper's people stand chest to chest";
  ModelParameters give_way;
  give_way.give_way = GiveWay::kWhereRoom;
  give_way.give_way_max_contacts = 0;  // touching one person is already too many
  HeadOnWithNoWayPast(give_way, 1, &no_room_end);
  EXPECT_EQ(std::memcmp(paper_end.data(), no_room_end.data(), 2 * sizeof(Vec2)), 0) << "no room: the paper's model";
  give_way.give_way_max_contacts = 1;
  const double lowest = HeadOnWithNoWayPast(give_way, 1, &room_end);
  EXPECT_LT(lowest, -0.5) << "after " << give_way.give_way_blocked_s << " s blocked it walks back with the other";
  HeadOnWithNoWayPast(give_way, 2, &two_threads_end);
  EXPECT_EQ(std::memcmp(room_end.data(), two_threads_end.data(), 2 * sizeof(Vec2)), 0);
}

// Off, its settings change nothing: the paper's model bit for bit (that it
// acts when on is the test above).
TEST(GiveWay, OffIsThePapersModelBitForBit) {
  WorldDef paper = RandomGas(6, 0.42, 5, true);
  paper.parameters.ground_reaction = true;
  WorldDef off = paper;
  off.parameters.give_way_blocked_s = 0.1;
  off.parameters.give_way_max_contacts = 20;
  Simulation a(paper), b(off);
  a.AdvanceTo(0.4);
  b.AdvanceTo(0.4);
  EXPECT_EQ(std::memcmp(a.bodies().position_m.data(), b.bodies().position_m.data(), a.bodies().size() * sizeof(Vec2)), 0);
  ModelParameters invalid;
  invalid.give_way_max_contacts = 2.5;
  std::string error;
  EXPECT_FALSE(invalid.IsValid(&error));
  EXPECT_NE(error.find("give_way_max_contacts = 2.5, expected a whole number"), std::string::npos) << error;
}

// A reaction time (DriveReaction::kLagged): a person starting from rest,
// alone, with m dv/dt = m/tau (v0 - w) and dw/dt = (v - w)/T, so that
// u = w - v0 obeys T u'' + u' + u/tau = 0 with u(0) = -v0, u'(0) = 0 and
// v = w + T w'. For T > tau/4 the roots are alpha +- i beta, alpha = -1/(2T),
// beta = sqrt(4T/tau - 1)/(2T): u = -v0 e^(alpha t) (cos bt - alpha/b sin bt),
// and the speed overshoots v0 before it settles, as a driver's with a delay.
TEST(DriveReaction, APersonStartingFromRestFollowsTheLaggedEquation3) {
  WorldDef def = testing::FreeWalker({1.0, 0.0}, 1.2);
  def.parameters.drive_reaction = DriveReaction::kLagged;
  const double T = def.parameters.drive_reaction_time_s, tau = def.parameters.relaxation_time_s;
  const double v0 = def.people[0].desired_speed_m_per_s, alpha = -0.5 / T, beta = std::sqrt(4.0 * T / tau - 1.0) / (2.0 * T);
  const auto analytic = [&](double t) {
    const double c = std::cos(beta * t), s = std::sin(beta * t), decay = std::exp(alpha * t);
    const double u = -v0 * decay * (c - alpha / beta * s);
    const double du = -v0 * decay * (alpha * c - alpha * alpha / beta * s - beta * s - alpha * c);
    return v0 + u + T * du;  // v = w + T w'
  };
  // The largest error of the speed over 5 s at the engine's step h, and at
  // h/2 (the update of w assumes v constant over a step: first order in h).
  const auto run = [&](double step_s, double* peak) {
    WorldDef at = def;
    at.parameters.time_step_s = step_s;
    Simulation sim(at);
    double largest_error = 0.0;
    *peak = 0.0;
    for (int k = 1; k <= 100; ++k) {
      sim.AdvanceTo(0.05 * k);
      const double v = sim.bodies().velocity_m_per_s[0].x;
      largest_error = std::max(largest_error, std::abs(v - analytic(sim.time_s())));
      *peak = std::max(*peak, v);
      EXPECT_NEAR(sim.bodies().velocity_m_per_s[0].y, 0.0, 1e-12);
    }
    std::printf("step %.3g s: largest error %.3g m/s\n", step_s, largest_error);
    return largest_error;
  };
  const double h = EstimateTimeStep(def).chosen_s;
  double peak = 0.0, half_peak = 0.0;
  const double error = run(h, &peak), half_error = run(0.5 * h, &half_peak);
  EXPECT_LT(error, 1e-3 * v0);
  EXPECT_NEAR(error / half_error, 2.0, 0.2) << "first order in the step";
  double analytic_peak = 0.0;
  for (int k = 1; k <= 5000; ++k) analytic_peak = std::max(analytic_peak, analytic(0.001 * k));
  std::printf("T = %.2f s: peak speed %.4f m/s (analytic %.4f) for v0 = %.2f m/s\n", T, peak, analytic_peak, v0);
  EXPECT_GT(analytic_peak, 1.05 * v0) << "an overshoot the paper's model (T = 0) does not have";
  EXPECT_NEAR(peak, analytic_peak, 1e-3 * v0);
}

// Off, its time changes nothing: the paper's model bit for bit; on, it acts,
// the same on two threads and after a resume (the perceived velocities are
// in the checkpoint).
TEST(DriveReaction, OffIsThePapersModelBitForBitAndOnIsDeterministic) {
  ExpectOffIsThePapersModelAndOnIsDeterministic([](ModelParameters& p) { p.drive_reaction_time_s = 3.0; },
                                                [](ModelParameters& p) { p.drive_reaction = DriveReaction::kLagged; });
}

}  // namespace
}  // namespace crowdrecon::engine
