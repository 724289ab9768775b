// Incident timelines over whole runs (issue 20 and after): the engine at a
// run's checkpoint, an arrival in an empty slot, a compressed run's clock,
// arrivals' ids, pre-movement times (RiMEA 5, NIST), a resumed run's wall
// time, the gait jitter's seed, and the areas' avalanches. (The schedules,
// inflow, exits, falls and bad timelines: test_timeline.cpp.)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/analysis/timeline_series.hpp"
#include "crowdrecon/common/distribution.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/scenario/runner.hpp"
#include "crowdrecon/scenario/scenario.hpp"
#include "crowdrecon/scenario/timeline.hpp"
#include "scratch.hpp"

#include "timeline_scenes.hpp"

namespace crowdrecon::scenario {
namespace timeline_tests {

// The engine at a run's checkpoint (for benchmarks on machines that cannot
// build worlds): the state is that of the uninterrupted run at that frame,
// and stepping it on gives the uninterrupted run's later frames exactly, so
// its world carries the run's time step.
TEST(Timeline, TheEngineAtACheckpointContinuesAsTheRunDoes) {
  const Scenario s = LoadScenario(kSource / "tests/data/scenarios/hallway-short.json");
  RunOptions whole, stopped;
  whole.output = crowdrecon::testing::ScratchFile("engine-at-checkpoint-whole.sqlite");
  stopped.output = crowdrecon::testing::ScratchFile("engine-at-checkpoint-stopped.sqlite");
  for (const RunOptions* o : {&whole, &stopped}) {
    std::filesystem::remove(o->output);
    std::filesystem::remove(CheckpointPath(o->output));
  }
  stopped.stop_after_s = 1.0;
  const RunSummary summary = RunScenario(s, whole);
  ASSERT_EQ(RunScenario(s, stopped).status, "interrupted");

  const EngineAtCheckpoint saved = ReadEngineAtCheckpoint(s, stopped.output, 2);
  EXPECT_NEAR(saved.time_s, 1.0, 1e-9);
  EXPECT_EQ(saved.world.parameters.time_step_s, summary.time_step_s);
  engine::Simulation sim(saved.world);
  sim.LoadState(saved.state);
  const runfile::RunFileReader reader(whole.output);
  std::vector<runfile::PersonFrame> frames;
  runfile::PersonFrame f;
  auto stream = reader.PersonFrames(20);
  while (stream.Next(&f)) frames.push_back(f);
  ASSERT_EQ(frames.size(), 21u);
  const auto expect_frame = [&](const runfile::PersonFrame& frame) {
    ASSERT_EQ(frame.person.size(), sim.bodies().size());
    for (std::size_t i = 0; i < frame.person.size(); ++i) {
      ASSERT_EQ(frame.position_m[i].x, sim.bodies().position_m[frame.person[i]].x) << "frame " << frame.frame;
      ASSERT_EQ(frame.position_m[i].y, sim.bodies().position_m[frame.person[i]].y) << "frame " << frame.frame;
    }
  };
  expect_frame(frames[10]);
  sim.AdvanceTo(2.0);
  expect_frame(frames[20]);

  // Another scenario's checkpoint is refused, naming the file.
  Scenario other = s;
  other.json_text += " ";
  try {
    ReadEngineAtCheckpoint(other, stopped.output, 1);
    ADD_FAILURE() << "another scenario's checkpoint was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("belongs to a different scenario"), std::string::npos) << e.what();
  }
}

// An arrival spawned into an engine slot that was empty (never used, or its
// person removed) is a newcomer, also when the slot's placeholder carries
// the arrival's own id (a slot's index is its placeholder's id; with nobody
// at the start and one inflow, every arrival's id is its slot's). The wall
// check and the exits compared slots by id alone: the uncompressed Itaewon
// evening stopped at 22:20, in both seeds, "person 7189 went through wall 5"
// on a path from the placeholders' parking place (-35, -4), the walkable
// area's lower corner, to the food street's west entry; and an arrival at
// the station's west entry, whose path from there crosses the exit
// station_west, would have been counted as leaving the moment it came.
TEST(Timeline, AnArrivalInAnEmptySlotIsANewcomerThoughItsIdIsThePlaceholders) {
  // Each walking away from the exits: from the food street down to the
  // station, from the station up to the food street.
  for (const auto& [entry, group] : {std::pair<std::string, std::string>{"from_food_street_west", "counter"},
                                     {"from_station_west", "main"}}) {
    const std::string json = Hallway(
        R"({"count": 0, "target": "to_food_street", "counter_target": "to_station",
            "body": {"mode": "paper", "reference": ")" + (kSource / "venues/bodies/thorax-18.json").string() + R"("},
            "desired_speed_m_per_s": [0.8, 1.2], "seed": 5})",
        R"({"duration_s": 2, "output_fps": 2, "checkpoint_interval_s": 0, "contacts": false})",
        R"({"inflows": [{"id": "in", "entry": ")" + entry + R"(", "group": ")" + group + R"(", "rate_per_s": 6}]})",
        "venues/itaewon/alley.json");
    TimelineRun run;
    try {
      run = Simulate(json, "empty-slot-" + entry);
    } catch (const InputError& e) {
      ADD_FAILURE() << entry << ": " << e.what();
      continue;
    }
    EXPECT_EQ(run.Value("status"), "complete") << entry;
    // 6 a second for 2 s.
    EXPECT_GE(run.Kind("enter").size(), 11u) << entry;
    EXPECT_TRUE(run.Kind("exit").empty()) << entry << ": " << run.Kind("exit").size() << " left at once";
    ExpectConservation(run);
    EXPECT_EQ(run.census.back().census.walking, static_cast<std::int64_t>(run.Kind("enter").size())) << entry;
  }
}

// A compressed scenario's clock (timeline.clock_scale): the figures, maps
// and scores give the incident's time, run time x scale after the start.
TEST(RunClock, ACompressedRunsClockGivesTheIncidentsTime) {
  const analysis::RunClock night{"21:45", 10.0};
  EXPECT_EQ(night.Text(0.0), "21:45");
  EXPECT_EQ(night.Text(180.0), "22:15");
  EXPECT_EQ(night.Text(269.9), "22:29:59");
  EXPECT_EQ(night.TickText(30.0, 30.0), "21:50") << "a tick of 30 run seconds spans 5 minutes of the night";
  // Issue 65: to the second where the time is not a whole minute (a tick at
  // 21:46:40 read "21:46").
  EXPECT_EQ(night.TickText(10.0, 10.0), "21:46:40");
  EXPECT_EQ(night.AxisLabel(), "time of night (run time 0 = 21:45; a second of the run stands for 10 s)");
  const analysis::RunClock plain{"02:00", 1.0};
  EXPECT_EQ(plain.Text(37 * 60.0 + 59.0), "02:37:59");
  EXPECT_EQ(plain.Text(50.0), "02:00:50") << "two maps 50 s apart were both titled 02:00";
  EXPECT_EQ(plain.Text(23 * 3600.0), "01:00") << "past midnight";
  EXPECT_EQ(plain.TickText(30.0, 30.0), "30 s");
  EXPECT_EQ(plain.AxisLabel(), "time of night (run time 0 = 02:00)");
  const analysis::RunClock none{"", 20.0};
  EXPECT_EQ(none.Text(285.0), "95 min");
  EXPECT_EQ(none.Text(1.0), "0 min 20 s");
  // A scale without a start (issue 65, F11): the axis is the incident's time, and so are the maps' titles.
  EXPECT_EQ(none.AxisLabel(), "time of the incident since the run's start (a second of the run stands for 20 s)");
  EXPECT_EQ(none.MomentText(15.0), "t = 15 s (5 min of the incident)");
  EXPECT_EQ((analysis::RunClock{"", 1.0}.AxisLabel()), "time of the run");
  EXPECT_EQ((analysis::RunClock{"", 1.0}.MomentText(15.04)), "t = 15 s");
  EXPECT_EQ(plain.MomentText(50.0), "02:00:50");
}

// The scale travels through the run file (run value timeline_clock_scale,
// written only where it is not 1) to the series the figures read.
TEST(RunClock, TheScaleReachesTheSeriesThroughTheRunFile) {
  for (const double scale : {1.0, 10.0}) {
    const TimelineRun run = Simulate(
        Hallway(R"({"count": 0, "target": "to_exit", "seed": 3})",
                R"({"duration_s": 1, "output_fps": 4, "checkpoint_interval_s": 0, "contacts": false})",
                R"({"clock_start": "21:45", "clock_scale": )" + FormatNumber(scale) +
                    R"(, "inflows": [{"id": "in", "entry": "from_court", "rate_per_s": 1.5}]})"),
        "clock-scale-" + FormatNumber(scale));
    EXPECT_EQ(run.Value("timeline_clock_scale"), scale == 1.0 ? "" : "10");
    const analysis::TimelineSeries series = analysis::ComputeTimeline(run.file, 0.0);
    EXPECT_EQ(series.clock.start, "21:45");
    EXPECT_EQ(series.clock.scale, scale);
    EXPECT_EQ(series.clock.Text(6.0), scale == 1.0 ? "21:45:06" : "21:46");
  }
}

// Two inflows, the second starting later and faster (a timeline as the
// Itaewon evening's): a person's id and row do not depend on how long the
// run is. The shorter run's people are the longer run's first ones, row for
// row, they enter at the same times under the same ids, and ids are given in
// the order the arrivals are due. (Ids numbered inflow by inflow gave every
// arrival of the second inflow another id in the longer run.)
TEST(Timeline, AnArrivalsIdDoesNotDependOnHowLongTheRunIs) {
  const auto run = [&](int seconds) {
    return Simulate(Hallway(R"({"count": 0, "target": "to_exit", "counter_target": "to_court", "seed": 11})",
                            R"({"duration_s": )" + std::to_string(seconds) +
                                R"(, "output_fps": 4, "checkpoint_interval_s": 0, "contacts": false})",
                            R"({"inflows": [{"id": "court", "entry": "from_court", "rate_per_s": 1.5},
                                            {"id": "street", "entry": "from_outside", "group": "counter",
                                             "rate_per_s": [[0, 0], [1, 2.5]]}]})"),
                    "ids-" + std::to_string(seconds) + "s");
  };
  const TimelineRun shorter = run(3), longer = run(6);
  const std::vector<runfile::Person> a = runfile::RunFileReader(shorter.file).People();
  const std::vector<runfile::Person> b = runfile::RunFileReader(longer.file).People();
  const auto shapes_a = runfile::RunFileReader(shorter.file).Shapes();
  const auto shapes_b = runfile::RunFileReader(longer.file).Shapes();
  // 1.5 x 3 + 2.5 x 2 arrivals against 1.5 x 6 + 2.5 x 5.
  ASSERT_EQ(a.size(), 4u + 5u);
  ASSERT_EQ(b.size(), 9u + 12u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE("person " + std::to_string(i + 1));
    EXPECT_EQ(a[i].group, b[i].group);
    EXPECT_EQ(a[i].target, b[i].target);
    EXPECT_EQ(a[i].mass_kg, b[i].mass_kg);
    EXPECT_EQ(a[i].desired_speed_m_per_s, b[i].desired_speed_m_per_s);
    EXPECT_EQ(a[i].shape, b[i].shape);
    EXPECT_EQ(shapes_a[a[i].shape].vertices, shapes_b[b[i].shape].vertices);
  }
  // Due: court 0.67, 1.33 s; street 1.4, 1.8; court 2.0; street 2.2, 2.6;
  // court 2.67; street 3.0: the groups interleave in the table.
  const std::uint32_t court = a[0].group, street = court == 0 ? 1 : 0;
  const std::vector<std::uint32_t> due_order = {court, court, street, street, court, street, street, court, street};
  std::vector<std::uint32_t> groups;
  for (const runfile::Person& p : a) groups.push_back(p.group);
  EXPECT_EQ(groups, due_order);
  const std::vector<runfile::Event> enter_a = shorter.Kind("enter"), enter_b = longer.Kind("enter");
  ASSERT_GE(enter_a.size(), 8u);
  ASSERT_GT(enter_b.size(), enter_a.size());
  for (std::size_t n = 0; n < enter_a.size(); ++n) {
    EXPECT_EQ(enter_a[n].person, enter_b[n].person) << n;
    EXPECT_EQ(enter_a[n].time_s, enter_b[n].time_s) << n;
  }
  // With the entries free, people enter in the order they are due: by id.
  for (std::size_t n = 1; n < enter_b.size(); ++n) EXPECT_GT(enter_b[n].person, enter_b[n - 1].person) << n;
}

// A checkpoint of a build that numbered arrivals inflow by inflow is not
// resumed by this one (its person table would not match), with a message
// that says why and what to do.
TEST(Timeline, ACheckpointThatNumberedArrivalsInflowByInflowIsNotResumed) {
  const Scenario s = ParseScenario(
      Hallway(R"({"count": 0, "target": "to_exit", "seed": 3})",
              R"({"duration_s": 3, "output_fps": 4, "checkpoint_interval_s": 0.5, "contacts": false})",
              R"({"inflows": [{"id": "in", "entry": "from_court", "rate_per_s": 1.5}]})"),
      "old-checkpoint.json", kSource);
  RunOptions options;
  options.output = crowdrecon::testing::ScratchFile("old-checkpoint.sqlite");
  std::filesystem::remove(options.output);
  std::filesystem::remove(CheckpointPath(options.output));
  options.stop_after_s = 1.0;
  ASSERT_EQ(RunScenario(s, options).status, "interrupted");
  // The timeline's state as the earlier build wrote it: its magic 001.
  const std::filesystem::path checkpoint = CheckpointPath(options.output);
  std::string bytes;
  {
    std::ifstream in(checkpoint, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::size_t at = bytes.find("TLINE002");
  ASSERT_NE(at, std::string::npos);
  const auto write = [&](const std::string& b) {
    std::ofstream out(checkpoint, std::ios::binary | std::ios::trunc);
    out << b;
  };
  std::string earlier = bytes;
  earlier[at + 7] = '1';
  write(earlier);
  options.resume = true;
  options.stop_after_s = -1.0;
  try {
    RunScenario(s, options);
    ADD_FAILURE() << "a 001 checkpoint was resumed";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(checkpoint.string(), 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("inflow by inflow"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("without --resume"), std::string::npos) << e.what();
  }
  write(bytes);  // the same checkpoint as this build wrote it resumes
  EXPECT_EQ(RunScenario(s, options).status, "complete");
}

// Pre-movement times (RiMEA test 5; timeline.premovement): each person of
// the start stands until their time, sets off at the first step at or after
// it with their own desired speed, and a run stopped and resumed between
// two starts gives the same tables.
TEST(Timeline, PeopleOfTheStartSetOffAtTheirPremovementTimes) {
  const std::string json =
      Hallway(R"({"count": 4, "target": "to_exit", "placement": {"region": "entries"}, "seed": 5})",
              R"({"duration_s": 4, "output_fps": 10, "checkpoint_interval_s": 0, "contacts": false})",
              R"({"premovement": {"times_s": [1.0, 0.5, 2.55, 3.0]}})");
  const TimelineRun run = Simulate(json, "premovement");
  const std::vector<runfile::Event> starts = run.Kind("start");
  ASSERT_EQ(starts.size(), 4u);
  const double expected[] = {1.0, 0.5, 2.55, 3.0};
  for (const runfile::Event& e : starts) {
    ASSERT_GE(e.person, 0);
    ASSERT_LT(e.person, 4);
    // The first step that starts at or after the time (steps are about a millisecond).
    EXPECT_GE(e.time_s, expected[e.person] - 1e-9);
    EXPECT_LT(e.time_s, expected[e.person] + 0.01);
  }
  // Nobody moves before the first time (later, a walker may push a person
  // who still stands: the validation suite counts that, rimea-05); everyone
  // walks after their time.
  const runfile::RunFileReader reader(run.file);
  runfile::PersonFrame f, first;
  auto stream = reader.PersonFrames(40);
  ASSERT_TRUE(stream.Next(&first));
  while (stream.Next(&f)) {
    const double t = double(f.frame) / 10.0;
    for (std::size_t i = 0; i < f.person.size(); ++i) {
      const double moved = Length(f.position_m[i] - first.position_m[i]);
      if (t <= 0.5) {
        EXPECT_EQ(moved, 0.0) << "person " << f.person[i] << " at " << t << " s";
      }
      if (t >= expected[f.person[i]] + 0.5) {
        EXPECT_GT(moved, 0.05) << "person " << f.person[i] << " at " << t << " s";
      }
    }
  }
  // Stopped at 2 s (between two starts) and resumed: the same tables.
  const Scenario s = ParseScenario(json, "premovement-resumed.json", kSource);
  RunOptions options;
  options.output = crowdrecon::testing::ScratchFile("premovement-resumed.sqlite");
  std::filesystem::remove(options.output);
  std::filesystem::remove(CheckpointPath(options.output));
  options.stop_after_s = 2.0;
  ASSERT_EQ(RunScenario(s, options).status, "interrupted");
  options.resume = true;
  options.stop_after_s = -1.0;
  ASSERT_EQ(RunScenario(s, options).status, "complete");
  EXPECT_EQ(runfile::RunFileReader(options.output).TablesDigest(), reader.TablesDigest());
  // Drawn times: one per person of the start, inside the range, from the seed.
  const TimelineRun drawn = Simulate(
      Hallway(R"({"count": 6, "target": "to_exit", "placement": {"region": "entries"}, "seed": 5})",
              R"({"duration_s": 0.5, "output_fps": 10, "checkpoint_interval_s": 0, "contacts": false})",
              R"({"premovement": {"uniform_s": [0.1, 0.4]}})"),
      "premovement-drawn");
  ASSERT_EQ(drawn.Kind("start").size(), 6u);
  for (const runfile::Event& e : drawn.Kind("start")) {
    EXPECT_GE(e.time_s, 0.1);
    EXPECT_LT(e.time_s, 0.41);
  }
  // NIST TN 1822 Verif.1.1's shapes: the times are the distribution's
  // quantiles of the same stream (here a Weibull of scale 0.2 s: each start
  // at the first step at or after its time).
  const std::string weibull = R"({"premovement": {"weibull": {"shape": 1.195, "scale_s": 0.2}}})";
  // The draw as documented (timeline.hpp): the population's seed's own
  // stream, one uniform number per person in id order, moved to the middle
  // of its 2^-53 interval, through the distribution's quantile.
  const Distribution w{Distribution::Kind::kWeibull, 1.195, 0.2};
  std::mt19937_64 rng(5 ^ 0x9e3779b97f4a7c15ull);
  std::vector<double> times(6);
  for (double& t : times) t = w.Quantile((double(rng() >> 11) + 0.5) * 0x1.0p-53);
  const TimelineRun shaped = Simulate(
      Hallway(R"({"count": 6, "target": "to_exit", "placement": {"region": "entries"}, "seed": 5})",
              R"({"duration_s": 3, "output_fps": 10, "checkpoint_interval_s": 0, "contacts": false})", weibull),
      "premovement-weibull");
  std::vector<double> started;
  for (const runfile::Event& e : shaped.Kind("start")) started.push_back(e.time_s);
  std::vector<double> sorted = times;
  std::sort(sorted.begin(), sorted.end());
  std::sort(started.begin(), started.end());
  ASSERT_EQ(started.size(), sorted.size());
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    EXPECT_GE(started[i], sorted[i] - 1e-9);
    EXPECT_LT(started[i], sorted[i] + 0.011);  // within a step (dt <= 0.01 s)
  }
}

TEST(Timeline, PremovementTimesThatDoNotFitAreRefused) {
  const auto refuse = [](const std::string& timeline, const std::string& expected) {
    try {
      const Scenario s = ParseScenario(
          Hallway(R"({"count": 3, "target": "to_exit", "placement": {"region": "entries"}})", R"({"duration_s": 1})", timeline),
          "bad-premovement.json", kSource);
      RunOptions options;
      options.output = crowdrecon::testing::ScratchFile("bad-premovement.sqlite");
      std::filesystem::remove(options.output);
      RunScenario(s, options);
      ADD_FAILURE() << "accepted: " << timeline;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refuse(R"({"premovement": {"uniform_s": [5, 1]}})", "/timeline/premovement/uniform_s: expected low <= high");
  refuse(R"({"premovement": {"uniform_s": [1, 5], "times_s": [1]}})", "exactly one of a distribution");
  refuse(R"({"premovement": {"gamma": {"shape": 1.3, "scale_s": 0}}})", "/timeline/premovement/gamma/scale_s");
  refuse(R"({"premovement": {"times_s": [1, -2, 3]}})", "/timeline/premovement/times_s/1");
  refuse(R"({"premovement": {"times_s": [1, 2]}})", "/timeline/premovement/times_s: 2 times for 3 people of the start");
  refuse(R"({"premovement": {"uniform_s": [1, 5], "shape": "gamma"}})", "shape");
}

// A run's wall time (run value wall_s) counts every invocation of a resumed
// run, so that a sweep's results and a long run's statement of what it cost
// are not the last part's alone.
TEST(Timeline, AResumedRunsWallTimeCountsAllItsParts) {
  const Scenario s = LoadScenario(kSource / "tests/data/scenarios/hallway-short.json");
  RunOptions options;
  options.output = crowdrecon::testing::ScratchFile("wall-time.sqlite");
  std::filesystem::remove(options.output);
  std::filesystem::remove(CheckpointPath(options.output));
  const auto recorded = [&] { return scenario::RecordedWallSeconds(options.output); };

  options.stop_after_s = 1.0;
  const RunSummary first = RunScenario(s, options);
  ASSERT_EQ(first.status, "interrupted");
  EXPECT_EQ(first.total_wall_s, first.wall_s);
  // Written at the end, just before the summary's own reading of the clock.
  const double after_first = recorded();
  EXPECT_GT(after_first, 0.0);
  EXPECT_LE(after_first, first.wall_s * (1.0 + 1e-9));

  options.stop_after_s = -1.0;
  options.resume = true;
  const RunSummary second = RunScenario(s, options);
  ASSERT_EQ(second.status, "complete");
  EXPECT_DOUBLE_EQ(second.total_wall_s, after_first + second.wall_s);
  EXPECT_GT(recorded(), after_first);
  EXPECT_LE(recorded(), second.total_wall_s * (1.0 + 1e-9));
  EXPECT_GT(second.total_wall_s, second.wall_s);
}

}  // namespace timeline_tests
}  // namespace crowdrecon::scenario

namespace crowdrecon::scenario {
namespace timeline_tests {

// The gait jitter's seed (issue 39) follows the population's seed unless the
// model gives its own, so that every seed of an ensemble jitters
// differently without a second key to keep in step.
TEST(Scenario, TheGaitJittersSeedFollowsThePopulationsUnlessGiven) {
  const std::string venue = (kSource / "venues/madrid-arena/hallway-open.json").string();
  const auto scenario = [&](const std::string& model) {
    return R"({"format": "crowdrecon-scenario", "version": 1, "venue": ")" + venue +
           R"(", "population": {"count": 10, "target": "to_exit", "seed": 4242}, "model": )" + model + "}";
  };
  EXPECT_EQ(ParseScenario(scenario(R"({"gait_jitter": "isotropic"})"), "a.json", kSource).model.gait_jitter_seed, 4242.0);
  EXPECT_EQ(ParseScenario(scenario(R"({"gait_jitter": "isotropic", "gait_jitter_seed": 7})"), "b.json", kSource)
                .model.gait_jitter_seed,
            7.0);
  try {
    ParseScenario(scenario(R"({"gait_jitter_seed": 1.5})"), "c.json", kSource);
    ADD_FAILURE() << "a seed that is not whole was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gait_jitter_seed = 1.5, expected a whole number"), std::string::npos) << e.what();
  }
}

}  // namespace timeline_tests
}  // namespace crowdrecon::scenario

// --- the local reading of avalanches (analysis::AreaAvalanches) -------------
namespace crowdrecon::scenario {
namespace timeline_tests {

// One area whose flow walks, stops for 5 s and walks again, at the given
// density while stopped (10 frames/s, 40 s).
analysis::TimelineSeries OneAreaStopAndGo(double stop_density_per_m2, bool gap_in_the_stop = false) {
  analysis::TimelineSeries s;
  s.area_names = {"end"};
  s.area_m2_each = {9.0};
  s.area_speed_m_per_s.assign(1, {});
  s.area_density_per_m2.assign(1, {});
  for (int k = 0; k <= 400; ++k) {
    const double t = k / 10.0;
    const bool stopped = t >= 20.0 - 1e-9 && t < 25.0 - 1e-9;
    s.time_s.push_back(t);
    s.area_speed_m_per_s[0].push_back(stopped ? 0.02 : 0.9);
    s.area_density_per_m2[0].push_back(stopped ? stop_density_per_m2 : 1.5);
    if (gap_in_the_stop && t >= 22.0 - 1e-9 && t < 22.5 - 1e-9) s.area_speed_m_per_s[0].back() = NAN;
  }
  return s;
}

TEST(AreaAvalanches, AStopOfACrowdInContactThatReleasesIsOneAvalancheNamedByItsArea) {
  const std::vector<analysis::TimelineMark> m = analysis::AreaAvalanches(OneAreaStopAndGo(5.0));
  ASSERT_EQ(m.size(), 1u);
  EXPECT_NEAR(m[0].time_s, 25.0, 1e-9);  // the sample where the flow rose (FindAvalanches)
  EXPECT_EQ(m[0].kind, "avalanche");
  EXPECT_NE(m[0].label.find("area end: released after a stop of 5.0 s at 5.0 /m2"), std::string::npos) << m[0].label;
  EXPECT_FALSE(std::isnan(m[0].rise_time_s));
  // The same stop in a crowd below contact density is not a clog.
  EXPECT_TRUE(analysis::AreaAvalanches(OneAreaStopAndGo(3.0)).empty());
  EXPECT_EQ(analysis::AreaAvalanches(OneAreaStopAndGo(3.0), {}, 2.5).size(), 1u);
  // A moment with nobody walking in the area ends the stop, and what
  // follows the gap begins at rest, as a crowd placed standing does: not a
  // stop of a flow (FindAvalanches), so no avalanche.
  EXPECT_TRUE(analysis::AreaAvalanches(OneAreaStopAndGo(5.0, true)).empty());
}

TEST(AreaAvalanches, OneReleaseSeenInSeveralPlacesIsMergedOnce) {
  const std::vector<analysis::TimelineMark> marks = {
      {13.5, "c", "avalanche"}, {10.0, "a", "avalanche"}, {11.0, "b", "avalanche"}, {16.0, "d", "avalanche"}};
  const std::vector<analysis::TimelineMark> kept = analysis::MergeAvalanches(marks, 2.0);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0].label, "a");
  EXPECT_EQ(kept[1].label, "c");
  EXPECT_EQ(kept[2].label, "d");  // 2.5 s after c
}

// The areas' speeds from a run: the mean over the walking people whose
// centre is inside of their velocity along their group's direction (the
// open hallway: +x to the exit, -x to the court), recomputed from the run
// file's frames directly (with the groups' directions of the run's analysis,
// which the navigation field makes a little off the axis).
TEST(AreaAvalanches, TheAreasSpeedIsTheMeanAlongEachGroupsDirectionOfTheWalkersInside) {
  const TimelineRun run = Simulate(
      Hallway(R"({"count": 60, "counter_flow_fraction": 0.3, "target": "to_exit", "counter_target": "to_court",
                  "body": {"mode": "paper", "reference": ")" + (kSource / "venues/bodies/thorax-18.json").string() +
                  R"("}, "seed": 5})",
              R"({"duration_s": 2, "output_fps": 10, "checkpoint_interval_s": 0, "contacts": false})", R"({})"),
      "area_speeds");
  const analysis::TimelineSeries s = analysis::ComputeTimeline(run.file);
  ASSERT_EQ(s.area_names, (std::vector<std::string>{"centre", "court_end", "exit_end"}));
  const std::vector<Vec2> e = analysis::AnalyzeRun(run.file).group_direction;
  ASSERT_EQ(e.size(), 2u);
  EXPECT_NEAR(e[0].x, 1.0, 1e-3);
  EXPECT_NEAR(e[1].x, -1.0, 1e-3);
  const runfile::RunFileReader reader(run.file);
  const std::vector<std::uint32_t> group = reader.PersonGroups();
  const std::vector<runfile::FrameTime> times = reader.FrameTimes();
  auto stream = reader.PersonFrames(times.back().frame);
  runfile::PersonFrame f;
  const double x0[3] = {5.0, 1.5, 7.5}, x1[3] = {7.0, 4.5, 10.5};
  std::size_t k = 0, checked = 0;
  while (stream.Next(&f)) {
    while (times[k].frame < f.frame) ++k;
    for (int a = 0; a < 3; ++a) {
      double sum = 0.0;
      int n = 0;
      for (std::size_t r = 0; r < f.person.size(); ++r) {
        if (f.position_m[r].x < x0[a] || f.position_m[r].x > x1[a]) continue;
        sum += Dot(f.velocity_m_per_s[r], e[group[f.person[r]]]);
        ++n;
      }
      if (n == 0) {
        EXPECT_TRUE(std::isnan(s.area_speed_m_per_s[a][k]));
      } else {
        EXPECT_NEAR(s.area_speed_m_per_s[a][k], sum / n, 1e-12) << "area " << a << " frame " << k;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 40u);
}

}  // namespace timeline_tests
}  // namespace crowdrecon::scenario
