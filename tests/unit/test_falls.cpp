// Falls that happen (issue 39, point 3; docs/decisions.md, "Falls that
// happen"): the verification scenarios of venues/verification/scenarios/.
// A crowd surging down a slope into a standing crowd must fell people, by
// the paper's rule and with tripping; an ordinary crowd walking at 1 m/s at
// 3 persons/m^2, with and without counter-flow, must fell no one. Tripping
// over the fallen is the paper's rule until the first fall, fells people
// who are pushed onto the fallen, and continues across a resume as the
// uninterrupted run does.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/scenario/runner.hpp"
#include "crowdrecon/scenario/scenario.hpp"
#include "scratch.hpp"

namespace crowdrecon::scenario {
namespace {

const std::filesystem::path kScenarios = std::filesystem::path(CROWDRECON_SOURCE_DIR) / "venues/verification/scenarios";

std::vector<runfile::Event> Falls(const std::filesystem::path& file) {
  std::vector<runfile::Event> out;
  for (const runfile::Event& e : runfile::RunFileReader(file).Events())
    if (e.kind == "fall") out.push_back(e);
  return out;
}

std::filesystem::path RunFalls(const Scenario& s, const std::string& name, double stop_after_s = -1.0,
                          bool resume = false) {
  RunOptions options;
  options.output = crowdrecon::testing::ScratchFile(name + ".sqlite");
  if (!resume) {
    std::filesystem::remove(options.output);
    std::filesystem::remove(CheckpointPath(options.output));
  }
  options.stop_after_s = stop_after_s;
  options.resume = resume;
  RunScenario(s, options);
  return options.output;
}

Scenario WithTripping(Scenario s) {
  s.timeline.falls.trip_over_fallen = true;
  return s;
}

TEST(Falls, ACrowdSurgingDownASlopeIntoAStandingCrowdFellsPeople) {
  const Scenario s = LoadScenario(kScenarios / "falls-surge-down-slope.json");
  ASSERT_EQ(s.timeline.falls.criterion, FallSpec::Criterion::kAcceleration);
  const std::vector<runfile::Event> paper = Falls(RunFalls(s, "surge-paper"));
  ASSERT_GE(paper.size(), 5u) << "a surge at up to 3 m/s down a 10 % slope into a standing crowd felled almost no one";
  for (const runfile::Event& f : paper) EXPECT_EQ(f.detail.rfind("acceleration: mean ", 0), 0u) << f.detail;

  // With tripping: the same first fall, then people pushed onto the fallen
  // go over them.
  const std::vector<runfile::Event> tripping = Falls(RunFalls(WithTripping(s), "surge-tripping"));
  ASSERT_FALSE(tripping.empty());
  EXPECT_EQ(tripping.front().time_s, paper.front().time_s);
  EXPECT_EQ(tripping.front().person, paper.front().person);
  std::size_t tripped = 0;
  for (const runfile::Event& f : tripping) tripped += f.detail.rfind("tripped: pushed onto a fallen person", 0) == 0;
  EXPECT_GE(tripped, 1u) << "no one pushed onto the fallen went over them";
}

TEST(Falls, WalkingAtOneMetrePerSecondAtThreePerSquareMetreFellsNoOne) {
  Scenario s = LoadScenario(kScenarios / "falls-walking-3pm2.json");
  ASSERT_NEAR(s.population.counter_flow_fraction, 0.3, 1e-12);
  EXPECT_TRUE(Falls(RunFalls(s, "walking-counter")).empty()) << "30 % counter-flow at 3 /m^2 felled people";
  EXPECT_TRUE(Falls(RunFalls(WithTripping(s), "walking-counter-tripping")).empty());
  s.population.counter_flow_fraction = 0.0;
  EXPECT_TRUE(Falls(RunFalls(s, "walking-one-way")).empty()) << "one-way walking at 3 /m^2 felled people";
}

TEST(Falls, TrippingContinuesAfterAResumeAsTheWholeRunDoes) {
  Scenario s = WithTripping(LoadScenario(kScenarios / "falls-surge-down-slope.json"));
  s.run.duration_s = 4.0;
  s.run.checkpoint_interval_s = 0.5;
  const std::vector<runfile::Event> whole = Falls(RunFalls(s, "trip-whole"));
  ASSERT_FALSE(whole.empty());
  // Stopped after the first falls (the tripping filter holds impulses then).
  const double stop = whole.front().time_s + 0.6;
  RunFalls(s, "trip-resumed", stop);
  const std::vector<runfile::Event> resumed = Falls(RunFalls(s, "trip-resumed", -1.0, true));
  ASSERT_EQ(resumed.size(), whole.size());
  for (std::size_t k = 0; k < whole.size(); ++k) {
    EXPECT_EQ(resumed[k].time_s, whole[k].time_s);
    EXPECT_EQ(resumed[k].person, whole[k].person);
    EXPECT_EQ(resumed[k].detail, whole[k].detail);
  }
}

TEST(Falls, TrippingIsForTheAccelerationCriterionOnly) {
  const std::string venue = (std::filesystem::path(CROWDRECON_SOURCE_DIR) / "venues/verification/gate-corridor.json").string();
  const std::string json = R"({"format": "crowdrecon-scenario", "version": 1, "name": "t", "venue": ")" + venue +
                           R"(", "population": {"count": 4, "target": "east"},
      "run": {"duration_s": 1}, "timeline": {"falls": {"criterion": "load", "trip_over_fallen": true}}})";
  try {
    ParseScenario(json, "t.json", kScenarios);
    ADD_FAILURE() << "tripping with the load criterion was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("/timeline/falls/trip_over_fallen"), std::string::npos) << m;
    EXPECT_NE(m.find("acceleration"), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace crowdrecon::scenario
