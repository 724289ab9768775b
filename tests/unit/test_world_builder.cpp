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

}  // namespace
}  // namespace crowdrecon::scenario
