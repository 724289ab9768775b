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

}  // namespace
}  // namespace crowdrecon::scenario
