// Building a world from a scenario: people numbered along the crowd.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>

#include "crowdrecon/scenario/scenario.hpp"
#include "crowdrecon/scenario/world_builder.hpp"

namespace crowdrecon::scenario {
namespace {

TEST(WorldBuilder, PeopleAreNumberedAlongTheCrowd) {
  // The hallway at 5 /m2 (periodic along x): consecutive people stand close,
  // far closer than two people taken at random; each has its own shape at
  // its own index.
  const Scenario scenario = LoadScenario(std::string(CROWDRECON_SOURCE_DIR) + "/tests/data/scenarios/hallway-short.json");
  const BuiltWorld built = BuildWorld(scenario, 1);
  const auto& people = built.world.people;
  ASSERT_GT(people.size(), 100u);
  ASSERT_EQ(built.world.shapes.size(), people.size());
  double consecutive = 0.0, apart = 0.0;
  const std::size_t n = people.size();
  for (std::size_t k = 0; k < n; ++k) {
    EXPECT_EQ(people[k].shape, k);
    if (k + 1 < n) consecutive += Length(people[k + 1].position_m - people[k].position_m);
    apart += Length(people[(k * 7919 + 13) % n].position_m - people[k].position_m);  // a fixed scramble
  }
  consecutive /= double(n - 1);
  apart /= double(n);
  EXPECT_LT(consecutive, 0.2 * apart) << consecutive << " m between consecutive people, " << apart << " m at random";
  EXPECT_LT(consecutive, 1.0);
}

// A scenario's "slope" gives the venue's slope another gradient or switches
// it (issue 43: the Itaewon alley's 6-10 degrees); its direction and region
// stay the venue's and reach the engine's world; a venue without a slope
// refuses one by the JSON path.
TEST(WorldBuilder, TheScenarioSetsTheSlopesGradient) {
  const std::string dir = std::string(CROWDRECON_SOURCE_DIR) + "/venues/itaewon/scenarios";
  const std::string body = R"({"format": "crowdrecon-scenario", "version": 1, "venue": "../alley.json",
    "population": {"count": 20, "target": "to_station", "body": {"mode": "circle"}}, "run": {"duration_s": 1}, )";
  const Scenario steep = ParseScenario(body + R"("slope": {"gradient": 0.1763}})", "steep.json", dir);
  const BuiltWorld built = BuildWorld(steep, 1);
  EXPECT_DOUBLE_EQ(built.world.slope.gradient, 0.1763);
  EXPECT_EQ(built.world.slope.region.size(), 4u);
  EXPECT_EQ(built.world.slope.downhill, (Vec2{0.0, -1.0}));
  const Scenario off = ParseScenario(body + R"("slope": {"enabled": false}})", "off.json", dir);
  EXPECT_EQ(BuildWorld(off, 1).world.slope.gradient, 0.0);
  std::string error;
  try {
    ParseScenario(R"({"format": "crowdrecon-scenario", "version": 1, "venue": "../../madrid-arena/hallway-antechambers.json",
      "population": {"count": 20, "target": "to_street"}, "slope": {"gradient": 0.1}})",
                  "flat.json", dir);
  } catch (const std::exception& e) {
    error = e.what();
  }
  EXPECT_NE(error.find("flat.json: /slope: the venue"), std::string::npos) << error;
  EXPECT_NE(error.find("has no slope"), std::string::npos) << error;
}

// Settings that change nothing are said (issue 65, the adversarial pass's
// A24, B05, L03): an extension's numbers while it is off, a slope's gradient
// while the slope is off, how people meet a slope on a level floor; none when
// they act.
TEST(WorldBuilder, SettingsThatChangeNothingAreSaid) {
  const std::string dir = std::string(CROWDRECON_SOURCE_DIR) + "/venues/itaewon/scenarios";
  const std::string body = R"({"format": "crowdrecon-scenario", "version": 1, "venue": "../alley.json",
    "population": {"count": 20, "target": "to_station", "body": {"mode": "circle"}}, "run": {"duration_s": 1}, )";
  const Scenario off = ParseScenario(body + R"("model": {"give_way_blocked_s": 3, "yielding": "when_blocked",
    "yielding_push_share": 0.5, "slope_response": "held"}, "slope": {"gradient": 0.1, "enabled": false}})", "off.json", dir);
  ASSERT_EQ(off.settings_without_effect.size(), 3u);
  EXPECT_EQ(off.settings_without_effect[0],
            "model.give_way_blocked_s changes nothing: it acts only when give_way = where_room (here give_way is none)");
  EXPECT_EQ(off.settings_without_effect[1],
            "model.slope_response changes nothing: the floor is level here: the slope is off (slope.enabled false)");
  EXPECT_NE(off.settings_without_effect[2].find("slope.gradient changes nothing: the slope is off"), std::string::npos);
  const Scenario on = ParseScenario(body + R"("model": {"give_way": "where_room", "give_way_blocked_s": 3,
    "slope_response": "held"}, "slope": {"gradient": 0.1}})", "on.json", dir);
  EXPECT_TRUE(on.settings_without_effect.empty()) << on.settings_without_effect[0];
}

}  // namespace
}  // namespace crowdrecon::scenario
