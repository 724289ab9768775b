// Tests of the run analysis (analysis/): the regime classifier on hand-made
// mean-speed series of each regime, the lane order parameter on hand-made
// configurations, line crossings across a periodic seam, and the whole
// analysis of a small run file written from an engine world.
#include <sqlite3.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "crowdrecon/analysis/metrics.hpp"
#include "crowdrecon/analysis/regime.hpp"
#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/scenario/run_record.hpp"
#include "engine_scenes.hpp"
#include "render_scene.hpp"
#include "series_helpers.hpp"
#include "test_util.hpp"

namespace crowdrecon::analysis {

// Regimes by name in failure messages (found by argument-dependent lookup).
void PrintTo(Regime regime, std::ostream* os) { *os << ToString(regime); }

namespace {

using testing_util::ErrorOf;

using test_series::Series;
using test_series::Times;

// --- regime classifier on synthetic series -----------------------------------

TEST(Regime, SteadyFreeFlowIsLanes) {
  const std::vector<double> t = Times(60.0);
  // Start from rest, relax to 0.8 m/s with tau = 2/3 s, small ripple.
  const auto v = Series(t, [](double x) { return 0.8 * (1.0 - std::exp(-x / (2.0 / 3.0))) + 0.03 * std::sin(3.0 * x); });
  const auto lanes = Series(t, [](double) { return 0.9; });
  const RegimeResult r = ClassifyRegime(t, v, lanes, RegimeOptions{});
  EXPECT_EQ(r.regime, Regime::kLanes) << r.reason;
  EXPECT_TRUE(r.avalanches.empty());  // the start from rest is not a stop
  EXPECT_DOUBLE_EQ(r.stopped_time_fraction, 0.0);
  EXPECT_FALSE(r.frozen_at_end);
  EXPECT_NEAR(r.mean_lane_order, 0.9, 1e-12);
  EXPECT_NE(r.reason.find("free flow"), std::string::npos) << r.reason;
}

TEST(Regime, RepeatedStopAndBurstIsAvalanchesWithCountAndDurations) {
  const std::vector<double> t = Times(60.0);
  // Moving until 12 s, then every 8 s: 4 s stopped (0.02 m/s), 2 s burst
  // (0.8 m/s), 2 s stopped; the last cycle starts at 52 s.
  const auto v = Series(t, [](double x) {
    if (x < 12.0 - 1e-9) return 0.6;
    const double phase = std::fmod(x - 12.0 + 1e-9, 8.0);
    return phase >= 4.0 && phase < 6.0 ? 0.8 : 0.02;
  });
  const RegimeResult r = ClassifyRegime(t, v, {}, RegimeOptions{});
  EXPECT_EQ(r.regime, Regime::kAvalanches) << r.reason;
  // Bursts at 16, 24, 32, 40, 48, 56 s.
  ASSERT_EQ(r.avalanches.size(), 6u);
  EXPECT_EQ(r.stationary_avalanches, 6);
  for (std::size_t i = 0; i < r.avalanches.size(); ++i) {
    const Avalanche& a = r.avalanches[i];
    EXPECT_NEAR(a.start_time_s, 16.0 + 8.0 * static_cast<double>(i), 1e-9);
    EXPECT_NEAR(a.duration_s, 2.0, 1e-9);
    EXPECT_NEAR(a.peak_speed_m_per_s, 0.8, 1e-12);
    EXPECT_TRUE(a.complete);
    EXPECT_TRUE(a.stationary);
    // The first stop lasts 4 s; later ones 2 + 4 s (the tail of the previous cycle).
    EXPECT_NEAR(a.stopped_before_s, i == 0 ? 4.0 : 6.0, 1e-9);
    // Trapezoid: 1.9 s at 0.8 m/s, then the last interval down to 0.02 m/s.
    EXPECT_NEAR(a.distance_m, 0.8 * 1.9 + 0.5 * (0.8 + 0.02) * 0.1, 1e-9);
  }
  EXPECT_FALSE(r.frozen_at_end);
  // Stationary samples 10.0 .. 60.0 s (501): 2 s moving, then 6 of every 8 s
  // stopped (360 samples), and the last sample (a stop).
  EXPECT_NEAR(r.stopped_time_fraction, 361.0 / 501.0, 1e-12);
}

TEST(Regime, DecayToZeroIsClogging) {
  const std::vector<double> t = Times(60.0);
  const auto v = Series(t, [](double x) { return 0.8 * std::exp(-x / 8.0); });
  const RegimeResult r = ClassifyRegime(t, v, {}, RegimeOptions{});
  EXPECT_EQ(r.regime, Regime::kClogging) << r.reason;
  EXPECT_TRUE(r.frozen_at_end);
  EXPECT_LT(r.end_mean_speed_m_per_s, 0.05);
  EXPECT_TRUE(r.avalanches.empty());
  EXPECT_TRUE(std::isnan(r.mean_lane_order));  // no lane order given
}

TEST(Regime, FrozenAfterAvalanchesIsClogging) {
  // Two avalanches, then frozen for good: the end decides (Madrid Arena: five
  // avalanches, then the fatal clog).
  const std::vector<double> t = Times(60.0);
  const auto v = Series(t, [](double x) {
    if (x < 5.0) return 0.7;
    if (x < 10.0) return 0.0;
    if (x < 12.0) return 0.9;
    if (x < 17.0) return 0.0;
    if (x < 19.0) return 0.9;
    return 0.01;
  });
  const RegimeResult r = ClassifyRegime(t, v, {}, RegimeOptions{});
  EXPECT_EQ(r.regime, Regime::kClogging) << r.reason;
  EXPECT_EQ(r.avalanches.size(), 2u);
}

TEST(Regime, ShortDipsAndCreepingAreNotAvalanches) {
  const std::vector<double> t = Times(60.0);
  const auto v = Series(t, [](double x) {
    // 1.5 s dips below the stop speed (shorter than a stop), then bursts.
    if (std::fmod(x + 1e-9, 10.0) < 1.5) return 0.05;
    return 0.7;
  });
  RegimeResult r = ClassifyRegime(t, v, {}, RegimeOptions{});
  EXPECT_TRUE(r.avalanches.empty());
  EXPECT_EQ(r.regime, Regime::kUnclassified) << r.reason;  // stopped 15 % of the time
  // A stop released by creeping (0.2 m/s, below the burst speed) is no avalanche.
  const auto creep = Series(t, [](double x) {
    if (x < 5.0) return 0.7;
    if (std::fmod(x + 1e-9, 10.0) < 5.0) return 0.02;
    return 0.2;
  });
  r = ClassifyRegime(t, creep, {}, RegimeOptions{});
  EXPECT_TRUE(r.avalanches.empty());
  EXPECT_FALSE(r.frozen_at_end);
}

TEST(Regime, InitialRestThenJamIsNotAnAvalanche) {
  // At rest from the first frame for 5 s, then moving: the placed crowd
  // starting, not a release.
  const std::vector<double> t = Times(30.0);
  const auto v = Series(t, [](double x) { return x < 5.0 ? 0.0 : 0.9; });
  const RegimeResult r = ClassifyRegime(t, v, {}, RegimeOptions{});
  EXPECT_TRUE(r.avalanches.empty());
  EXPECT_EQ(r.regime, Regime::kLanes) << r.reason;
}

// Issue 65: an incident's avalanches are stops of a flow. A crowd placed at
// rest that creeps, bunches up and sets off (the night demo's counter-flow
// at 3.8 s) is starting; a group with no one walking yet (NaN) is a gap,
// neither a stop nor a flow.
TEST(Regime, AnIncidentsAvalancheNeedsAFlowBeforeItsStop) {
  const std::vector<double> t = Times(20.0);
  const auto start_up = Series(t, [](double x) { return x < 1.0 ? 0.15 : (x < 4.0 ? 0.02 : 0.8); });
  EXPECT_EQ(FindAvalanches(t, start_up, RegimeOptions{}).size(), 1u);  // the diagrams' reading, unchanged
  EXPECT_TRUE(FindAvalanches(t, start_up, IncidentAvalancheOptions()).empty());
  // Groups that walk, meet, stall and pass within the start-up (the demo's
  // counter-flow: released at 3.8 s after a stop of 2.8 s): the transient.
  const auto meeting = Series(t, [](double x) { return x < 1.0 ? 0.5 : (x < 3.8 ? 0.02 : 0.8); });
  EXPECT_EQ(FindAvalanches(t, meeting, RegimeOptions{}).size(), 1u);
  EXPECT_TRUE(FindAvalanches(t, meeting, IncidentAvalancheOptions()).empty());
  const std::vector<double> t30 = Times(30.0);
  const auto flow_stop_go = Series(t30, [](double x) { return x < 12.0 ? 0.8 : (x < 16.0 ? 0.02 : 0.8); });
  EXPECT_EQ(FindAvalanches(t30, flow_stop_go, IncidentAvalancheOptions()).size(), 1u);
  // Nobody there for 3 s, then walkers who stop (after their own start-up)
  // and go: the gap is no stop, the later stop is.
  auto gap = Series(t30, [](double x) { return x < 16.0 ? 0.8 : (x < 20.0 ? 0.02 : 0.8); });
  for (std::size_t k = 0; k < t30.size(); ++k)
    if (t30[k] < 3.0) gap[k] = std::nan("");
  const std::vector<Avalanche> found = FindAvalanchesBetweenGaps(t30, gap, IncidentAvalancheOptions());
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NEAR(found[0].start_time_s, 20.0, 0.11);
  EXPECT_NEAR(t30[found[0].start_index], found[0].start_time_s, 1e-12);  // indices of the whole series
  auto empty_then_walkers = Series(t, [](double x) { return x < 2.0 ? 0.0 : 0.8; });
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] < 2.0) empty_then_walkers[k] = std::nan("");
  EXPECT_TRUE(FindAvalanchesBetweenGaps(t, empty_then_walkers, IncidentAvalancheOptions()).empty());
}

TEST(Regime, OneReleaseIsIntermittentAndShortRunsAreUnclassified) {
  const std::vector<double> t = Times(40.0);
  const auto v = Series(t, [](double x) { return x < 5.0 ? 0.7 : (x < 25.0 ? 0.0 : 0.8); });
  const RegimeResult r = ClassifyRegime(t, v, {}, RegimeOptions{});
  EXPECT_EQ(r.avalanches.size(), 1u);
  EXPECT_EQ(r.regime, Regime::kUnclassified) << r.reason;
  EXPECT_NE(r.reason.find("intermittent"), std::string::npos) << r.reason;

  const std::vector<double> short_t = Times(15.0);
  const RegimeResult s = ClassifyRegime(short_t, Series(short_t, [](double) { return 0.0; }), {}, RegimeOptions{});
  EXPECT_EQ(s.regime, Regime::kUnclassified);
  EXPECT_NE(s.reason.find("run too short"), std::string::npos) << s.reason;
}

// Issue 39, candidate (d): read as a single release, one clog of 5 s or more
// that releases to flow is the avalanche regime; a shorter one is not, and a
// clog that never releases is still clogging.
TEST(Regime, TheSingleReleaseReadingTakesOneLongClogThatReleases) {
  const std::vector<double> t = Times(40.0);
  const RegimeOptions single = SingleReleaseReading(RegimeOptions{});
  EXPECT_EQ(single.min_avalanches, 1);
  EXPECT_EQ(single.min_released_stop_s, 5.0);
  std::string error;
  EXPECT_TRUE(single.IsValid(&error)) << error;
  // Flow, a 6-s clog from 15 s, then flow again.
  const auto released = Series(t, [](double x) { return x >= 15.0 && x < 21.0 ? 0.0 : 0.8; });
  const RegimeResult recurring = ClassifyRegime(t, released, {}, RegimeOptions{});
  EXPECT_NE(recurring.regime, Regime::kAvalanches) << recurring.reason;
  const RegimeResult once = ClassifyRegime(t, released, {}, single);
  EXPECT_EQ(once.regime, Regime::kAvalanches) << once.reason;
  EXPECT_EQ(once.stationary_avalanches, 1);
  EXPECT_NE(once.reason.find("stop >= 5 s"), std::string::npos) << once.reason;
  // A 3-s clog is a stop, not a clog of this reading.
  const auto brief = Series(t, [](double x) { return x >= 15.0 && x < 18.0 ? 0.0 : 0.8; });
  const RegimeResult short_stop = ClassifyRegime(t, brief, {}, single);
  EXPECT_NE(short_stop.regime, Regime::kAvalanches) << short_stop.reason;
  EXPECT_EQ(short_stop.stationary_avalanches, 0);
  EXPECT_EQ(short_stop.avalanches.size(), 1u);  // still found, not counted
  // Released once, then frozen for good: clogging under either reading.
  const auto refrozen = Series(t, [](double x) { return x >= 15.0 && x < 21.0 ? 0.0 : (x < 26.0 ? 0.8 : 0.0); });
  EXPECT_EQ(ClassifyRegime(t, refrozen, {}, single).regime, Regime::kClogging);
  RegimeOptions bad = single;
  bad.min_released_stop_s = std::nan("");
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("min_released_stop_s"), std::string::npos) << error;
}

TEST(Regime, LaneOrderRequirement) {
  const std::vector<double> t = Times(30.0);
  const auto v = Series(t, [](double) { return 0.8; });
  const auto order = Series(t, [](double) { return 0.3; });
  RegimeOptions options;
  options.min_lane_order_for_lanes = 0.5;
  const RegimeResult r = ClassifyRegime(t, v, order, options);
  EXPECT_EQ(r.regime, Regime::kUnclassified);
  EXPECT_NE(r.reason.find("without lanes"), std::string::npos) << r.reason;
}

TEST(Regime, NamesAndOptions) {
  for (Regime g : {Regime::kLanes, Regime::kAvalanches, Regime::kClogging, Regime::kUnclassified}) {
    Regime back = Regime::kUnclassified;
    ASSERT_TRUE(FromString(ToString(g), &back));
    EXPECT_EQ(back, g);
  }
  Regime dummy;
  EXPECT_FALSE(FromString("jammed", &dummy));
  RegimeOptions o;
  std::string error;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  o.burst_speed_m_per_s = 0.05;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("burst_speed_m_per_s (0.05 m/s) must exceed stop_speed_m_per_s"), std::string::npos) << error;
  o = RegimeOptions{};
  o.min_avalanches = 0;
  EXPECT_FALSE(o.IsValid(&error));
  const std::vector<double> t = Times(1.0);
  EXPECT_NE(ErrorOf([&] { ClassifyRegime(t, {0.0}, {}, RegimeOptions{}); }).find("differ in length"), std::string::npos);
}

// --- lane order ------------------------------------------------------------------

PeriodicBox Hallway() {
  PeriodicBox box;
  box.x = true;
  box.min_m = {0.0, 0.0};
  box.max_m = {12.0, 3.0};
  return box;
}

TEST(LaneOrder, SeparatedLanesGiveOne) {
  // Five lanes 0.6 m apart (wider than the band), alternating groups, people
  // every 0.4 m along the whole periodic corridor (bands wrap across the seam).
  std::vector<Vec2> position;
  std::vector<std::uint32_t> group;
  for (int lane = 0; lane < 5; ++lane)
    for (int k = 0; k < 30; ++k) {
      position.push_back({0.2 + 0.4 * k, 0.3 + 0.6 * lane});
      group.push_back(static_cast<std::uint32_t>(lane % 2));
    }
  std::vector<double> per_person;
  const LaneOrderResult r = LaneOrder(position, group, {1.0, 0.0}, LaneOrderOptions{}, Hallway(), &per_person);
  EXPECT_DOUBLE_EQ(r.order, 1.0);
  EXPECT_EQ(r.people_counted, position.size());
  for (double phi : per_person) EXPECT_DOUBLE_EQ(phi, 1.0);
}

TEST(LaneOrder, AlternatingAlongTheLaneGivesZero) {
  // One lane, groups alternating every 0.45 m: within +-2 m there are two of
  // each group on either side, so n_same = n_other and phi_j = 0.
  std::vector<Vec2> position;
  std::vector<std::uint32_t> group;
  PeriodicBox box = Hallway();
  box.max_m.x = 0.45 * 26;  // a whole number of pairs around the seam
  for (int k = 0; k < 26; ++k) {
    position.push_back({0.45 * k, 1.5});
    group.push_back(static_cast<std::uint32_t>(k % 2));
  }
  const LaneOrderResult r = LaneOrder(position, group, {-1.0, 0.0}, LaneOrderOptions{}, box);
  EXPECT_NEAR(r.order, 0.0, 1e-12);
}

TEST(LaneOrder, RandomMixingGivesTheBinomialExpectation) {
  // Uniform random positions and groups: E[phi_j] = (2p - 1)^2 + 4 p (1 - p) / n
  // with n ~ density x band area neighbours (docs/analysis.md).
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ux(0.0, 12.0), uy(0.0, 3.0), u01(0.0, 1.0);
  const int people = 3000;
  const LaneOrderOptions options;
  const double neighbours = (people - 1) / 36.0 * (2.0 * options.band_half_width_m) * (2.0 * options.band_half_length_m);
  for (double p : {0.5, 0.8}) {
    std::vector<Vec2> position;
    std::vector<std::uint32_t> group;
    for (int i = 0; i < people; ++i) {
      position.push_back({ux(rng), uy(rng)});
      group.push_back(u01(rng) < p ? 0u : 1u);
    }
    // The realised share of group 0, not the nominal p, sets the expectation.
    double share = 0.0;
    for (std::uint32_t g : group) share += g == 0 ? 1.0 : 0.0;
    share /= people;
    const double expected = (2.0 * share - 1.0) * (2.0 * share - 1.0) + 4.0 * share * (1.0 - share) / neighbours;
    const LaneOrderResult r = LaneOrder(position, group, {1.0, 0.0}, options, Hallway());
    EXPECT_NEAR(r.order, expected, 0.02) << "p = " << p;
  }
}

TEST(LaneOrder, NobodyInTheBandIsNaN) {
  const LaneOrderResult r = LaneOrder({{1.0, 0.5}, {1.0, 2.5}}, {0, 1}, {1.0, 0.0}, LaneOrderOptions{}, Hallway());
  EXPECT_TRUE(std::isnan(r.order));
  EXPECT_EQ(r.people_counted, 0u);
}

// --- crossings ----------------------------------------------------------------------

TEST(Crossing, DirectionAndPeriodicSeam) {
  const PeriodicBox box = Hallway();
  const MeasurementLine middle{{6.0, 0.0}, {6.0, 3.0}};
  const Vec2 forward{1.0, 0.0};
  EXPECT_EQ(CrossingDirection(middle, forward, {5.9, 1.0}, {6.1, 1.0}, box), 1);
  EXPECT_EQ(CrossingDirection(middle, forward, {6.1, 1.0}, {5.9, 1.0}, box), -1);
  EXPECT_EQ(CrossingDirection(middle, forward, {5.0, 1.0}, {5.9, 1.0}, box), 0);
  // Across the seam (11.9 -> 0.1): not a crossing of the middle line, although
  // the naive difference (-11.8 m) passes x = 6.
  EXPECT_EQ(CrossingDirection(middle, forward, {11.9, 1.0}, {0.1, 1.0}, box), 0);
  EXPECT_EQ(CrossingDirection(middle, forward, {0.1, 1.0}, {11.9, 1.0}, box), 0);
  // A line on the seam is crossed through its periodic image.
  const MeasurementLine seam{{0.0, 0.0}, {0.0, 3.0}};
  EXPECT_EQ(CrossingDirection(seam, forward, {11.9, 1.0}, {0.1, 1.0}, box), 1);
  EXPECT_EQ(CrossingDirection(seam, forward, {0.1, 1.0}, {11.9, 1.0}, box), -1);
  // Ending on the line counts, leaving it forward does not count again.
  EXPECT_EQ(CrossingDirection(middle, forward, {5.9, 1.0}, {6.0, 1.0}, box), 1);
  EXPECT_EQ(CrossingDirection(middle, forward, {6.0, 1.0}, {6.1, 1.0}, box), 0);
  // Beside the segment: no crossing.
  const MeasurementLine half{{6.0, 0.0}, {6.0, 1.0}};
  EXPECT_EQ(CrossingDirection(half, forward, {5.9, 2.0}, {6.1, 2.0}, box), 0);
  // The forward side follows `forward`, whichever way the segment is drawn.
  const MeasurementLine reversed{{6.0, 3.0}, {6.0, 0.0}};
  EXPECT_EQ(CrossingDirection(reversed, forward, {5.9, 1.0}, {6.1, 1.0}, box), 1);
}

// --- a run file written from an engine world ------------------------------------------

// Three passive people (no self-driven force, no contacts: constant velocity)
// in the periodic 12 m x 3 m hallway, 10 s at 10 frames per second:
//   1: x 11.0 -> 26.0 (unwrapped) at +1.5 m/s, group 0: crosses x = 18 (line
//      x = 6) once, the seam twice;
//   2: x  1.0 -> -7.0 at -0.8 m/s, group 1: crosses x = -6 once, the seam once;
//   3: x  5.5 -> 15.5 at +1.0 m/s, group 0: crosses x = 6 once, the seam once.
std::filesystem::path WriteWalkersRun(const std::string& name) {
  using engine::PersonDef;
  engine::WorldDef def = engine::testing::PassiveWorld();
  def.targets.push_back(geometry::NavigationField::Constant({-1.0, 0.0}));
  def.shapes.push_back(engine::testing::ThoraxLikeShape());
  const struct {
    double x, y, vx;
    std::uint32_t group;
  } walkers[] = {{11.0, 0.5, 1.5, 0}, {1.0, 1.5, -0.8, 1}, {5.5, 2.5, 1.0, 0}};
  for (const auto& w : walkers) {
    PersonDef p;
    p.shape = 0;
    engine::testing::SetMassFromShape(def.shapes[0], 1000.0, p);
    p.position_m = {w.x, w.y};
    p.velocity_m_per_s = {w.vx, 0.0};
    p.group = p.target = w.group;
    p.angle_rad = w.vx > 0 ? 0.0 : std::numbers::pi;
    def.people.push_back(p);
  }
  def.periodic.x = true;
  def.periodic.min_m = {0.0, 0.0};
  def.periodic.max_m = {12.0, 3.0};
  engine::Simulation sim(def);
  const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) / name;
  runfile::RunHeader header;
  header.scenario_json = "{\"test\": \"three walkers\"}";
  header.scenario_origin = "tests/unit/test_analysis.cpp";
  header.walkable_wkt = engine::testing::RectangleWkt(12.0, 3.0);
  header.output_fps = 10.0;
  header.time_step_s = sim.time_step_s();
  runfile::RunFileWriter writer = scenario::CreateRunFile(file, header, sim, {"to_exit", "to_court"});
  for (int k = 0; k <= 100; ++k) {
    if (k > 0) sim.AdvanceTo(k / 10.0);
    scenario::WriteFrame(writer, sim, k, {}, /*with_contacts=*/false);
  }
  writer.SetStatus("complete");
  return file;
}

TEST(AnalyzeRun, FlowAcrossThePeriodicSeam) {
  const std::filesystem::path file = WriteWalkersRun("analysis-walkers.sqlite");
  AnalysisOptions options;
  options.regime.transient_s = 0.0;
  const RunAnalysis a = AnalyzeRun(file, options);
  EXPECT_EQ(a.people, 3u);
  EXPECT_EQ(a.frames, 101u);
  EXPECT_NEAR(a.duration_s, 10.0, 1e-3);
  // No venue: directions from the groups' mean velocities, signs along x.
  EXPECT_NE(a.direction_source.find("group mean velocity"), std::string::npos) << a.direction_source;
  EXPECT_EQ(a.group_direction[0], (Vec2{1.0, 0.0}));
  EXPECT_EQ(a.group_direction[1], (Vec2{-1.0, 0.0}));
  // Default line: across the middle of the walkable area, x = 6.
  EXPECT_NEAR(a.line.a_m.x, 6.0, 1e-12);
  EXPECT_NEAR(a.line.length_m(), 3.0, 1e-12);
  EXPECT_EQ(a.forward, (Vec2{1.0, 0.0}));
  EXPECT_EQ(a.crossings_forward, 2);
  EXPECT_EQ(a.crossings_backward, 1);
  EXPECT_NEAR(a.flow_forward_per_m_s, 2.0 / (10.0 * 3.0), 1e-4);
  EXPECT_NEAR(a.flow_backward_per_m_s, 1.0 / (10.0 * 3.0), 1e-4);
  // Constant velocities: mean speed along the desired direction exactly.
  EXPECT_NEAR(a.mean_speed_m_per_s, (1.5 + 0.8 + 1.0) / 3.0, 1e-9);
  EXPECT_NEAR(a.group_mean_speed_m_per_s[0], 1.25, 1e-9);
  EXPECT_NEAR(a.group_mean_speed_m_per_s[1], 0.8, 1e-9);
  EXPECT_DOUBLE_EQ(a.mean_stopped_fraction, 0.0);
  EXPECT_DOUBLE_EQ(a.max_load_n, 0.0);
  EXPECT_TRUE(std::isnan(a.mean_lane_order));  // lanes 1 m apart: nobody in anyone's band
  // Flow series: trailing 2 s window; frame 0 has none.
  EXPECT_TRUE(std::isnan(a.series.flow_forward_per_m_s[0]));
  double forward_integral = 0.0;
  for (std::size_t k = 20; k < a.frames; k += 20) forward_integral += a.series.flow_forward_per_m_s[k] * 2.0 * 3.0;
  EXPECT_NEAR(forward_integral, 2.0, 1e-3);  // disjoint windows add up to the crossings
  // With no transient, 10 s of steady walking fill the final window: free flow.
  EXPECT_EQ(a.regime.regime, Regime::kLanes) << a.regime.reason;

  // A line on the seam counts the wraps instead.
  options.line = MeasurementLine{{0.0, 0.0}, {0.0, 3.0}};
  const RunAnalysis seam = AnalyzeRun(file, options);
  EXPECT_EQ(seam.line_source, "given");
  EXPECT_EQ(seam.crossings_forward, 3);
  EXPECT_EQ(seam.crossings_backward, 1);
}

TEST(AnalyzeRun, WritesTablesIntoTheRunFile) {
  const std::filesystem::path file = WriteWalkersRun("analysis-walkers-write.sqlite");
  const AnalysisOptions options;
  const RunAnalysis a = AnalyzeRun(file, options);
  WriteAnalysis(file, a, options);
  WriteAnalysis(file, a, options);  // a second analysis replaces the first
  const runfile::RunFileReader run(file);
  EXPECT_EQ(run.RunValue("regime"), "unclassified");
  EXPECT_NE(run.RunValue("regime_reason").find("run too short"), std::string::npos);
  EXPECT_NE(run.RunValue("analysis_options").find("\"frozen_window_s\":10.0"), std::string::npos);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  auto count = [&](const char* sql) {
    sqlite3_stmt* stmt = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db, sql, -1, &stmt, nullptr), SQLITE_OK) << sql;
    std::int64_t n = -1;
    if (sqlite3_step(stmt) == SQLITE_ROW) n = sqlite3_column_int64(stmt, 0);
    sqlite3_finalize(stmt);
    return n;
  };
  const std::int64_t columns = static_cast<std::int64_t>(a.series.Columns().size());
  EXPECT_EQ(count("SELECT COUNT(*) FROM metric_series"), columns * 101);
  EXPECT_EQ(count("SELECT COUNT(*) FROM metric_summary"), static_cast<std::int64_t>(a.SummaryTable().size()));
  EXPECT_EQ(count("SELECT value FROM metric_summary WHERE name = 'crossings_forward'"), 2);
  EXPECT_EQ(count("SELECT COUNT(*) FROM metric_load_histogram"), 21);
  sqlite3_close(db);
  // Issue 65: a run continued after its analysis was stored drops it (a
  // resumed run kept the analysis of its first half).
  { runfile::RunFileWriter::Resume(file, 50); }
  const runfile::RunFileReader resumed(file);
  EXPECT_EQ(resumed.RunValue("regime"), "");
  EXPECT_EQ(resumed.RunValue("analysis_options"), "");
  EXPECT_EQ(resumed.RunValue("derived_keys"), "");
  ASSERT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  EXPECT_EQ(count("SELECT COUNT(*) FROM sqlite_master WHERE name LIKE 'metric%'"), 0);
  sqlite3_close(db);
}

// A run file whose frames are written by hand (header from RunFileWriter):
// two people walking in opposite directions with the stop-and-go speed of
// RepeatedStopAndBurstIsAvalanchesWithCountAndDurations, and person 1 loaded
// with 500 N from 20.0 to 22.9 s.
TEST(AnalyzeRun, StopAndGoRunFile) {
  const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) / "analysis-stop-and-go.sqlite";
  {
    engine::WorldDef def = engine::testing::PassiveWorld();
    def.targets.push_back(geometry::NavigationField::Constant({-1.0, 0.0}));
    def.shapes.push_back(engine::testing::ThoraxLikeShape());
    for (std::uint32_t g = 0; g < 2; ++g) {
      engine::PersonDef p;
      engine::testing::SetMassFromShape(def.shapes[0], 1000.0, p);
      p.position_m = {6.0, 1.0 + g};
      p.group = p.target = g;
      def.people.push_back(p);
    }
    def.periodic.x = true;
    def.periodic.max_m = {12.0, 3.0};
    engine::Simulation sim(def);
    runfile::RunHeader header;
    header.scenario_json = "{}";
    header.walkable_wkt = engine::testing::RectangleWkt(12.0, 3.0);
      runfile::RunFileWriter writer = scenario::CreateRunFile(file, header, sim, {"to_exit", "to_court"});
    writer.SetStatus("complete");
  }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  auto exec = [&](const std::string& sql) { ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sql; };
  exec("BEGIN");
  double x[2] = {6.0, 6.0};
  for (int k = 0; k <= 600; ++k) {
    const double t = k / 10.0;
    const double phase = std::fmod(t - 12.0 + 1e-9, 8.0);
    const double v = t < 12.0 - 1e-9 ? 0.6 : (phase >= 4.0 && phase < 6.0 ? 0.8 : 0.02);
    exec("INSERT INTO frame_time VALUES(" + std::to_string(k) + ", " + std::to_string(t) + ")");
    for (int i = 0; i < 2; ++i) {
      const double vx = i == 0 ? v : -v;
      if (k > 0) x[i] = std::fmod(x[i] + vx * 0.1 + 12.0, 12.0);
      const double load_n = i == 0 && t >= 20.0 - 1e-9 && t < 23.0 - 1e-9 ? 500.0 : 10.0;
      const std::string id = std::to_string(i + 1), frame = std::to_string(k);
      exec("INSERT INTO trajectory_data VALUES(" + frame + ", " + id + ", " + std::to_string(x[i]) + ", " +
           std::to_string(1.0 + i) + ", 1, 0)");
      exec("INSERT INTO person_state VALUES(" + frame + ", " + id + ", " + std::to_string(vx) + ", 0, 0, 0, 0, " +
           std::to_string(load_n) + ")");
      // The chest load the analysis reads (table person_load): the same load
      // across the chest; person_state.load_n gets twice it, which must not
      // be read where person_load exists.
      exec("INSERT INTO person_load VALUES(" + frame + ", " + id + ", " + std::to_string(load_n) + ", 0)");
      exec("UPDATE person_state SET load_n = " + std::to_string(2.0 * load_n) + " WHERE frame = " + frame +
           " AND id = " + id);
    }
  }
  exec("COMMIT");
  sqlite3_close(db);

  const RunAnalysis a = AnalyzeRun(file);
  EXPECT_TRUE(a.chest_loads);
  EXPECT_EQ(a.regime.regime, Regime::kAvalanches) << a.regime.reason;
  ASSERT_EQ(a.regime.avalanches.size(), 6u);
  for (const Avalanche& av : a.regime.avalanches) {
    EXPECT_NEAR(av.duration_s, 2.0, 1e-6);
    EXPECT_EQ(av.people_moved, 2);  // each advanced ~1.6 m
  }
  EXPECT_NEAR(a.avalanche_mean_duration_s, 2.0, 1e-6);
  EXPECT_NEAR(a.avalanche_mean_people, 2.0, 1e-12);
  EXPECT_EQ(a.group_direction[1], (Vec2{-1.0, 0.0}));
  EXPECT_DOUBLE_EQ(a.max_load_n, 500.0);
  EXPECT_EQ(a.max_load_person, 1);
  EXPECT_NEAR(a.max_load_time_s, 20.0, 1e-6);
  EXPECT_EQ(a.people_ever_above_load, 1);
  EXPECT_NEAR(a.longest_above_load_s, 2.9, 1e-6);  // first to last frame above
  EXPECT_NEAR(a.max_above_load_fraction, 0.5, 1e-12);
  // Stationary person-frames (10.0 .. 60.0 s, 2 x 501): 30 above 400 N.
  EXPECT_NEAR(a.above_load_person_frames, 30.0 / 1002.0, 1e-12);
  EXPECT_EQ(a.load_histogram[0], 1002 - 30);
  EXPECT_EQ(a.load_histogram[10], 30);  // [500, 550)
  EXPECT_NEAR(a.load_p50_n, 10.0, 1e-12);
}

TEST(AnalyzeRun, Errors) {
  EXPECT_NE(ErrorOf([] { AnalyzeRun("no-such-run.sqlite"); }).find("no-such-run.sqlite: run file does not exist"),
            std::string::npos);
  AnalysisOptions bad;
  bad.flow_window_s = 0.0;
  EXPECT_NE(ErrorOf([&] { AnalyzeRun("x.sqlite", bad); }).find("analysis options: flow_window_s = 0 s"),
            std::string::npos);
  bad = AnalysisOptions{};
  bad.lanes.band_half_width_m = -1.0;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("band_half_width_m"), std::string::npos);
}

}  // namespace
}  // namespace crowdrecon::analysis

namespace crowdrecon::analysis {
namespace {

// A square lattice of disks (radius 0.12 m, area 0.0452 m^2) with spacing a
// in a periodic 6 m x 6 m box, written as a one-frame run with its contacts.
std::filesystem::path WriteLatticeRun(const std::string& name, double spacing_m) {
  engine::WorldDef def = engine::testing::PassiveWorld();
  def.shapes.push_back(engine::testing::DiskShape(0.12));
  const int per_side = static_cast<int>(std::lround(6.0 / spacing_m));
  for (int i = 0; i < per_side; ++i)
    for (int j = 0; j < per_side; ++j) {
      engine::PersonDef p;
      engine::testing::SetMassFromShape(def.shapes[0], 1000.0, p);
      p.position_m = {(i + 0.5) * spacing_m, (j + 0.5) * spacing_m};
      def.people.push_back(p);
    }
  def.periodic.x = def.periodic.y = true;
  def.periodic.max_m = {6.0, 6.0};
  engine::Simulation sim(def);
  const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) / name;
  runfile::RunHeader header;
  header.scenario_json = "{}";
  header.walkable_wkt = engine::testing::RectangleWkt(6.0, 6.0);
  header.periodic_box = def.periodic;
  header.output_fps = 10.0;
  header.time_step_s = sim.time_step_s();
  runfile::RunFileWriter writer = scenario::CreateRunFile(file, header, sim, {"to_exit"});
  scenario::WriteFrame(writer, sim, 0, {}, /*with_contacts=*/true);
  writer.SetStatus("complete");
  return file;
}

// Within a 1 m^2 disc (radius 0.564 m) a square lattice of spacing 0.3 m
// puts 9 centres (i^2 + j^2 <= 3.5), of spacing 0.2 m 21 (i^2 + j^2 <= 7.96),
// everyone alike across the periodic seams. The disks cover
// 9 x 0.0452 / 0.0868 = 4.7 and 21 x 0.0452 / 0.0868 = 10.9 real-size
// people's floor: within the range, and beyond any crowd measured.
TEST(Plausibility, PeakDensityOfALatticeAndWhatItMeans) {
  const double disk_area = std::numbers::pi * 0.12 * 0.12;
  const PlausibilityOptions options;
  const Plausibility loose = ComputePlausibility(WriteLatticeRun("plausibility-loose.sqlite", 0.3));
  EXPECT_DOUBLE_EQ(loose.peak_density_per_m2, 9.0);
  EXPECT_NEAR(loose.peak_equivalent_density_per_m2, 9.0 * disk_area / options.reference_body_area_m2, 1e-9);
  EXPECT_NEAR(loose.peak_mean_body_area_m2, disk_area, 1e-12);
  EXPECT_EQ(loose.verdict, PlausibilityVerdict::kWithin);
  EXPECT_EQ(loose.max_overlap_m, 0.0);
  EXPECT_NE(loose.Statement(options).find("within Fruin's critical density of a static crowd (7.1 /m2)"), std::string::npos)
      << loose.Statement(options);

  const Plausibility dense = ComputePlausibility(WriteLatticeRun("plausibility-dense.sqlite", 0.2));
  EXPECT_DOUBLE_EQ(dense.peak_density_per_m2, 21.0);
  EXPECT_EQ(dense.verdict, PlausibilityVerdict::kBeyondMeasured);
  EXPECT_TRUE(dense.contacts_available);
  EXPECT_NEAR(dense.max_overlap_m, 0.04, 1e-9);  // 2 x 0.12 - 0.2
  const std::string said = dense.Statement(options);
  EXPECT_NE(said.find("beyond any density measured in a human crowd"), std::string::npos) << said;
  EXPECT_NE(said.find("4.0 cm"), std::string::npos) << said;
}

}  // namespace
}  // namespace crowdrecon::analysis
