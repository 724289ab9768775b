// Chest load from a person's contact forces (issue 21; docs/reports.md,
// "Chest load"): analytic cases on hand-made contacts, and a jammed row of
// people driven against a wall by the engine, whose static loads are known.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/reports/chest_load.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::reports {
namespace {

constexpr double kDepth = 0.24, kWidth = 0.42;

Vec2 Dir(double angle) { return {std::cos(angle), std::sin(angle)}; }

// One person at `at` facing `angle`, squeezed between two walls whose contact
// points lie on the line through the centre along `axis` (unit), each wall
// pushing inward with `force`.
std::vector<ChestLoad> Squeezed(Vec2 at, double angle, Vec2 axis, double half_extent, double force) {
  const std::vector<Pose> poses{{at, angle, true}};
  const std::vector<LoadContact> contacts{
      {0, 0, true, at + axis * half_extent, axis * -force},
      {0, 1, true, at - axis * half_extent, axis * force},
  };
  return ChestLoads(poses, contacts, PeriodicBox{});
}

TEST(ChestLoad, SqueezedChestFacingReadsTheForceAcrossTheChest) {
  for (double angle : {0.0, 0.7, -2.5}) {
    const auto loads = Squeezed({3.0, -1.0}, angle, Dir(angle), kDepth / 2, 650.0);
    EXPECT_NEAR(loads[0].chest_n, 650.0, 1e-9) << angle;
    EXPECT_NEAR(loads[0].lateral_n, 0.0, 1e-9) << angle;
    EXPECT_NEAR(loads[0].load_n(), 650.0, 1e-9);
  }
}

TEST(ChestLoad, SqueezedSideOnReadsTheForceAcrossTheShoulders) {
  for (double angle : {0.0, 1.1}) {
    const auto loads = Squeezed({0.0, 0.0}, angle, Perp(Dir(angle)), kWidth / 2, 420.0);
    EXPECT_NEAR(loads[0].lateral_n, 420.0, 1e-9);
    EXPECT_NEAR(loads[0].chest_n, 0.0, 1e-9);
    EXPECT_NEAR(loads[0].load_n(), 420.0, 1e-9);
  }
}

TEST(ChestLoad, PushedFromOneSideWhileAcceleratingReadsNoLoad) {
  // One push on the back; nothing in front: the body accelerates. (The force
  // moment tensor would read half the push: compared below.)
  const std::vector<Pose> poses{{{0.0, 0.0}, 0.0, true}, {{-0.3, 0.0}, 0.0, true}};
  const std::vector<LoadContact> contacts{{0, 1, false, {-kDepth / 2, 0.0}, {800.0, 0.0}}};
  const auto loads = ChestLoads(poses, contacts, PeriodicBox{});
  EXPECT_EQ(loads[0].chest_n, 0.0);
  EXPECT_EQ(loads[1].chest_n, 0.0);  // the pusher, pushed back from its front only
  // A light touch in front as well (a neighbour 20 N): the load is that touch.
  std::vector<LoadContact> with_touch = contacts;
  with_touch.push_back({0, 0, true, {kDepth / 2, 0.0}, {-20.0, 0.0}});
  EXPECT_NEAR(ChestLoads(poses, with_touch, PeriodicBox{})[0].chest_n, 20.0, 1e-12);
  // The moment tensor of the one-sided push: -d.M.d / depth = F / 2.
  const std::vector<Vec2> branch{{-kDepth / 2, 0.0}}, force{{800.0, 0.0}};
  EXPECT_NEAR(-MomentOf(branch, force).Along({1.0, 0.0}) / kDepth, 400.0, 1e-9);
}

TEST(ChestLoad, ARingOfEqualRadialPushesReadsEqualLoadsBothWays) {
  for (int n : {4, 7, 12, 60}) {
    const double f = 100.0, r = 0.2;
    std::vector<LoadContact> contacts;
    for (int k = 0; k < n; ++k) {
      const Vec2 u = Dir(2.0 * std::numbers::pi * (k + 0.25) / n);
      contacts.push_back({0, static_cast<std::uint32_t>(k), true, u * r, u * -f});
    }
    for (double angle : {0.0, 0.3, 1.2}) {
      const std::vector<Pose> poses{{{0.0, 0.0}, angle, true}};
      const auto loads = ChestLoads(poses, contacts, PeriodicBox{});
      EXPECT_NEAR(loads[0].chest_n, loads[0].lateral_n, 0.12 * loads[0].chest_n) << n << " " << angle;
      // Each side carries the sum of |cos| of its pushes: n f / pi for many.
      if (n == 60) {
        EXPECT_NEAR(loads[0].chest_n, n * f / std::numbers::pi, 0.01 * n * f / std::numbers::pi);
      }
    }
  }
}

TEST(ChestLoad, APeriodicSeamTakesTheMinimumImageOfTheBranch) {
  PeriodicBox box;
  box.x = true;
  box.min_m = {0.0, 0.0};
  box.max_m = {10.0, 3.0};
  // Person at x = 9.95 squeezed by contacts recorded at 10.07 (= 0.07 after
  // wrapping, as the engine may record it) and 9.83.
  const std::vector<Pose> poses{{{9.95, 1.0}, 0.0, true}};
  const std::vector<LoadContact> contacts{{0, 0, true, {0.07, 1.0}, {-300.0, 0.0}},
                                          {0, 1, true, {9.83, 1.0}, {300.0, 0.0}}};
  EXPECT_NEAR(ChestLoads(poses, contacts, box)[0].chest_n, 300.0, 1e-9);
}

TEST(ChestLoad, AContactWithSomeoneAbsentIsRefused) {
  const std::vector<Pose> poses{{{0.0, 0.0}, 0.0, true}, {{1.0, 0.0}, 0.0, false}};
  const std::vector<LoadContact> contacts{{0, 1, false, {0.5, 0.0}, {-1.0, 0.0}}};
  EXPECT_THROW(ChestLoads(poses, contacts, PeriodicBox{}), InputError);
}

// A row of N thorax-like bodies driven along +x against a wall, at rest: person k
// (counted from the wall) is pressed between the drives of the N - 1 - k
// people behind it and the wall's reaction, so its chest load is
// (N - 1 - k) m v0 / tau (eq. 3 at rest; no back force at rest).
TEST(ChestLoad, AJammedRowPushedAtOneEndReadsTheForceTransmittedThroughIt) {
  using namespace engine;
  using namespace engine::testing;
  WorldDef def;
  def.parameters.back_force_gamma = 0.0;
  def.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
  def.shapes.push_back(ThoraxLikeShape());  // 0.34 m deep with its sphero-radius
  def.walls.push_back({{{0.0, -1.0}, {0.0, 1.0}}, false, 0.0});
  constexpr int kN = 6;
  for (int k = 0; k < kN; ++k) {
    PersonDef p;
    SetMassFromShape(def.shapes[0], 1000.0, p);
    p.position_m = {-0.17 - 0.35 * k, 0.0};
    p.desired_speed_m_per_s = 1.0;
    def.people.push_back(p);
  }
  Simulation sim(def);
  sim.AdvanceTo(25.0);
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < sim.bodies().size(); ++i)
    poses.push_back({sim.bodies().position_m[i], sim.bodies().angle_rad[i], true});
  std::vector<LoadContact> contacts;
  for (const Contact& c : sim.contacts()) contacts.push_back({c.a, c.b, c.wall, c.point_m, c.Force()});
  const auto loads = ChestLoads(poses, contacts, PeriodicBox{});
  const double drive = sim.bodies().mass_kg[0] * 1.0 / def.parameters.relaxation_time_s;
  for (int k = 0; k < kN; ++k) {
    EXPECT_NEAR(sim.bodies().velocity_m_per_s[k].x, 0.0, 1e-3);
    // Still facing the wall (the row turns by a few milliradians as it
    // jams; friction on the slightly slanted contacts gives a small side load).
    EXPECT_NEAR(sim.bodies().angle_rad[k], 0.0, 0.01);
    EXPECT_NEAR(loads[k].chest_n, (kN - 1 - k) * drive, 0.01 * drive) << "person " << k;
    EXPECT_LT(loads[k].lateral_n, 0.1 * drive) << "person " << k;
  }
}

}  // namespace
}  // namespace crowdrecon::reports
