// Sleeping (ModelParameters::sleep_speed_m_per_s > 0; issue 66, point 3;
// docs/model.md "Sleeping"): a jammed crowd falls asleep and stays where the
// full integration holds it, at less cost; sleepers wake when pushed, when
// their target changes and when a wall goes; the results do not depend on
// the thread count or a resume; off, nothing changes (the reference
// checksums, bench/reference/checksums.txt, are of runs without it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/fnv.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::engine {
namespace {

using testing::SetMassFromShape;
using testing::ThoraxLikeShape;

constexpr double kEndWallX = 4.0;

// A dead end: a corridor 2.5 m wide closed at x = 4 m, 40 people (the
// paper's model, thorax-like bodies) pressing toward its end at 1 m/s; a
// 41st slot empty (for a latecomer). Wall 2 is the end.
WorldDef DeadEnd() {
  WorldDef def;
  def.parameters.ground_reaction = true;
  def.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
  def.targets.push_back(geometry::NavigationField::Constant({-1.0, 0.0}));
  def.shapes.push_back(ThoraxLikeShape());
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 5; ++j) {
      PersonDef p;
      SetMassFromShape(def.shapes[0], 1000.0, p);
      p.mass_kg *= 1.0 + 0.2 * u(rng);
      p.position_m = {1.0 + 0.36 * i + 0.02 * u(rng), 0.3 + 0.48 * j + 0.02 * u(rng)};
      p.desired_speed_m_per_s = 1.0;
      def.people.push_back(p);
    }
  PersonDef latecomer = def.people.front();
  latecomer.state = PersonState::kRemoved;
  def.people.push_back(latecomer);
  def.walls.push_back({{{-1.0, 0.0}, {kEndWallX, 0.0}}, false, 0.0});
  def.walls.push_back({{{-1.0, 2.5}, {kEndWallX, 2.5}}, false, 0.0});
  def.walls.push_back({{{kEndWallX, -0.5}, {kEndWallX, 3.0}}, false, 0.0});
  return def;
}

std::string Sealed(std::string bytes) {
  const std::uint64_t checksum = Fnv1a(bytes.data(), bytes.size());
  bytes.append(reinterpret_cast<const char*>(&checksum), sizeof(checksum));
  return bytes;
}

// The first person asleep (40: nobody).
std::uint32_t FirstSleeper(const Simulation& sim) {
  for (std::uint32_t i = 0; i < 40; ++i)
    if (sim.asleep(i)) return i;
  return 40;
}

void MakeSleeping(WorldDef& def) {
  def.parameters.sleep_speed_m_per_s = 0.02;
  def.parameters.sleep_time_s = 0.5;
  def.parameters.sleep_wake_force_n = 20.0;
}

// The end wall's load: the contact forces on it (on the people: -x).
double EndWallLoad(const Simulation& sim) {
  double load = 0.0;
  for (const Contact& c : sim.contacts())
    if (c.wall && c.b == 2) load -= c.Force().x;
  return load;
}

TEST(Sleeping, AJammedCrowdFallsAsleepWhereTheFullIntegrationHoldsItAtLessCost) {
  WorldDef def = DeadEnd();
  Simulation full(def);
  MakeSleeping(def);
  Simulation sleeping(def);
  full.AdvanceTo(6.0);
  sleeping.AdvanceTo(6.0);
  const std::uint64_t pairs_at_6 = sleeping.profile().pairs_measured, full_pairs_at_6 = full.profile().pairs_measured;
  const double time_at_6 = sleeping.profile().seconds(Stage::kCollide) + sleeping.profile().seconds(Stage::kDrive);
  const double full_time_at_6 = full.profile().seconds(Stage::kCollide) + full.profile().seconds(Stage::kDrive);
  full.AdvanceTo(12.0);
  sleeping.AdvanceTo(12.0);
  EXPECT_EQ(full.asleep_count(), 0u);
  EXPECT_GE(sleeping.asleep_count(), 30u) << "of 40";
  // Where they stand: within a centimetre of the full integration's (the
  // crowd is a packing held by stiff contacts; people at rest in the paper's
  // model chatter from step to step, eq. 15's switch, so stillness is what
  // sends them to sleep, not the force of one step).
  double worst = 0.0;
  for (std::size_t i = 0; i < 40; ++i)
    worst = std::max(worst, Length(sleeping.bodies().position_m[i] - full.bodies().position_m[i]));
  EXPECT_LT(worst, 0.01);
  // The end wall's load within 3 % (each sleeper's load within 20 N of the mean it held).
  const double load = EndWallLoad(full);
  EXPECT_GT(load, 1000.0);
  EXPECT_NEAR(EndWallLoad(sleeping), load, 0.03 * load);
  // Sleepers carry their contacts: far fewer pairs measured from 6 s to 12 s.
  const std::uint64_t measured = sleeping.profile().pairs_measured - pairs_at_6;
  const std::uint64_t full_measured = full.profile().pairs_measured - full_pairs_at_6;
  EXPECT_LT(measured * 2, full_measured) << measured << " against " << full_measured;
  const double time = sleeping.profile().seconds(Stage::kCollide) + sleeping.profile().seconds(Stage::kDrive) - time_at_6;
  const double full_time = full.profile().seconds(Stage::kCollide) + full.profile().seconds(Stage::kDrive) - full_time_at_6;
  std::printf("[ sleeping ] 6-12 s: %zu of 40 asleep; farthest from the full run %.2g m; end wall %.1f N vs %.1f N; "
              "pairs measured %llu vs %llu; collide + drive %.3f s vs %.3f s\n",
              sleeping.asleep_count(), worst, EndWallLoad(sleeping), load, static_cast<unsigned long long>(measured),
              static_cast<unsigned long long>(full_measured), time, full_time);
}

TEST(Sleeping, SleepersWakeWhenPushedWhenTheirTargetChangesAndWhenAWallGoes) {
  WorldDef def = DeadEnd();
  MakeSleeping(def);
  // Someone arriving at 1.5 m/s wakes the people they run into: the contact
  // force on a sleeper is computed at every step and grows past the bound.
  {
    Simulation sim(def);
    sim.AdvanceTo(12.0);
    std::vector<std::uint8_t> was_asleep(40);
    double back = kEndWallX;
    for (std::uint32_t i = 0; i < 40; ++i) {
      was_asleep[i] = sim.asleep(i);
      back = std::min(back, sim.bodies().position_m[i].x);
    }
    ASSERT_GE(std::count(was_asleep.begin(), was_asleep.end(), 1), 30);
    PersonDef latecomer = def.people[40];
    latecomer.state = PersonState::kWalking;
    latecomer.position_m = {back - 0.8, 1.25};
    latecomer.velocity_m_per_s = {1.5, 0.0};
    latecomer.desired_speed_m_per_s = 1.5;
    sim.Spawn(40, latecomer, 40);
    std::vector<std::uint8_t> woke(40, 0);
    while (sim.time_s() < 14.0) {
      sim.Step();
      for (std::uint32_t i = 0; i < 40; ++i) woke[i] = woke[i] || (was_asleep[i] && !sim.asleep(i));
    }
    EXPECT_GE(std::count(woke.begin(), woke.end(), 1), 1) << "nobody woke when run into";
    // The sleepers are not obstacles of infinite mass: the crowd gave way.
    EXPECT_GT(sim.bodies().position_m[40].x, back - 0.8 + 0.3);
  }
  // A new target wakes its person at once, and they walk away.
  {
    Simulation sim(def);
    sim.AdvanceTo(12.0);
    const std::uint32_t sleeper = FirstSleeper(sim);
    ASSERT_LT(sleeper, 40u);
    const Vec2 before = sim.bodies().position_m[sleeper];
    for (std::uint32_t i = 0; i < 40; ++i) sim.SetTarget(i, 1);
    EXPECT_EQ(sim.asleep_count(), 0u);
    sim.AdvanceTo(14.0);
    EXPECT_LT(sim.bodies().position_m[sleeper].x, before.x - 0.5);
  }
  // The end wall switched off: everyone wakes, and the crowd walks on.
  {
    Simulation sim(def);
    sim.AdvanceTo(12.0);
    ASSERT_GT(sim.asleep_count(), 0u);
    double front = 0.0;
    for (std::uint32_t i = 0; i < 40; ++i) front = std::max(front, sim.bodies().position_m[i].x);
    sim.SetWallEnabled(2, false);
    EXPECT_EQ(sim.asleep_count(), 0u);
    sim.AdvanceTo(13.0);
    double front_now = 0.0;
    for (std::uint32_t i = 0; i < 40; ++i) front_now = std::max(front_now, sim.bodies().position_m[i].x);
    EXPECT_GT(front_now, front + 0.3);
  }
  // An external force wakes its person.
  {
    Simulation sim(def);
    sim.AdvanceTo(12.0);
    const std::uint32_t sleeper = FirstSleeper(sim);
    ASSERT_LT(sleeper, 40u);
    sim.SetExternalForce(sleeper, {0.0, 5.0});
    EXPECT_FALSE(sim.asleep(sleeper));
  }
}

TEST(Sleeping, ResultsDoNotDependOnTheThreadCountOrAResume) {
  WorldDef def = DeadEnd();
  MakeSleeping(def);
  std::vector<Vec2> reference;
  std::size_t asleep = 0;
  for (int threads : {1, 2, 3}) {
    def.threads = threads;
    Simulation sim(def);
    sim.AdvanceTo(9.0);
    const auto& x = sim.bodies().position_m;
    if (reference.empty()) {
      reference = x;
      asleep = sim.asleep_count();
      EXPECT_GT(asleep, 0u);
    } else {
      ASSERT_EQ(std::memcmp(reference.data(), x.data(), x.size() * sizeof(Vec2)), 0) << threads;
      EXPECT_EQ(sim.asleep_count(), asleep);
    }
  }
  def.threads = 1;
  // Interrupted before anyone sleeps, while people fall asleep, and after.
  for (double stop : {0.3, 4.1, 7.7}) {
    Simulation first(def);
    first.AdvanceTo(stop);
    const std::string state = first.SaveState();
    Simulation resumed(def);
    resumed.LoadState(state);
    EXPECT_EQ(resumed.asleep_count(), first.asleep_count()) << stop;
    resumed.AdvanceTo(9.0);
    ASSERT_EQ(std::memcmp(reference.data(), resumed.bodies().position_m.data(), reference.size() * sizeof(Vec2)), 0)
        << stop;
  }
}

TEST(Sleeping, NeedsVelocityVerletAndItsStateIsCheckedWhenRead) {
  ModelParameters p;
  p.sleep_speed_m_per_s = 0.02;
  std::string error;
  EXPECT_TRUE(p.IsValid(&error)) << error;
  p.integrator = Integrator::kGear5;
  EXPECT_FALSE(p.IsValid(&error));
  EXPECT_NE(error.find("sleep_speed_m_per_s > 0 needs integrator = velocity_verlet"), std::string::npos) << error;
  // A checkpoint whose sleeping state is damaged is refused as such.
  WorldDef def = DeadEnd();
  MakeSleeping(def);
  Simulation sim(def);
  sim.AdvanceTo(8.0);
  ASSERT_GT(sim.asleep_count(), 0u);
  std::string state = sim.SaveState();
  // The section is last: six vectors of 41 entries (asleep 1 byte, the
  // spell's time 8, the frozen drive 16 and 8, the spell's place 16 and 8),
  // each after its count, then the checksum.
  const std::size_t tail = 8 + 6 * 8 + 41 * (1 + 8 + 16 + 8 + 16 + 8);
  const std::size_t first_flag = state.size() - tail + 8;
  state[first_flag] = 7;
  // (The checksum is recomputed so that the reader gets as far as the flag.)
  Simulation other(def);
  try {
    other.LoadState(Sealed(state.substr(0, state.size() - 8)));
    ADD_FAILURE() << "a damaged sleeping state was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("damaged sleeping state of slot 0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace crowdrecon::engine
