// The thread governor (engine/thread_governor.hpp): its decisions on given
// step times, and that changing the thread count between steps changes no
// result.
#include <gtest/gtest.h>

#include <cstring>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/thread_governor.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::engine {
namespace {

using testing::RandomGas;

// Feeds `choice` steps whose duration depends on the thread count, one every
// `step_s` of wall time plus the step itself; returns the wall time reached.
template <typename Duration>
double Drive(ThreadChoice& choice, int steps, double now_s, Duration duration) {
  for (int k = 0; k < steps; ++k) {
    const double d = duration(choice.threads());
    now_s += d;
    choice.Record(d, now_s);
  }
  return now_s;
}

ThreadChoice::Options TwoThreads() {
  ThreadChoice::Options o;
  o.max_threads = 2;
  return o;
}

TEST(ThreadGovernor, IdleMachineKeepsTwoThreads) {
  ThreadChoice choice(TwoThreads());
  // Two threads twice as fast as one (1 ms against 2 ms a step), for 30 s.
  Drive(choice, 30000, 0.0, [](int t) { return t == 2 ? 1e-3 : 2e-3; });
  EXPECT_EQ(choice.threads(), 2);
  EXPECT_EQ(choice.summary().switches, 0u);
  // Probes back off: 0.25, 0.5, 1, ... s apart, so few in 30 s, and the steps
  // spent at one thread are a tiny share.
  EXPECT_LE(choice.summary().probes, 7u);
  EXPECT_LT(static_cast<double>(choice.summary().steps_at[1]), 0.01 * 30000);
}

TEST(ThreadGovernor, BusyCoreMovesToOneThreadAndCostsLittle) {
  ThreadChoice choice(TwoThreads());
  // With one core busy, two threads wait on the busy core at every barrier:
  // 14 times the one-thread step (2 ms).
  const auto busy = [](int t) { return t == 2 ? 28e-3 : 2e-3; };
  double wall = Drive(choice, 200, 0.0, busy);
  EXPECT_EQ(choice.threads(), 1);
  EXPECT_EQ(choice.summary().switches, 1u);
  // Over a minute at one thread, the probes back to two cost under 5 %
  // against one thread throughout.
  const double start = wall;
  const int steps = 30000;
  wall = Drive(choice, steps, wall, busy);
  EXPECT_EQ(choice.threads(), 1);
  EXPECT_LT((wall - start) / (steps * 2e-3), 1.05);
}

TEST(ThreadGovernor, StallsThatAMedianWouldHideAreCounted) {
  ThreadChoice choice(TwoThreads());
  // What a busy core does: most two-thread steps are fast (0.5 ms), but every
  // eighth waits a scheduler slice for the thread on the busy core (6 ms);
  // one thread is steady at 0.9 ms. The median step says two threads (0.5
  // against 0.9 ms), the mean says one (1.19 against 0.9 ms): one is right.
  int step = 0;
  Drive(choice, 20000, 0.0, [&](int t) {
    ++step;
    return t == 1 ? 0.9e-3 : step % 8 == 0 ? 6e-3 : 0.5e-3;
  });
  EXPECT_EQ(choice.threads(), 1);
  EXPECT_GE(choice.summary().switches, 1u);
}

TEST(ThreadGovernor, ReturnsToTwoThreadsWhenTheMachineIsIdleAgain) {
  ThreadChoice choice(TwoThreads());
  double wall = Drive(choice, 200, 0.0, [](int t) { return t == 2 ? 28e-3 : 2e-3; });
  ASSERT_EQ(choice.threads(), 1);
  // The other program ends: within a few probe intervals two threads are back.
  wall = Drive(choice, 20000, wall, [](int t) { return t == 2 ? 1e-3 : 2e-3; });
  EXPECT_EQ(choice.threads(), 2);
  EXPECT_EQ(choice.summary().switches, 2u);
}

TEST(ThreadGovernor, ASmallGainIsNotWorthASwitch) {
  ThreadChoice choice(TwoThreads());
  // One thread 5 % faster (below the 10 % margin): stay, and never flap.
  Drive(choice, 20000, 0.0, [](int t) { return t == 2 ? 1.0e-3 : 0.95e-3; });
  EXPECT_EQ(choice.threads(), 2);
  EXPECT_EQ(choice.summary().switches, 0u);
}

TEST(ThreadGovernor, OneThreadAskedIsNeverProbed) {
  ThreadChoice::Options o;
  o.max_threads = 1;
  ThreadChoice choice(o);
  Drive(choice, 5000, 0.0, [](int) { return 1e-3; });
  EXPECT_EQ(choice.threads(), 1);
  EXPECT_EQ(choice.summary().probes, 0u);
}

TEST(ThreadGovernor, ManyCoresTryHalvesAndComeBackUp) {
  ThreadChoice::Options o;
  o.max_threads = 8;
  ThreadChoice choice(o);
  // Best at 4 (8 waits on busy cores; 2 and 1 have too little parallelism).
  const auto time = [](int t) { return t == 8 ? 4e-3 : t == 4 ? 1e-3 : t == 2 ? 1.8e-3 : 3.5e-3; };
  Drive(choice, 40000, 0.0, time);
  EXPECT_EQ(choice.threads(), 4);
  EXPECT_GE(choice.summary().steps_at[4], 30000u);
}

TEST(ThreadGovernor, InvalidOptionsAreRefused) {
  ThreadChoice::Options o;
  o.max_threads = 0;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("max_threads = 0"), std::string::npos);
  EXPECT_THROW(ThreadChoice{o}, InputError);
  o.max_threads = 2;
  o.switch_ratio = 1.5;
  EXPECT_FALSE(o.IsValid(&error));
}

TEST(ThreadGovernor, ChangingTheThreadCountBetweenStepsChangesNothing) {
  // A crowd large enough (>= 512) for every stage to split its work: the same
  // positions and velocities, bit for bit, with one thread throughout and
  // with the count changed every few steps (1, 2, 3, ...).
  WorldDef def = RandomGas(26, 0.38, 7, true);
  def.parameters.ground_reaction = true;
  def.threads = 1;
  Simulation fixed(def);
  Simulation varied(def);
  for (int k = 0; k < 60; ++k) {
    fixed.Step();
    varied.SetThreads(1 + (k / 5) % 3);
    varied.Step();
  }
  const auto& a = fixed.bodies();
  const auto& b = varied.bodies();
  ASSERT_GE(a.size(), 512u);
  EXPECT_EQ(std::memcmp(a.position_m.data(), b.position_m.data(), a.size() * sizeof(Vec2)), 0);
  EXPECT_EQ(std::memcmp(a.velocity_m_per_s.data(), b.velocity_m_per_s.data(), a.size() * sizeof(Vec2)), 0);
  EXPECT_EQ(std::memcmp(a.angle_rad.data(), b.angle_rad.data(), a.size() * sizeof(double)), 0);
  EXPECT_THROW(varied.SetThreads(0), InputError);
}

}  // namespace
}  // namespace crowdrecon::engine
