// The house of the drive (issue 63): behaviour terms as parts (which terms a
// run has, their states in checkpoints, switching them during a run) and the
// neighbour stage. Each term's physics is tested with its extension
// (test_engine_extensions.cpp, test_floor_slope.cpp, test_engine_physics.cpp);
// that the terms changed no result is bench/reference/checksums.txt.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::engine {
namespace {

using testing::RandomGas;

WorldDef Walkers(const ModelParameters& parameters, int per_side = 6) {
  WorldDef def = RandomGas(per_side, 0.45, 5, true);
  def.parameters = parameters;
  def.parameters.ground_reaction = true;
  for (PersonDef& p : def.people) p.desired_speed_m_per_s = 1.2;
  return def;
}

ModelParameters EveryTermWithState() {
  ModelParameters p;
  p.back_force_trigger = BackForceTrigger::kAveragedVelocity;
  p.drive_reaction = DriveReaction::kLagged;
  p.give_way = GiveWay::kWhereRoom;
  p.give_way_blocked_s = 0.1;
  return p;
}

TEST(BehaviourTerms, ThePapersModelHasItsFourTermsAndEachExtensionAddsItsOwn) {
  using Names = std::vector<std::string>;
  const Names paper{"desired_velocity", "back_force", "motive_torque", "rotational_damping"};
  EXPECT_EQ(Simulation(Walkers(ModelParameters{})).BehaviourTermNames(), paper);
  ModelParameters p;
  p.yielding = Yielding::kWhenBlocked;
  p.shoulder_turn = ShoulderTurn::kWhenBlocked;
  p.give_way = GiveWay::kWhereRoom;
  p.drive_reaction = DriveReaction::kLagged;
  p.gait_jitter = GaitJitter::kIsotropic;
  p.gait_jitter_velocity_m_per_s = 0.1;
  WorldDef def = Walkers(p);
  def.slope.gradient = 0.1;
  def.slope.downhill = {1.0, 0.0};
  EXPECT_EQ(Simulation(def).BehaviourTermNames(),
            (Names{"giving_way", "yielding", "reaction_time", "desired_velocity", "gait_jitter", "back_force",
                   "motive_torque", "shoulder_turn", "rotational_damping", "floor_slope"}));
  // A jitter of no amplitude, a level floor: no term.
  p.gait_jitter_velocity_m_per_s = 0.0;
  def = Walkers(p);
  const Names names = Simulation(def).BehaviourTermNames();
  EXPECT_EQ(std::count(names.begin(), names.end(), "gait_jitter"), 0);
  EXPECT_EQ(std::count(names.begin(), names.end(), "floor_slope"), 0);
}

TEST(BehaviourTerms, ACheckpointCarriesEachTermsStateAndRefusesAnotherSetOfTerms) {
  const WorldDef def = Walkers(EveryTermWithState());
  Simulation first(def);
  first.AdvanceTo(0.3);
  const std::string state = first.SaveState();
  first.AdvanceTo(0.6);
  Simulation resumed(def);
  resumed.LoadState(state);
  resumed.AdvanceTo(0.6);
  const std::size_t bytes = first.bodies().size() * sizeof(Vec2);
  EXPECT_EQ(std::memcmp(first.bodies().position_m.data(), resumed.bodies().position_m.data(), bytes), 0);
  // Restored into a run whose parameters have other terms with state: refused, naming both sets.
  ModelParameters fewer = EveryTermWithState();
  fewer.give_way = GiveWay::kNone;
  Simulation other(Walkers(fewer));
  try {
    other.LoadState(state);
    FAIL() << "a checkpoint with another set of terms was restored";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("terms giving_way, reaction_time, back_force where"), std::string::npos) << what;
    EXPECT_NE(what.find("have reaction_time, back_force (different model parameters?)"), std::string::npos) << what;
  }
}

TEST(BehaviourTerms, ATermWithStateCannotBeSwitchedDuringARunAStatelessOneCan) {
  Simulation sim(Walkers(ModelParameters{}));
  sim.AdvanceTo(0.05);
  ModelParameters p = sim.definition().parameters;
  p.drive_reaction = DriveReaction::kLagged;
  try {
    sim.SetParameters(p);
    FAIL() << "the reaction time was switched on during a run";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("behaviour term reaction_time on"), std::string::npos) << e.what();
  }
  EXPECT_EQ(sim.definition().parameters.drive_reaction, DriveReaction::kInstant);
  sim.AdvanceTo(0.1);  // the run goes on with its terms
  p = sim.definition().parameters;
  p.gait_jitter = GaitJitter::kIsotropic;
  p.gait_jitter_velocity_m_per_s = 0.2;
  sim.SetParameters(p);
  const std::vector<std::string> names = sim.BehaviourTermNames();
  EXPECT_EQ(std::count(names.begin(), names.end(), "gait_jitter"), 1);
  sim.AdvanceTo(0.15);
  // A run with state keeps it through a change of its numbers.
  Simulation lagged(Walkers(EveryTermWithState()));
  Simulation same(Walkers(EveryTermWithState()));
  lagged.AdvanceTo(0.2);
  same.AdvanceTo(0.2);
  ModelParameters q = lagged.definition().parameters;
  q.back_force_gamma = 2.0;
  lagged.SetParameters(q);
  same.SetParameters(q);
  lagged.AdvanceTo(0.4);
  same.AdvanceTo(0.4);
  const std::size_t bytes = same.bodies().size() * sizeof(Vec2);
  EXPECT_EQ(std::memcmp(lagged.bodies().position_m.data(), same.bodies().position_m.data(), bytes), 0);
}

// The people within r of person i, by brute force (minimum image).
std::vector<std::uint32_t> BruteForceWithin(const Simulation& sim, std::uint32_t i, double r) {
  std::vector<std::uint32_t> within;
  const auto& x = sim.bodies().position_m;
  for (std::uint32_t j = 0; j < x.size(); ++j)
    if (j != i && Length(sim.Separation(x[i], x[j])) <= r) within.push_back(j);
  return within;
}

void ExpectNeighboursAsBruteForce(bool periodic) {
  WorldDef def = Walkers(ModelParameters{}, 12);
  if (!periodic) def.periodic = PeriodicBox{};
  Simulation sim(def);
  const double r = 1.3;
  sim.RequestNeighbours(r);
  std::size_t listed = 0;
  for (double t : {0.0, 0.2, 0.6}) {  // the list carried over steps, and rebuilt as people move
    sim.AdvanceTo(t);
    for (std::uint32_t i = 0; i < sim.bodies().size(); ++i) {
      const std::vector<std::uint32_t> found = sim.NeighboursWithin(i, r);
      EXPECT_EQ(found, BruteForceWithin(sim, i, r)) << "person " << i << " at t = " << t;
      listed += found.size();
    }
  }
  EXPECT_GT(listed, 3u * 144u * 10u);  // about 6 people per 1.3 m circle at 5 persons/m^2, and more
}

TEST(NeighbourStage, FindsExactlyThePeopleWithinTheRadiusInAnOpenWorldAndAPeriodicBox) {
  ExpectNeighboursAsBruteForce(false);
  ExpectNeighboursAsBruteForce(true);
}

TEST(NeighbourStage, PeopleFarApartNeedNoMoreCellsThanPeople) {
  WorldDef def = Walkers(ModelParameters{}, 2);
  def.periodic = PeriodicBox{};
  def.people[0].position_m = {0.0, 0.0};
  def.people[1].position_m = {1.0, 0.5};
  def.people[2].position_m = {1e7, -1e7};  // a grid of 2 m cells would have 5e6 x 5e6 of them
  def.people[3].position_m = {1e7 + 1.5, -1e7};
  Simulation sim(def);
  sim.RequestNeighbours(2.0);
  EXPECT_EQ(sim.NeighboursWithin(0, 2.0), (std::vector<std::uint32_t>{1}));
  EXPECT_EQ(sim.NeighboursWithin(3, 2.0), (std::vector<std::uint32_t>{2}));
  EXPECT_TRUE(sim.NeighboursWithin(2, 1.0).empty());
}

// Empty slots (parked together by the hundred in a timeline's engine) are
// nobody's candidates; a slot filled between builds is listed at once where
// it was at the build (so that a drive evaluated at a placement sees what it
// saw when every slot was listed: bench/reference's timeline-validated), and
// where it is now from the next build on.
TEST(NeighbourStage, EmptySlotsAreNobodysCandidatesAndSlotsFilledAgainAreListedAtOnce) {
  WorldDef def = Walkers(ModelParameters{}, 2);
  def.periodic = PeriodicBox{};
  def.people[0].position_m = {0.0, 0.0};
  def.people[1].position_m = {1.0, 0.5};
  def.people[2].position_m = {0.5, -0.6};  // parked beside person 0
  def.people[3].position_m = {8.0, 8.0};   // parked far away
  def.people[2].state = def.people[3].state = PersonState::kRemoved;
  PersonDef newcomer = def.people[0];
  Simulation sim(def);
  sim.RequestNeighbours(2.0);
  using Ids = std::vector<std::uint32_t>;
  EXPECT_EQ(sim.NeighboursWithin(0, 2.0), (Ids{1}));
  sim.SetPersonState(2, PersonState::kWalking);  // back where they were parked: no rebuild
  EXPECT_EQ(sim.NeighboursWithin(0, 2.0), (Ids{1, 2}));
  newcomer.position_m = {0.2, 0.9};
  sim.Spawn(3, newcomer, 3);  // far from the build's place of slot 3: not yet person 0's candidate
  EXPECT_EQ(sim.NeighboursWithin(0, 2.0), (Ids{1, 2}));
  sim.AdvanceTo(1e-3);  // the newcomer moved far since the build: rebuilt
  EXPECT_EQ(sim.NeighboursWithin(0, 2.0), (Ids{1, 2, 3}));
  EXPECT_EQ(sim.NeighboursWithin(3, 2.0), BruteForceWithin(sim, 3, 2.0));
}

TEST(NeighbourStage, CostsNothingAndListsNothingWhenNoTermAsks) {
  Simulation sim(Walkers(ModelParameters{}));
  sim.AdvanceTo(0.05);
  EXPECT_EQ(sim.profile().seconds(Stage::kNeighbours), 0.0);
  EXPECT_THROW(sim.NeighboursWithin(0, 1.0), InputError);
  // Asking changes no result (the stage only lists).
  Simulation asked(Walkers(ModelParameters{}));
  asked.RequestNeighbours(2.0);
  asked.AdvanceTo(0.05);
  EXPECT_GT(asked.profile().seconds(Stage::kNeighbours), 0.0);
  const std::size_t bytes = sim.bodies().size() * sizeof(Vec2);
  EXPECT_EQ(std::memcmp(sim.bodies().position_m.data(), asked.bodies().position_m.data(), bytes), 0);
  EXPECT_THROW(asked.NeighboursWithin(0, 2.5), InputError);  // beyond the radius asked for
  EXPECT_THROW(asked.RequestNeighbours(-1.0), InputError);
  asked.RequestNeighbours(0.0);
  EXPECT_THROW(asked.NeighboursWithin(0, 1.0), InputError);
}

}  // namespace
}  // namespace crowdrecon::engine
